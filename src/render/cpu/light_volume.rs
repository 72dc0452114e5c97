//! The sunlight scattered more than once, over the clouds: a coarse
//! volume over the simulated domain and the cloud band that holds, per
//! cell, the radiance of the sun's light scattered at least once as
//! spherical harmonics to l = 2, by Monte Carlo transport
//! ([`super::light_transport`]; docs/ground_truth: light that depends on
//! the whole cloud, not on one ray toward the sun, is what the path
//! tracer's deep cloud asks for, and the backlit view asks for its
//! forward peak).
//!
//! Built once per field, sun and density change, in two steps, each a
//! WGSL entry of the same name in `shaders/light_volume_build.wgsl`:
//! 1. [`cell_extinction`]: the mean σ_t of each cell, the renderer's own
//!    [`density_at`] averaged over eight points of the cell;
//! 2. [`super::light_transport::trace`]: [`light_photons`] photons from
//!    the sun through those cells, their tracks summed as nine
//!    coefficients a cell (`follow` on the GPU, into fixed-point cells);
//!    then [`sh_planes`] (the entry of that name on the GPU): the coefficients
//!    scaled to per unit irradiance and convolved with the phase
//!    function ([`PHASE_MOMENTS`]), in the three rgba planes the cloud
//!    pass samples.
//!
//! The grid repeats across the domain as the clouds do; photons leave
//! through the band's floor and ceiling. [`LightVolume::light_toward`]
//! reads the planes trilinearly, outside the domain where the density
//! reads P ([`noise_point`]), and gives the light scattered toward the
//! eye per unit scattering coefficient.

use std::ops::{Add, Mul, Sub};

use glam::{UVec3, Vec3, Vec4};
use rayon::prelude::*;

use super::density::{DensityParams, Fields, density_at, noise_point, warped_lookup};
use super::light_transport::{PHASE_MOMENTS, SH_BAND, trace};
use super::lighting::sh9;

/// The horizontal side of a light cell, m: the grid takes the nearest
/// even count of cells of about this size across the domain. Light
/// spreads through cloud over a transport mean free path,
/// `1 / (σ_t (1 - g))`, 50-500 m in these clouds.
pub const LIGHT_CELL_M: f32 = 80.0;
/// The height of a light cell, m: the nearest even count of cells of about
/// this height across the band. Half the horizontal side: a cumulus layer
/// is 1-2 km deep, about a dozen cells of 80 m, and the light falls from a
/// cloud's sunlit top to its base. Against the path tracer, with the
/// gains refitted for each size, 80 m cells leave the backlit view at
/// 10.2 % per pixel and these 9.6 % (every fitted view under 10 %) for
/// 45 % more build time; 40 m cubes need 4 times the photons and over 6
/// times the time (docs/ground_truth/README.md).
pub const LIGHT_CELL_HEIGHT_M: f32 = 40.0;
/// The most cells along the domain's side and along the band's height
/// (48 layers: cells of 40 m up to a band 1.92 km deep, taller beyond
/// it). 48 bounds the largest grid, which deep convection's 12 km band
/// reaches, at 1.8 M cells: 177 MB on the GPU and a 64 MB copy of the
/// sums per CPU thread.
pub const LIGHT_CELLS_MAX: UVec3 = UVec3::new(192, 48, 192);
/// The photons' seed: the same clouds and sun give the same light.
pub const LIGHT_SEED: u32 = 1;
/// The sun's height under which no photon is traced (`LIGHT_SUN_MIN` in
/// WGSL): a sun this low crosses a layer 10 cells sideways, and the
/// octaves carry its light.
pub const LIGHT_SUN_MIN: f32 = 0.05;

/// The photons a build of `grid` traces: `per_column` for each column of
/// cells (`render.light_photons`), so that the light's noise per cell does
/// not depend on the domain's size (`LightVolumePass` traces as many).
pub fn light_photons(grid: &LightVolumeGrid, per_column: u32) -> u32 {
    (grid.cells.x * grid.cells.z).saturating_mul(per_column)
}

/// The grid: cell counts and sizes, over `[0, extent)²` horizontally and
/// the band vertically.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightVolumeGrid {
    pub cells: UVec3,
    /// Cell sides, m.
    pub cell_m: Vec3,
    /// The band's bottom, m.
    pub bottom_m: f32,
}

impl LightVolumeGrid {
    /// The grid for the density's domain and band.
    pub fn new(d: &DensityParams) -> Self {
        let height = (d.band_top_m - d.band_bottom_m).max(1.0);
        let side = |length: f32, cell: f32, max: u32| {
            let n = ((length / cell / 2.0).round() as u32 * 2).clamp(4, max);
            (n, length / n as f32)
        };
        let (nx, hx) = side(d.map_extent_m.max(1.0), LIGHT_CELL_M, LIGHT_CELLS_MAX.x);
        let (ny, hy) = side(height, LIGHT_CELL_HEIGHT_M, LIGHT_CELLS_MAX.y);
        Self {
            cells: UVec3::new(nx, ny, nx),
            cell_m: Vec3::new(hx, hy, hx),
            bottom_m: d.band_bottom_m,
        }
    }

    pub fn len(&self) -> usize {
        (self.cells.x * self.cells.y * self.cells.z) as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The index of cell `(i, j, k)` (x fastest, then z, then the layer
    /// `j`): `i` and `k` wrap around the domain.
    #[inline]
    pub fn index(&self, i: i32, j: i32, k: i32) -> usize {
        let (nx, nz) = (self.cells.x as i32, self.cells.z as i32);
        let i = i.rem_euclid(nx);
        let k = k.rem_euclid(nz);
        ((j * nz + k) * nx + i) as usize
    }

    /// The cell of index `idx`.
    #[inline]
    pub fn cell(&self, idx: usize) -> (i32, i32, i32) {
        let (nx, nz) = (self.cells.x as usize, self.cells.z as usize);
        (
            (idx % nx) as i32,
            (idx / (nx * nz)) as i32,
            ((idx / nx) % nz) as i32,
        )
    }

    /// The centre of cell `(i, j, k)`, m.
    #[inline]
    pub fn centre(&self, i: i32, j: i32, k: i32) -> Vec3 {
        Vec3::new(
            (i as f32 + 0.5) * self.cell_m.x,
            self.bottom_m + (j as f32 + 0.5) * self.cell_m.y,
            (k as f32 + 0.5) * self.cell_m.z,
        )
    }
}

/// Reads `values` (one per cell of `grid`: the extinction or a plane of
/// the transported light) trilinearly at `p`: wrapping across the domain, clamped to
/// the band's outer cell centres (`read_cells` in WGSL).
#[inline]
pub fn read_cells<T: Cell>(values: &[T], grid: &LightVolumeGrid, p: Vec3) -> T {
    let v = ((p.y - grid.bottom_m) / grid.cell_m.y - 0.5).clamp(0.0, grid.cells.y as f32 - 1.0);
    let j = v.floor();
    let fy = v - j;
    let j = j as usize;
    let j1 = (j + 1).min(grid.cells.y as usize - 1);
    let n = (grid.cells.x * grid.cells.z) as usize;
    let a = read_layer(&values[j * n..(j + 1) * n], grid, p.x, p.z);
    let b = read_layer(&values[j1 * n..(j1 + 1) * n], grid, p.x, p.z);
    a + (b - a) * fy
}

/// What a cell holds and [`read_cells`] interpolates: a scalar or a
/// vector.
pub trait Cell: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<f32, Output = Self> {}
impl Cell for f32 {}
impl Cell for Vec3 {}
impl Cell for Vec4 {}

/// The mean extinction of each cell, 1/m: [`density_at`] (with the
/// detail noise, at the level of detail of half a cell) averaged over the
/// centres of the cell's eight octants.
pub fn cell_extinction(grid: &LightVolumeGrid, f: &Fields, d: &DensityParams) -> Vec<f32> {
    let quarter = grid.cell_m * 0.25;
    let footprint = 0.5 * grid.cell_m.x;
    (0..grid.len())
        .into_par_iter()
        .map(|idx| {
            let (i, j, k) = grid.cell(idx);
            let c = grid.centre(i, j, k);
            let mut sum = 0.0;
            for o in 0..8 {
                let s = Vec3::new(
                    if o & 1 == 0 { -1.0 } else { 1.0 },
                    if o & 2 == 0 { -1.0 } else { 1.0 },
                    if o & 4 == 0 { -1.0 } else { 1.0 },
                );
                sum += density_at(c + s * quarter, f, d, true, footprint);
            }
            sum / 8.0
        })
        .collect()
}

/// Reads one layer's `values` bilinearly at world `(x, z)`, wrapping.
#[inline]
pub fn read_layer<T: Cell>(values: &[T], grid: &LightVolumeGrid, x: f32, z: f32) -> T {
    let nx = grid.cells.x as i32;
    let (u, w) = (x / grid.cell_m.x - 0.5, z / grid.cell_m.z - 0.5);
    let (i, k) = (u.floor(), w.floor());
    let (fx, fz) = (u - i, w - k);
    let (i, k) = (i as i32, k as i32);
    let at = |a: i32, c: i32| {
        values[(c.rem_euclid(grid.cells.z as i32) * nx + a.rem_euclid(nx)) as usize]
    };
    let lo = at(i, k) + (at(i + 1, k) - at(i, k)) * fx;
    let hi = at(i, k + 1) + (at(i + 1, k + 1) - at(i, k + 1)) * fx;
    lo + (hi - lo) * fz
}

/// The cloud pass's three planes from the radiance coefficients `sh` (per
/// unit irradiance, [`trace`]'s): each coefficient times its band's
/// [`PHASE_MOMENTS`], coefficients 0-3, 4-7 and 8 (then zeros) in turn
/// (the `sh_planes` entry in WGSL). The light scattered toward `ω` is the dot
/// product of the planes with [`sh9`]`(ω)`.
pub fn sh_planes(sh: &[[f32; 9]]) -> [Vec<Vec4>; 3] {
    let c = |v: &[f32; 9], k: usize| v[k] * PHASE_MOMENTS[SH_BAND[k]];
    [
        sh.iter()
            .map(|v| Vec4::new(c(v, 0), c(v, 1), c(v, 2), c(v, 3)))
            .collect(),
        sh.iter()
            .map(|v| Vec4::new(c(v, 4), c(v, 5), c(v, 6), c(v, 7)))
            .collect(),
        sh.iter()
            .map(|v| Vec4::new(c(v, 8), 0.0, 0.0, 0.0))
            .collect(),
    ]
}

/// The sunlight scattered at least once over the clouds, per unit sun
/// irradiance.
#[derive(Debug, Clone, PartialEq)]
pub struct LightVolume {
    pub grid: LightVolumeGrid,
    /// The radiance of each cell as [`sh9`] coefficients, per unit
    /// irradiance ([`trace`]).
    pub sh: Vec<[f32; 9]>,
    /// What [`Self::light_toward`] reads ([`sh_planes`]), the GPU's three
    /// textures.
    pub planes: [Vec<Vec4>; 3],
}

impl LightVolume {
    /// Builds the volume for the clouds of `f` and `d` under the sun
    /// `sun_dir`: [`cell_extinction`], then `per_column` photons for each
    /// column of cells ([`light_photons`], [`LIGHT_SEED`]).
    pub fn build(f: &Fields, d: &DensityParams, sun_dir: Vec3, per_column: u32) -> Self {
        let grid = LightVolumeGrid::new(d);
        let sigma = cell_extinction(&grid, f, d);
        Self::trace(grid, &sigma, sun_dir, light_photons(&grid, per_column))
    }

    /// The volume for the cells' extinction `sigma`, from `photons`.
    pub fn trace(grid: LightVolumeGrid, sigma: &[f32], sun_dir: Vec3, photons: u32) -> Self {
        let sh = trace(&grid, sigma, sun_dir, photons, LIGHT_SEED);
        let planes = sh_planes(&sh);
        Self { grid, sh, planes }
    }

    /// The sunlight scattered at world point `p` toward `to_eye` (unit),
    /// per unit scattering coefficient and irradiance: where `p` reads P
    /// and the cloud map ([`warped_lookup`], [`noise_point`]: itself over
    /// the simulated domain), trilinearly, through the phase function to
    /// l = 2; never below 0 (the truncated series may dip there).
    #[inline]
    pub fn light_toward(&self, p: Vec3, to_eye: Vec3, map_extent_m: f32) -> f32 {
        let q = noise_point(p, warped_lookup(p.x, p.z, map_extent_m), map_extent_m);
        let y = sh9(to_eye);
        let a = read_cells(&self.planes[0], &self.grid, q);
        let b = read_cells(&self.planes[1], &self.grid, q);
        let c = read_cells(&self.planes[2], &self.grid, q);
        let s = a.dot(Vec4::new(y[0], y[1], y[2], y[3]))
            + b.dot(Vec4::new(y[4], y[5], y[6], y[7]))
            + c.x * y[8];
        s.max(0.0)
    }
}

#[cfg(test)]
#[path = "light_volume_tests.rs"]
mod tests;
