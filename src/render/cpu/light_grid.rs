//! The light volume's grid ([`LightVolumeGrid`]): cells of about
//! [`LIGHT_CELL_M`] by [`LIGHT_CELL_HEIGHT_M`] over the simulated domain
//! and the cloud band, what each cell holds and how it is read, the
//! clouds' mean extinction per cell, and the photon budget. The transport
//! ([`super::light_transport`]) traces through it and the volume
//! ([`super::light_volume`]) is stored on it. The twin of
//! `shaders/light_grid.wgsl` (and of `cell_extinction` in
//! `shaders/light_volume_build.wgsl`).

use std::ops::{Add, Mul, Sub};

use glam::{UVec3, Vec3, Vec4};
use rayon::prelude::*;

use super::density::{DensityParams, Fields, density_at};
use super::lighting::SHADOW_RAY_M;

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
/// centres of the cell's eight octants ([`cell_samples`]).
pub fn cell_extinction(grid: &LightVolumeGrid, f: &Fields, d: &DensityParams) -> Vec<f32> {
    (0..grid.len())
        .into_par_iter()
        .map(|idx| cell_samples(grid, idx, f, d).iter().sum::<f32>() / 8.0)
        .collect()
}

/// The extinction at the centres of cell `idx`'s eight octants, 1/m
/// ([`density_at`] with the detail noise at the level of detail of half a
/// cell).
#[inline]
pub fn cell_samples(grid: &LightVolumeGrid, idx: usize, f: &Fields, d: &DensityParams) -> [f32; 8] {
    let quarter = grid.cell_m * 0.25;
    let footprint = 0.5 * grid.cell_m.x;
    let (i, j, k) = grid.cell(idx);
    let c = grid.centre(i, j, k);
    std::array::from_fn(|o| {
        let s = Vec3::new(
            if o & 1 == 0 { -1.0 } else { 1.0 },
            if o & 2 == 0 { -1.0 } else { 1.0 },
            if o & 4 == 0 { -1.0 } else { 1.0 },
        );
        density_at(c + s * quarter, f, d, true, footprint)
    })
}

/// The length over which a ray along `sun_dir` crosses one cell along the
/// axis it crosses fastest, m: [`sun_depth_from`]'s step.
#[inline]
pub fn sun_cell_length(grid: &LightVolumeGrid, sun_dir: Vec3) -> f32 {
    1.0 / (sun_dir.abs() / grid.cell_m).max_element().max(1e-6)
}

/// Each cell's extinction as the sunlight crossing it sees it, 1/m
/// (`cell_extinction` in WGSL writes it after the mean): the extinction
/// of a uniform cell with the mean transmittance of its eight octants'
/// over one [`sun_cell_length`], `-ln(mean e^{-σ_o ℓ}) / ℓ`. Where cloud
/// fills part of a cell, light passes through the clear part: the mean
/// extinction's Beer law would shade it as if the cloud were spread over
/// the whole cell (against the path tracer's backlit view, the depth
/// through the mean extinction ran 4 % dark on average, this 0 %).
pub fn sun_extinction(samples: &[f32; 8], length: f32) -> f32 {
    let t = samples.iter().map(|s| (-s * length).exp()).sum::<f32>() / 8.0;
    -t.max(1e-30).ln() / length
}

/// [`cell_extinction`] and [`sun_extinction`] of each cell in one pass
/// over its samples.
pub fn cell_extinctions(
    grid: &LightVolumeGrid,
    f: &Fields,
    d: &DensityParams,
    sun_dir: Vec3,
) -> (Vec<f32>, Vec<f32>) {
    let l = sun_cell_length(grid, sun_dir);
    (0..grid.len())
        .into_par_iter()
        .map(|idx| {
            let s = cell_samples(grid, idx, f, d);
            (s.iter().sum::<f32>() / 8.0, sun_extinction(&s, l))
        })
        .unzip()
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

/// The most samples of one march toward the sun through the cells
/// ([`sun_depth_from`]): a ray of [`SHADOW_RAY_M`] crosses 150 cells of
/// 80 m.
pub const SUN_DEPTH_STEPS_MAX: u32 = 160;

/// The optical depth from `p` toward the sun through the cells'
/// extinction `sigma` (`sun_depth_from` in WGSL): to the grid's top, at
/// most [`SHADOW_RAY_M`] (along a sun at or below the horizon, that), one
/// trilinear read ([`read_cells`]) at the middle of each step, a step the
/// length in which the ray crosses one cell along the axis it crosses
/// fastest.
#[inline]
pub fn sun_depth_from(sigma: &[f32], grid: &LightVolumeGrid, p: Vec3, sun_dir: Vec3) -> f32 {
    let top = grid.bottom_m + grid.cells.y as f32 * grid.cell_m.y;
    let mut length = SHADOW_RAY_M;
    if sun_dir.y > 1e-3 {
        length = ((top - p.y).max(0.0) / sun_dir.y).min(SHADOW_RAY_M);
    }
    let per_m = (sun_dir.abs() / grid.cell_m).max_element();
    let n = ((length * per_m).ceil() as u32).clamp(1, SUN_DEPTH_STEPS_MAX);
    let ds = length / n as f32;
    let mut tau = 0.0;
    for i in 0..n {
        tau += read_cells(sigma, grid, p + sun_dir * ((i as f32 + 0.5) * ds));
    }
    tau * ds
}

/// [`sun_depth_from`] each cell's centre: the sun's optical depth through
/// the clouds' mean extinction, which the march reads beyond its shadow
/// rays' near steps (`light_volume::LightVolume::sun_depth_at`).
pub fn sun_depth(sigma: &[f32], grid: &LightVolumeGrid, sun_dir: Vec3) -> Vec<f32> {
    (0..grid.len())
        .into_par_iter()
        .map(|idx| {
            let (i, j, k) = grid.cell(idx);
            sun_depth_from(sigma, grid, grid.centre(i, j, k), sun_dir)
        })
        .collect()
}
