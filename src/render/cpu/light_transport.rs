//! The sunlight scattered more than once, by Monte Carlo transport on the
//! light volume's grid (the renderers' light volume,
//! [`super::light_volume::LightVolume`]; `shaders/light_transport.wgsl` is
//! the GPU's twin, same names). Photons enter through the band's top
//! along the sun, fly through the cells' extinction (free paths sampled
//! exactly in the piecewise constant medium, cell by cell), scatter by the
//! renderer's phase function with its albedo, and leave through the
//! band's top or floor. Every flight after the first scattering is added
//! to the cells it crosses (the track-length estimator): its length times
//! the real spherical harmonics to l = 2 of its direction ([`sh9`]). Per
//! cell that is the radiance of the sunlight scattered at least once, per
//! unit sun irradiance, as nine coefficients, without the diffusion
//! approximation: forward scattering, the light that crosses clear air
//! from one cloud to another and a cloud's thin edges are transported as
//! they are, and the second order keeps the light's forward peak, which
//! the backlit view needs against the path tracer
//! (docs/ground_truth/README.md).

use std::f32::consts::PI;

use glam::Vec3;
use rayon::prelude::*;

use super::light_grid::{LIGHT_SUN_MIN, LightVolumeGrid};
use super::lighting::{ALBEDO, sh9};
use super::tone_map::luminance;

/// A photon's random numbers: a 32-bit PCG stream (O'Neill's RXS-M-XS
/// output), seeded per photon; 32 bits so that WGSL draws the same
/// (`rng_seed`, `rng_next`).
pub struct Rng(u32);

impl Rng {
    /// The stream of photon `photon` under `seed` (`rng_seed` in WGSL).
    pub fn new(photon: u32, seed: u32) -> Self {
        let mut r = Self(photon ^ seed.wrapping_mul(0x9E37_79B9));
        r.next();
        r
    }

    /// Uniform in `[0, 1)` (`rng_next` in WGSL).
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
        let s = self.0;
        let word = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277_803_737);
        let x = (word >> 22) ^ word;
        (x >> 8) as f32 / (1u32 << 24) as f32
    }
}

/// A cosine drawn from the Henyey-Greenstein phase of asymmetry `g`.
#[inline]
pub fn sample_hg(g: f32, u: f32) -> f32 {
    if g.abs() < 1e-3 {
        return 1.0 - 2.0 * u;
    }
    let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
}

/// Two unit vectors square to unit `d` and to each other (Duff et al.
/// 2017's branchless basis).
#[inline]
pub fn orthonormal_pair(d: Vec3) -> (Vec3, Vec3) {
    let sign = if d.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + d.z);
    let b = d.x * d.y * a;
    (
        Vec3::new(1.0 + sign * d.x * d.x * a, sign * b, -sign * d.x),
        Vec3::new(b, sign + d.y * d.y * a, -d.y),
    )
}

/// A direction scattered from `dir` by the dual lobe
/// ([`super::lighting::phase_dual`] at full eccentricity).
pub fn scatter(dir: Vec3, rng: &mut Rng) -> Vec3 {
    let g = if rng.next() < 0.75 { 0.8 } else { -0.3 };
    let cos = sample_hg(g, rng.next());
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = 2.0 * PI * rng.next();
    let (a, b) = orthonormal_pair(dir);
    (dir * cos + (a * phi.cos() + b * phi.sin()) * sin).normalize()
}

/// The band `l` of each of [`super::lighting::sh9`]'s coefficients.
pub const SH_BAND: [usize; 9] = [0, 1, 1, 1, 2, 2, 2, 2, 2];

/// The dual-lobe phase's Legendre moments for l = 0, 1, 2:
/// `0.75 · 0.8^l + 0.25 · (-0.3)^l`. Light of radiance coefficients
/// `L_lm` scatters toward `ω` as `Σ PHASE_MOMENTS[l] L_lm Y_lm(ω)` per
/// unit scattering coefficient (Funk-Hecke).
pub const PHASE_MOMENTS: [f32; 3] = [1.0, 0.525, 0.5025];

/// The fluence (`∫ L dω`) of radiance coefficients `c`.
#[inline]
pub fn sh_fluence(c: &[f32; 9]) -> f32 {
    c[0] / 0.282_094_8
}

/// The net flux (`∫ L ω dω`) of radiance coefficients `c`.
#[inline]
pub fn sh_flux(c: &[f32; 9]) -> Vec3 {
    Vec3::new(c[3], c[1], c[2]) / 0.488_602_5
}

/// The most cells one photon crosses before it is dropped: a flight
/// nearly level in clear air would otherwise circle the repeating domain
/// (`CELLS_PER_PHOTON_MAX` in WGSL).
pub const CELLS_PER_PHOTON_MAX: u32 = 20_000;
/// The weight under which Russian roulette may end a photon
/// (`ROULETTE_WEIGHT` in WGSL).
pub const ROULETTE_WEIGHT: f32 = 0.1;

/// Where photon `photon` (seeded by `seed`) enters the band's top under
/// the sun `sun_dir`: a grid position (in cells) and its direction
/// (`sun_photon` in WGSL).
#[inline]
pub fn sun_photon(grid: &LightVolumeGrid, sun_dir: Vec3, rng: &mut Rng) -> (Vec3, Vec3) {
    let cells = grid.cells.as_vec3();
    let pos = Vec3::new(rng.next() * cells.x, cells.y - 1e-4, rng.next() * cells.z);
    (pos, -sun_dir)
}

/// What each photon's track length is multiplied by to make the
/// radiance coefficients per unit sun irradiance: each of `photons`
/// carries the power `μ A / N` through the domain's top of area `A`; the
/// radiance is the track length per volume (`transport_scale`, twin of
/// the GPU's).
pub fn transport_scale(grid: &LightVolumeGrid, sun_dir: Vec3, photons: u32) -> f32 {
    sun_dir.y * area(grid) / photons.max(1) as f32 / volume(grid)
}

/// The radiance of the sunlight scattered at least once, as [`sh9`]
/// coefficients per cell of `grid` and per unit sun irradiance, from
/// `photons` photons (seeded by `seed`) under the sun `sun_dir` through
/// the cells' extinction `sigma`. Under a sun below [`LIGHT_SUN_MIN`],
/// nothing.
pub fn trace(
    grid: &LightVolumeGrid,
    sigma: &[f32],
    sun_dir: Vec3,
    photons: u32,
    seed: u32,
) -> Vec<[f32; 9]> {
    trace_reporting(grid, sigma, sun_dir, photons, seed, &|_| {})
}

/// [`trace`], calling `progress` with the share of the photons traced so
/// far (0 to 1) after each batch, on the calling thread.
pub fn trace_reporting(
    grid: &LightVolumeGrid,
    sigma: &[f32],
    sun_dir: Vec3,
    photons: u32,
    seed: u32,
    progress: &dyn Fn(f32),
) -> Vec<[f32; 9]> {
    let n = grid.len();
    if sun_dir.y < LIGHT_SUN_MIN || photons == 0 {
        return vec![[0.0; 9]; n];
    }
    let start = |rng: &mut Rng| {
        let (pos, dir) = sun_photon(grid, sun_dir, rng);
        (pos, dir, Vec3::ONE)
    };
    let (_, sh) = run(grid, sigma, photons, seed, true, &start, progress);
    let scale = transport_scale(grid, sun_dir, photons);
    sh.iter().map(|c| c.map(|v| v * scale)).collect()
}

fn area(grid: &LightVolumeGrid) -> f32 {
    let extent = grid.cell_m * grid.cells.as_vec3();
    extent.x * extent.z
}

fn volume(grid: &LightVolumeGrid) -> f32 {
    grid.cell_m.x * grid.cell_m.y * grid.cell_m.z
}

/// The fluence (RGB) and the radiance coefficients (of the luminance,
/// [`sh9`]) of the light of an environment of radiance `radiance(u)` from
/// direction `u`, entering the band through its top (from the upper
/// hemisphere) or its floor (`from_top` false: the lower), all orders of
/// scattering and the unscattered light. Not used by the renderers (the
/// sky's light in cloud is a profile, `renderer::ambient_light`): the
/// transport experiment (docs/ground_truth/transport_experiment.patch)
/// transports the sky's and the ground's light with it, and the tests
/// check the estimator's scale with it.
pub fn trace_sky(
    grid: &LightVolumeGrid,
    sigma: &[f32],
    radiance: &(dyn Fn(Vec3) -> Vec3 + Sync),
    from_top: bool,
    photons: u32,
    seed: u32,
) -> (Vec<Vec3>, Vec<[f32; 9]>) {
    let cells = grid.cells.as_vec3();
    let (length, sh) = run(
        grid,
        sigma,
        photons,
        seed,
        false,
        &|rng: &mut Rng| {
            // Cosine-weighted about the inward normal.
            let r = rng.next().sqrt();
            let phi = 2.0 * PI * rng.next();
            let up = (1.0 - r * r).max(0.0).sqrt();
            let inward = Vec3::new(
                r * phi.cos(),
                if from_top { -up } else { up },
                r * phi.sin(),
            );
            let y = if from_top { cells.y - 1e-4 } else { 1e-4 };
            let pos = Vec3::new(rng.next() * cells.x, y, rng.next() * cells.z);
            (pos, inward, radiance(-inward) * PI)
        },
        &|_| {},
    );
    let scale = area(grid) / photons.max(1) as f32 / volume(grid);
    (
        length.iter().map(|l| *l * scale).collect(),
        sh.iter().map(|c| c.map(|v| v * scale)).collect(),
    )
}

/// A photon's start: a grid position, a direction and an RGB weight.
type Start<'a> = dyn Fn(&mut Rng) -> (Vec3, Vec3, Vec3) + Sync + 'a;

/// `photons` walks from `start`, their tracks summed per cell (after the
/// first scattering with `scattered_only`): the lengths times the RGB
/// weight (only where `scattered_only` is false: the sun's light is
/// white), and the lengths times [`sh9`] of the direction and the
/// weight's luminance.
fn run(
    grid: &LightVolumeGrid,
    sigma: &[f32],
    photons: u32,
    seed: u32,
    scattered_only: bool,
    start: &Start,
    progress: &dyn Fn(f32),
) -> (Vec<Vec3>, Vec<[f32; 9]>) {
    let n = grid.len();
    let colours = if scattered_only { 0 } else { n };
    let chunk = photons.div_ceil(CHUNKS).max(1);
    let chunks = photons.div_ceil(chunk);
    let mut length = vec![Vec3::ZERO; colours];
    let mut sh = vec![[0.0f32; 9]; n];
    // Chunks traced in parallel a batch (one per thread) at a time and
    // summed in their order: the same light from the same seed on any
    // number of threads.
    let at_once = rayon::current_num_threads().max(1) as u32;
    for batch in (0..chunks).step_by(at_once as usize) {
        let parts: Vec<_> = (batch..(batch + at_once).min(chunks))
            .into_par_iter()
            .map(|c| {
                let mut tracks = Tracks {
                    length: vec![Vec3::ZERO; colours],
                    sh: vec![[0.0f32; 9]; n],
                };
                for p in c * chunk..((c + 1) * chunk).min(photons) {
                    let mut rng = Rng::new(p, seed);
                    let start = start(&mut rng);
                    follow(grid, sigma, start, scattered_only, &mut rng, &mut tracks);
                }
                tracks
            })
            .collect();
        for t in parts {
            length.iter_mut().zip(&t.length).for_each(|(a, b)| *a += *b);
            for (a, b) in sh.iter_mut().zip(&t.sh) {
                for k in 0..9 {
                    a[k] += b[k];
                }
            }
        }
        progress((batch + at_once).min(chunks) as f32 / chunks as f32);
    }
    (length, sh)
}

/// The photons are traced in this many chunks, one per thread at a time,
/// each into its own copy of the cells (15 MB on fair weather), summed in
/// order: 16 rather than 64 takes 0.16 s of copies and sums off a
/// fair-weather build on 2 cores, and still keeps 16 threads busy.
const CHUNKS: u32 = 16;

/// Where a walk adds its tracks: per cell, the lengths times the RGB
/// weight (empty when not asked for), and the lengths times [`sh9`] of
/// the direction and the weight's luminance.
struct Tracks {
    length: Vec<Vec3>,
    sh: Vec<[f32; 9]>,
}

/// One photon's walk from `start` (a grid position, a direction and an
/// RGB weight), its tracks added to `tracks` (after its first scattering
/// with `scattered_only`; `follow` in WGSL, which adds them to fixed-point
/// cells).
fn follow(
    grid: &LightVolumeGrid,
    sigma: &[f32],
    start: (Vec3, Vec3, Vec3),
    scattered_only: bool,
    rng: &mut Rng,
    tracks: &mut Tracks,
) {
    let (mut pos, mut dir, colour) = start;
    let h = grid.cell_m;
    let cells = grid.cells.as_ivec3();
    let lum = luminance(colour);
    let mut weight = 1.0f32;
    let mut scattered = !scattered_only;
    let mut crossed = 0u32;
    loop {
        // The optical depth to the next collision.
        let mut left = -(1.0 - rng.next()).ln();
        // The flight's direction's harmonics, the same in every cell it
        // crosses.
        let y = sh9(dir);
        // Fly cell by cell until it is spent or the photon leaves.
        loop {
            let cell = pos.floor().as_ivec3();
            if cell.y < 0 || cell.y >= cells.y {
                return;
            }
            crossed += 1;
            if crossed > CELLS_PER_PHOTON_MAX {
                return;
            }
            let idx = grid.index(cell.x, cell.y, cell.z);
            let mut exit = f32::INFINITY;
            let mut axis = 0;
            for a in 0..3 {
                let d = dir[a];
                if d.abs() < 1e-9 {
                    continue;
                }
                let face = if d > 0.0 {
                    cell[a] as f32 + 1.0
                } else {
                    cell[a] as f32
                };
                let t = (face - pos[a]) * h[a] / d;
                if t < exit {
                    exit = t;
                    axis = a;
                }
            }
            let exit = exit.max(0.0);
            let s = sigma[idx];
            let (travel, hit) = if s * exit >= left {
                (left / s, true)
            } else {
                left -= s * exit;
                (exit, false)
            };
            if !travel.is_finite() {
                return;
            }
            if scattered {
                if !tracks.length.is_empty() {
                    tracks.length[idx] += colour * (weight * travel);
                }
                let c = &mut tracks.sh[idx];
                for k in 0..9 {
                    c[k] += y[k] * (weight * travel * lum);
                }
            }
            pos += dir * travel / h;
            if !pos.is_finite() {
                return;
            }
            if hit {
                break;
            }
            // Onto the next cell, across the face it left by.
            pos[axis] = if dir[axis] > 0.0 {
                cell[axis] as f32 + 1.0
            } else {
                cell[axis] as f32 - 1e-4
            };
            pos.x = pos.x.rem_euclid(cells.x as f32);
            pos.z = pos.z.rem_euclid(cells.z as f32);
        }
        weight *= ALBEDO;
        scattered = true;
        if weight < ROULETTE_WEIGHT {
            if rng.next() < 0.5 {
                return;
            }
            weight *= 2.0;
        }
        dir = scatter(dir, rng);
    }
}

#[cfg(test)]
#[path = "light_transport_tests.rs"]
mod tests;
