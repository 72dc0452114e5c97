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
//! 1. `cell_extinction` ([`cell_extinctions`] in
//!    [`super::light_grid`]): the mean σ_t of each cell, the renderer's
//!    own `density_at` averaged over eight points of the cell, and the
//!    extinction the sunlight sees there
//!    ([`super::light_grid::sun_extinction`]);
//! 2. [`super::light_transport::trace`]: [`light_photons`] photons from
//!    the sun through those cells, their tracks summed as nine
//!    coefficients a cell (`follow` on the GPU, into fixed-point cells);
//!    then [`filter_cells`] and [`sh_planes`] (the GPU's `sh_planes` entry
//!    does both): the coefficients scaled to per unit irradiance, their
//!    directional part smoothed over the neighbouring cells, and
//!    convolved with the phase function ([`PHASE_MOMENTS`]), in the three
//!    rgba planes the cloud pass samples, with the sun's optical depth
//!    from each cell in the third plane's spare channel
//!    ([`with_sun_depth`]).
//!
//! The grid repeats across the domain as the clouds do; photons leave
//! through the band's floor and ceiling. [`LightVolume::light_toward`]
//! reads the planes trilinearly, outside the domain where the density
//! reads P ([`noise_point`]), and gives the light scattered toward the
//! eye per unit scattering coefficient.

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use super::density::{DensityParams, Fields, noise_point, warped_lookup};
use super::light_grid::{
    LIGHT_SEED, LightVolumeGrid, cell_extinctions, light_photons, read_cells, sun_depth,
};
use super::light_transport::{PHASE_MOMENTS, SH_BAND, trace, trace_reporting};
use super::lighting::sh9;

/// The cloud pass's three planes from the radiance coefficients `sh` (per
/// unit irradiance, [`trace`]'s): each coefficient times its band's
/// [`PHASE_MOMENTS`], coefficients 0-3, 4-7 and 8 (then zeros) in turn
/// (the `sh_planes` entry in WGSL). The light scattered toward `ω` is the dot
/// product of the planes with [`sh9`]`(ω)`. The third plane's second
/// channel is left for [`with_sun_depth`].
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

/// The transported coefficients `sh` with their directional part
/// smoothed over neighbouring cells (`filter_cells` and `sh_planes` in
/// WGSL): coefficients 1-8 of each cell the binomial mean of the 3 x 3
/// cells about it in its layer (weights 1-2-1 along x and z, wrapping
/// across the domain as the grid does), coefficient 0 (the fluence) its
/// own. The directional coefficients are the photons' noisiest; against
/// the path tracer at 64 photons a column this filter takes 0.4-0.7
/// points off the per-pixel error, where smoothing the fluence too blurs
/// the lit tops (0.84 of Mitsuba's at a low sun) and the side view's
/// flanks (11 % per pixel; docs/ground_truth/README.md).
pub fn filter_cells(sh: &[[f32; 9]], grid: &LightVolumeGrid) -> Vec<[f32; 9]> {
    (0..grid.len())
        .into_par_iter()
        .map(|idx| {
            let (i, j, k) = grid.cell(idx);
            let mut out = [0.0f32; 9];
            for dk in -1..=1_i32 {
                for di in -1..=1_i32 {
                    let w = ((2 - di.abs()) * (2 - dk.abs())) as f32;
                    let c = &sh[grid.index(i + di, j, k + dk)];
                    for n in 1..9 {
                        out[n] += w * c[n];
                    }
                }
            }
            let mut out = out.map(|v| v / 16.0);
            out[0] = sh[idx][0];
            out
        })
        .collect()
}

/// `planes` with the sun's optical depth from each cell's centre
/// ([`sun_depth`] of the cells' extinction `sigma`) in the third plane's
/// second channel, which the cloud pass reads beyond its shadow rays' near
/// steps (the `sh_planes` entry in WGSL writes it there too).
pub fn with_sun_depth(
    mut planes: [Vec<Vec4>; 3],
    sigma: &[f32],
    grid: &LightVolumeGrid,
    sun_dir: Vec3,
) -> [Vec<Vec4>; 3] {
    for (texel, depth) in planes[2].iter_mut().zip(sun_depth(sigma, grid, sun_dir)) {
        texel.y = depth;
    }
    planes
}

/// The share of a build's progress given to the cells' extinction (the
/// rest is the photons'): about its share of the time on fair weather.
const EXTINCTION_SHARE: f32 = 0.05;

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
    /// `sun_dir`: [`cell_extinctions`], then `per_column` photons for each
    /// column of cells ([`light_photons`], [`LIGHT_SEED`]).
    pub fn build(f: &Fields, d: &DensityParams, sun_dir: Vec3, per_column: u32) -> Self {
        Self::build_reporting(f, d, sun_dir, per_column, &|_| {})
    }

    /// [`Self::build`], calling `progress` with the share of the build
    /// done (0 to 1: the cells' extinction, then the photons by batch) on
    /// the calling thread.
    pub fn build_reporting(
        f: &Fields,
        d: &DensityParams,
        sun_dir: Vec3,
        per_column: u32,
        progress: &dyn Fn(f32),
    ) -> Self {
        let grid = LightVolumeGrid::new(d);
        let (sigma, sun_sigma) = cell_extinctions(&grid, f, d, sun_dir);
        progress(EXTINCTION_SHARE);
        let photons = light_photons(&grid, per_column);
        let sh = trace_reporting(&grid, &sigma, sun_dir, photons, LIGHT_SEED, &|t| {
            progress(EXTINCTION_SHARE + (1.0 - EXTINCTION_SHARE) * t)
        });
        let planes = with_sun_depth(
            sh_planes(&filter_cells(&sh, &grid)),
            &sun_sigma,
            &grid,
            sun_dir,
        );
        progress(1.0);
        Self { grid, sh, planes }
    }

    /// The volume for the cells' extinction `sigma`, from `photons`.
    pub fn trace(grid: LightVolumeGrid, sigma: &[f32], sun_dir: Vec3, photons: u32) -> Self {
        let sh = trace(&grid, sigma, sun_dir, photons, LIGHT_SEED);
        let planes = with_sun_depth(sh_planes(&filter_cells(&sh, &grid)), sigma, &grid, sun_dir);
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

    /// The sun's optical depth from world point `p` through the clouds'
    /// mean extinction ([`with_sun_depth`]), read where `p` reads P, as
    /// [`Self::light_toward`] reads (`sun_depth_at` in WGSL).
    #[inline]
    pub fn sun_depth_at(&self, p: Vec3, map_extent_m: f32) -> f32 {
        let q = noise_point(p, warped_lookup(p.x, p.z, map_extent_m), map_extent_m);
        read_cells(&self.planes[2], &self.grid, q).y
    }
}

#[cfg(test)]
#[path = "light_volume_tests.rs"]
mod tests;
