//! The sunlight diffused through the clouds: a coarse volume over the
//! simulated domain and the cloud band that holds the fluence of the
//! sun's light scattered more than once, by the diffusion approximation
//! (docs/ground_truth: light that depends on the whole cloud, not on one
//! ray toward the sun, is what the path tracer's deep cloud asks for).
//!
//! Built once per field, sun and density change, in four steps, each a
//! WGSL function of the same name in `shaders/light_volume_build.wgsl`:
//! 1. [`cell_extinction`]: the mean σ_t of each cell, the renderer's own
//!    [`density_at`] averaged over eight points of the cell;
//! 2. [`sun_depth`]: the optical depth from each cell's centre toward the
//!    sun, layer by layer from the band's top (the layer above read where
//!    the sun's ray crosses it, plus the segment between);
//! 3. [`relax`]: red-black over-relaxed Gauss-Seidel sweeps of
//!    `-∇·(D ∇φ) + σ_a φ = ϖ σ_t e^{-τ_sun}` (the sunlight scattered once
//!    as the source, `D = 1 / (3 σ_t (1 - g))`), from φ = 0, a fixed count;
//! 4. [`light_flux`]: the net flux of that light, `F = -D ∇φ` (limited to
//!    [`FLUX_LIMIT`] of φ; on the GPU inside the last entry,
//!    `fluence_texture`, which writes φ and F into the texture the cloud
//!    pass samples).
//!
//! The grid repeats across the domain as the clouds do; the band's floor
//! and ceiling are vacuum. Clear air carries the diffused light on and
//! loses it over [`CLEAR_AIR_LOSS_M`]: light that leaves a cloud leaves
//! the band or reaches another cloud. The fluence and
//! the flux are per unit sun irradiance; [`LightVolume::light_at`] reads
//! them trilinearly, outside the domain where the density reads P
//! ([`noise_point`]).

use std::ops::{Add, Mul, Sub};

use glam::{UVec3, Vec3};
use rayon::prelude::*;

use super::density::{DensityParams, Fields, density_at, noise_point, warped_lookup};
use super::renderer::ALBEDO;

/// The side of a light cell, m (`LIGHT_CELL_M` in WGSL): the grid takes
/// the nearest even count of cells of about this size across the domain
/// and the band. Light diffuses over a transport mean free path,
/// `1 / (σ_t (1 - g))`, 50-500 m in these clouds.
pub const LIGHT_CELL_M: f32 = 80.0;
/// The most cells along the domain's side and along the band's height.
pub const LIGHT_CELLS_MAX: UVec3 = UVec3::new(192, 48, 192);
/// Red-black sweeps per build, from nothing. On the fair-weather, BOMEX
/// and evening fields the cloud cells' fluence is within 0.13-0.20 % of
/// the settled one (1000 sweeps) after 24, 1.3-1.5 % after 16 (over
/// [`LIGHT_RELAXATION`] 1.8). Clear air that carries the light far
/// (2026-12-04) settles more slowly: at the earlier 1.7, 24 sweeps left
/// 0.3-0.95 % (0.02 % while clear air absorbed the light within a cell).
/// A lone 1 km cloud's is within 1 % after 24
/// (`the_sweeps_settle_on_a_cloud`).
pub const LIGHT_SWEEPS: u32 = 24;
/// The over-relaxation factor of the sweeps (`LIGHT_RELAXATION`): 1.8
/// settles the shipped fields fastest of 1.7, 1.8 and 1.87 at 24 sweeps.
pub const LIGHT_RELAXATION: f32 = 1.8;
/// The mean cosine of the phase function, `0.75 · 0.8 + 0.25 · (-0.3)`
/// ([`super::lighting::phase_dual`] at full eccentricity).
pub const PHASE_MEAN_COSINE: f32 = 0.525;
/// The longest transport path light diffuses over, m: in thin cloud and
/// clear air the diffusion coefficient is at most a third of it. Light
/// crosses clear air unscattered, so the path is long (200 m until
/// 2026-12-04).
pub const AIR_TRANSPORT_M: f32 = 2000.0;
/// Extinction below which a cell is clear air, 1/m (at half of it, half
/// clear air).
pub const CLOUD_EXTINCTION_MIN: f32 = 0.004;
/// Clear air loses the diffused light over this distance, m. With the
/// long [`AIR_TRANSPORT_M`], light that leaves a cloud spreads through the
/// band's clear air and leaves through its top and floor, or enters
/// another cloud. Until 2026-12-04 clear air absorbed it within a cell
/// (80 m), which held the light at the cloud's sunlit top: relative to
/// the top, a lone 1 km cloud's centre now holds 0.41 (was 0.37) and
/// the air under its base 2.5 times as much, and a cloud beside another
/// gains 3 % (0.4 %). Against the path tracer that scored 2.2 points
/// better summed over the four views, mostly in mid and deep cloud (0.8
/// to 4 km all within 0.3 points of it; docs/ground_truth).
pub const CLEAR_AIR_LOSS_M: f32 = 1600.0;

/// The grid: cell counts and sizes, over `[0, extent)²` horizontally and
/// the band vertically.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiffusionGrid {
    pub cells: UVec3,
    /// Cell sides, m.
    pub cell_m: Vec3,
    /// The band's bottom, m.
    pub bottom_m: f32,
}

impl DiffusionGrid {
    /// The grid for the density's domain and band.
    pub fn new(d: &DensityParams) -> Self {
        let height = (d.band_top_m - d.band_bottom_m).max(1.0);
        let side = |length: f32, max: u32| {
            let n = ((length / LIGHT_CELL_M / 2.0).round() as u32 * 2).clamp(4, max);
            (n, length / n as f32)
        };
        let (nx, hx) = side(d.map_extent_m.max(1.0), LIGHT_CELLS_MAX.x);
        let (ny, hy) = side(height, LIGHT_CELLS_MAX.y);
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

/// Reads `values` (one per cell of `grid`: the extinction, the fluence or
/// the flux) trilinearly at `p`: wrapping across the domain, clamped to
/// the band's outer cell centres (`read_cells` in WGSL).
#[inline]
pub fn read_cells<T: Cell>(values: &[T], grid: &DiffusionGrid, p: Vec3) -> T {
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

/// The mean extinction of each cell, 1/m: [`density_at`] (with the
/// detail noise, at the level of detail of half a cell) averaged over the
/// centres of the cell's eight octants.
pub fn cell_extinction(grid: &DiffusionGrid, f: &Fields, d: &DensityParams) -> Vec<f32> {
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

/// The sun's height below which the layers' recursion stops: a sun this
/// low crosses a layer 20 cells sideways (`LIGHT_SUN_MIN` in WGSL).
pub const LIGHT_SUN_MIN: f32 = 0.05;
/// The optical depth of every cell under a sun below [`LIGHT_SUN_MIN`]
/// (`LIGHT_DEPTH_NONE`): `e^{-τ}` of it is 0, no sunlight.
pub const LIGHT_DEPTH_NONE: f32 = 3.0e38;

/// The optical depth toward the sun of the centres of layer `j`'s cells,
/// given `above`, layer `j + 1`'s (ignored for the top layer): the ray
/// from the centre rises one layer to the next centres' height, where it
/// reads `above` bilinearly, and the extinction along the segment between
/// is summed at one sample per cell crossed sideways. The top layer's
/// ray leaves through the band's top, half a layer up. Under a sun below
/// [`LIGHT_SUN_MIN`] the depths are [`LIGHT_DEPTH_NONE`]: no diffused
/// sunlight.
pub fn sun_depth_layer(
    grid: &DiffusionGrid,
    sigma: &[f32],
    above: &[f32],
    j: i32,
    sun_dir: Vec3,
) -> Vec<f32> {
    let n = (grid.cells.x * grid.cells.z) as usize;
    if sun_dir.y < LIGHT_SUN_MIN {
        return vec![LIGHT_DEPTH_NONE; n];
    }
    let top = j == grid.cells.y as i32 - 1;
    let rise = if top { 0.5 } else { 1.0 } * grid.cell_m.y;
    let length = rise / sun_dir.y;
    let sideways = length * (sun_dir.x.hypot(sun_dir.z));
    let samples = (sideways / grid.cell_m.x).ceil().max(1.0);
    let dt = length / samples;
    (0..n)
        .into_par_iter()
        .map(|c| {
            let i = (c % grid.cells.x as usize) as i32;
            let k = (c / grid.cells.x as usize) as i32;
            let p = grid.centre(i, j, k);
            let mut tau = 0.0;
            for s in 0..samples as u32 {
                tau += read_cells(sigma, grid, p + sun_dir * ((s as f32 + 0.5) * dt)) * dt;
            }
            if !top {
                let q = p + sun_dir * length;
                tau += read_layer(above, grid, q.x, q.z);
            }
            tau
        })
        .collect()
}

/// Reads one layer's `values` bilinearly at world `(x, z)`, wrapping.
#[inline]
pub fn read_layer<T: Cell>(values: &[T], grid: &DiffusionGrid, x: f32, z: f32) -> T {
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

/// The optical depth toward the sun of every cell's centre
/// ([`sun_depth_layer`] from the top layer down).
pub fn sun_depth(grid: &DiffusionGrid, sigma: &[f32], sun_dir: Vec3) -> Vec<f32> {
    let n = (grid.cells.x * grid.cells.z) as usize;
    let mut tau = vec![0.0; grid.len()];
    let mut above = vec![0.0; n];
    for j in (0..grid.cells.y as i32).rev() {
        let layer = sun_depth_layer(grid, sigma, &above, j, sun_dir);
        tau[j as usize * n..(j as usize + 1) * n].copy_from_slice(&layer);
        above = layer;
    }
    tau
}

/// The diffusion coefficient `D = 1 / (3 σ_t (1 - g))`, m, at most that
/// of a transport path of [`AIR_TRANSPORT_M`].
#[inline]
pub fn diffusion_coefficient(sigma_t: f32) -> f32 {
    1.0 / (3.0 * ((1.0 - PHASE_MEAN_COSINE) * sigma_t).max(1.0 / AIR_TRANSPORT_M))
}

/// The absorption of a cell, 1/m: the droplets' `σ_t (1 - ϖ)`, and in
/// clear air (under [`CLOUD_EXTINCTION_MIN`]) the loss over
/// [`CLEAR_AIR_LOSS_M`].
#[inline]
pub fn absorption(sigma_t: f32) -> f32 {
    let clear = 1.0 - (sigma_t / CLOUD_EXTINCTION_MIN).clamp(0.0, 1.0);
    sigma_t * (1.0 - ALBEDO) + clear / CLEAR_AIR_LOSS_M
}

/// The diffusion's source, per unit irradiance, 1/m: the sunlight
/// scattered once, `ϖ σ_t e^{-(1 - g) τ}`. The sunlight is attenuated
/// through the scaled optical depth `(1 - g) τ` of similarity theory
/// (the scaling `D` makes too): a forward-peaked phase sends most of what
/// it scatters on along the beam, which then goes deeper than `e^{-τ}`
/// says. Against the path tracer the unscaled `e^{-τ}` left 0.7 points
/// more per pixel over the four views and asked for twice the gain
/// (docs/ground_truth).
#[inline]
pub fn first_scattering(sigma_t: f32, tau_sun: f32) -> f32 {
    ALBEDO * sigma_t * (-(1.0 - PHASE_MEAN_COSINE) * tau_sun).exp()
}

/// Each cell's [`diffusion_coefficient`], [`absorption`] and source
/// ([`first_scattering`]), computed once for all the sweeps (the GPU's
/// `relax` computes them where it reads them, the same arithmetic).
pub struct Coefficients {
    pub diffusion: Vec<f32>,
    pub absorption: Vec<f32>,
    pub source: Vec<f32>,
}

impl Coefficients {
    pub fn new(sigma: &[f32], tau: &[f32]) -> Self {
        Self {
            diffusion: sigma.iter().map(|s| diffusion_coefficient(*s)).collect(),
            absorption: sigma.iter().map(|s| absorption(*s)).collect(),
            source: sigma
                .iter()
                .zip(tau)
                .map(|(s, t)| first_scattering(*s, *t))
                .collect(),
        }
    }
}

/// The over-relaxed Gauss-Seidel update of cell `idx` from its six
/// neighbours in `phi`: the face coefficients are the harmonic means of
/// the cells' `D` over the side squared; the band's floor and ceiling are
/// vacuum (the fluence is 0 on them, half a cell beyond the outer cells'
/// centres).
#[inline]
pub fn relax(idx: usize, grid: &DiffusionGrid, c: &Coefficients, phi: &[f32]) -> f32 {
    let (i, j, k) = grid.cell(idx);
    let d = c.diffusion[idx];
    let mut diagonal = c.absorption[idx];
    let mut sum = c.source[idx];
    let ny = grid.cells.y as i32;
    let neighbours = [
        (i - 1, j, k, grid.cell_m.x),
        (i + 1, j, k, grid.cell_m.x),
        (i, j, k - 1, grid.cell_m.z),
        (i, j, k + 1, grid.cell_m.z),
        (i, j - 1, k, grid.cell_m.y),
        (i, j + 1, k, grid.cell_m.y),
    ];
    for (a, b, cz, h) in neighbours {
        if b < 0 || b >= ny {
            diagonal += 2.0 * d / (h * h);
            continue;
        }
        let n = grid.index(a, b, cz);
        let dn = c.diffusion[n];
        let w = 2.0 * d * dn / ((d + dn) * h * h);
        diagonal += w;
        sum += w * phi[n];
    }
    let old = phi[idx];
    old + LIGHT_RELAXATION * (sum / diagonal - old)
}

/// `sweeps` red-black sweeps of [`relax`] from `phi`: the cells with
/// `i + j + k` even, then the odd ones (each half reads only the other's
/// values, so the order within a half does not matter).
pub fn relax_sweeps(
    grid: &DiffusionGrid,
    sigma: &[f32],
    tau: &[f32],
    mut phi: Vec<f32>,
    sweeps: u32,
) -> Vec<f32> {
    let c = Coefficients::new(sigma, tau);
    let mut next = phi.clone();
    for _ in 0..sweeps {
        for colour in 0..2 {
            next.par_iter_mut().enumerate().for_each(|(idx, out)| {
                let (i, j, k) = grid.cell(idx);
                *out = if (i + j + k) & 1 == colour {
                    relax(idx, grid, &c, &phi)
                } else {
                    phi[idx]
                };
            });
            std::mem::swap(&mut phi, &mut next);
        }
    }
    phi
}

/// The most net flux the diffused light carries, as a fraction of its
/// fluence (`FLUX_LIMIT` in WGSL): `1 / 3g`, under which the first-order
/// light scattered by a phase of mean cosine `g`, `(φ + 3 g F·ω) / 4π`,
/// is nowhere negative. Diffusion theory's own flux at a free surface is
/// `φ / 2` (no light coming in); Fick's law on a coarse grid gives more
/// at a cloud's edge, where the fluence falls to the clear air's in a
/// cell. Against the path tracer a limit of 0.6 scored 0.3 points better
/// over the four views than `1/3` (docs/ground_truth).
pub const FLUX_LIMIT: f32 = 1.0 / (3.0 * PHASE_MEAN_COSINE);

/// The net flux of the diffused light through cell `idx`, per unit sun
/// irradiance (`light_flux` in WGSL): Fick's law, `F = -D ∇φ`, by central
/// differences (at the band's floor and ceiling, where φ is 0 half a
/// cell beyond, one-sided over the cell and a half), at most
/// [`FLUX_LIMIT`] of the cell's fluence.
#[inline]
pub fn light_flux(idx: usize, grid: &DiffusionGrid, sigma: &[f32], phi: &[f32]) -> Vec3 {
    let (i, j, k) = grid.cell(idx);
    let h = grid.cell_m;
    let ny = grid.cells.y as i32;
    let dx = (phi[grid.index(i + 1, j, k)] - phi[grid.index(i - 1, j, k)]) / (2.0 * h.x);
    let dz = (phi[grid.index(i, j, k + 1)] - phi[grid.index(i, j, k - 1)]) / (2.0 * h.z);
    let (up, span_up) = if j + 1 < ny {
        (phi[grid.index(i, j + 1, k)], h.y)
    } else {
        (0.0, 0.5 * h.y)
    };
    let (down, span_down) = if j > 0 {
        (phi[grid.index(i, j - 1, k)], h.y)
    } else {
        (0.0, 0.5 * h.y)
    };
    let dy = (up - down) / (span_up + span_down);
    let f = -diffusion_coefficient(sigma[idx]) * Vec3::new(dx, dy, dz);
    let limit = FLUX_LIMIT * phi[idx].max(0.0);
    let size = f.length();
    if size > limit { f * (limit / size) } else { f }
}

/// The diffused sunlight's fluence and net flux over the clouds, per unit
/// sun irradiance.
#[derive(Debug, Clone, PartialEq)]
pub struct LightVolume {
    pub grid: DiffusionGrid,
    /// The fluence of each cell (dimensionless: per unit irradiance).
    pub fluence: Vec<f32>,
    /// The net flux of each cell ([`light_flux`]), per unit irradiance.
    pub flux: Vec<Vec3>,
}

impl LightVolume {
    /// Builds the volume for the clouds of `f` and `d` under the sun
    /// `sun_dir`: [`cell_extinction`], [`sun_depth`], [`LIGHT_SWEEPS`]
    /// sweeps of [`relax`] from nothing.
    pub fn build(f: &Fields, d: &DensityParams, sun_dir: Vec3) -> Self {
        let grid = DiffusionGrid::new(d);
        let sigma = cell_extinction(&grid, f, d);
        Self::solve(grid, &sigma, sun_dir, LIGHT_SWEEPS)
    }

    /// The volume for the cells' extinction `sigma`, after `sweeps`.
    pub fn solve(grid: DiffusionGrid, sigma: &[f32], sun_dir: Vec3, sweeps: u32) -> Self {
        let tau = sun_depth(&grid, sigma, sun_dir);
        let fluence = relax_sweeps(&grid, sigma, &tau, vec![0.0; grid.len()], sweeps);
        let flux = (0..grid.len())
            .into_par_iter()
            .map(|idx| light_flux(idx, &grid, sigma, &fluence))
            .collect();
        Self {
            grid,
            fluence,
            flux,
        }
    }

    /// The fluence and the net flux at world point `p`, per unit
    /// irradiance: where `p` reads P and the cloud map ([`warped_lookup`],
    /// [`noise_point`]: itself over the simulated domain), trilinearly
    /// (the warp moves a point and shears the field only slightly: the
    /// flux keeps its direction).
    #[inline]
    pub fn light_at(&self, p: Vec3, map_extent_m: f32) -> (f32, Vec3) {
        let q = noise_point(p, warped_lookup(p.x, p.z, map_extent_m), map_extent_m);
        (
            read_cells(&self.fluence, &self.grid, q),
            read_cells(&self.flux, &self.grid, q),
        )
    }
}

#[cfg(test)]
#[path = "light_volume_tests.rs"]
mod tests;
