//! The sunlight scattered more than once, by Monte Carlo transport on the
//! light volume's grid: photons enter through the band's top along the
//! sun, fly through the cells' extinction (free paths sampled exactly in
//! the piecewise constant medium, cell by cell), scatter by the renderer's
//! phase function with its albedo, and leave through the band's top or
//! floor. Every flight after the first scattering is added to the cells
//! it crosses (the track-length estimator): its length to the fluence,
//! its length times its direction to the net flux. The result is the
//! same pair [`super::light_volume::LightVolume`] holds, the fluence and
//! flux of the sunlight scattered at least once, per unit sun irradiance,
//! without the diffusion approximation: forward scattering, the light
//! that crosses clear air from one cloud to another and a cloud's thin
//! edges are transported as they are.

use std::f32::consts::PI;

use glam::Vec3;
use rayon::prelude::*;

use super::exposure::luminance;
use super::light_volume::{DiffusionGrid, LIGHT_SUN_MIN};
use super::renderer::ALBEDO;

/// A photon's random numbers: a 32-bit PCG stream (O'Neill's RXS-M-XS
/// output), seeded per photon; 32 bits so that WGSL draws the same.
struct Rng(u32);

impl Rng {
    fn new(photon: u32, seed: u32) -> Self {
        let mut r = Self(photon ^ seed.wrapping_mul(0x9E37_79B9));
        r.next();
        r
    }

    /// Uniform in `[0, 1)`.
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
        let s = self.0;
        let word = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277_803_737);
        let x = (word >> 22) ^ word;
        (x >> 8) as f32 / (1u32 << 24) as f32
    }
}

/// A cosine drawn from the Henyey-Greenstein phase of asymmetry `g`.
fn sample_hg(g: f32, u: f32) -> f32 {
    if g.abs() < 1e-3 {
        return 1.0 - 2.0 * u;
    }
    let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
}

/// A direction scattered from `dir` by the dual lobe
/// ([`super::lighting::phase_dual`] at full eccentricity).
fn scatter(dir: Vec3, rng: &mut Rng) -> Vec3 {
    let g = if rng.next() < 0.75 { 0.8 } else { -0.3 };
    let cos = sample_hg(g, rng.next());
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = 2.0 * PI * rng.next();
    let (a, b) = dir.any_orthonormal_pair();
    (dir * cos + (a * phi.cos() + b * phi.sin()) * sin).normalize()
}

/// The most cells one photon crosses before it is dropped: a flight
/// nearly level in clear air would otherwise circle the repeating domain.
const CELLS_PER_PHOTON_MAX: u32 = 20_000;
/// The weight under which Russian roulette may end a photon.
const ROULETTE_WEIGHT: f32 = 0.1;

/// The fluence and the net flux of the sunlight scattered at least once,
/// per cell of `grid` and per unit sun irradiance, from `photons` photons
/// (seeded by `seed`) under the sun `sun_dir` through the cells'
/// extinction `sigma`. Under a sun below [`LIGHT_SUN_MIN`], nothing.
pub fn trace(
    grid: &DiffusionGrid,
    sigma: &[f32],
    sun_dir: Vec3,
    photons: u32,
    seed: u32,
) -> (Vec<f32>, Vec<Vec3>) {
    let n = grid.len();
    if sun_dir.y < LIGHT_SUN_MIN || photons == 0 {
        return (vec![0.0; n], vec![Vec3::ZERO; n]);
    }
    let cells = grid.cells.as_vec3();
    let (length, moment) = run(grid, sigma, photons, seed, true, &|rng: &mut Rng| {
        let pos = Vec3::new(rng.next() * cells.x, cells.y - 1e-4, rng.next() * cells.z);
        (pos, -sun_dir, Vec3::ONE)
    });
    // Each photon carries the power μ A / N through the domain's top of
    // area A; the fluence is the track length per volume.
    let scale = sun_dir.y * area(grid) / photons as f32 / volume(grid);
    (
        length.iter().map(|l| l.x * scale).collect(),
        moment.iter().map(|m| *m * scale).collect(),
    )
}

fn area(grid: &DiffusionGrid) -> f32 {
    let extent = grid.cell_m * grid.cells.as_vec3();
    extent.x * extent.z
}

fn volume(grid: &DiffusionGrid) -> f32 {
    grid.cell_m.x * grid.cell_m.y * grid.cell_m.z
}

/// The fluence (RGB) and the net flux (of the luminance) of the light of
/// an environment of radiance `radiance(u)` from direction `u`, entering
/// the band through its top (from the upper hemisphere) or its floor
/// (`from_top` false: the lower), all orders of scattering and the
/// unscattered light.
pub fn trace_sky(
    grid: &DiffusionGrid,
    sigma: &[f32],
    radiance: &(dyn Fn(Vec3) -> Vec3 + Sync),
    from_top: bool,
    photons: u32,
    seed: u32,
) -> (Vec<Vec3>, Vec<Vec3>) {
    let cells = grid.cells.as_vec3();
    let (length, moment) = run(grid, sigma, photons, seed, false, &|rng: &mut Rng| {
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
    });
    let scale = area(grid) / photons as f32 / volume(grid);
    (
        length.iter().map(|l| *l * scale).collect(),
        moment.iter().map(|m| *m * scale).collect(),
    )
}

type Start<'a> = dyn Fn(&mut Rng) -> (Vec3, Vec3, Vec3) + Sync + 'a;

/// `photons` walks from `start` (a grid position, a direction and an RGB
/// weight), their tracks summed per cell (after the first scattering
/// with `scattered_only`): the lengths times the weight, and the lengths
/// times the direction and the weight's luminance.
fn run(
    grid: &DiffusionGrid,
    sigma: &[f32],
    photons: u32,
    seed: u32,
    scattered_only: bool,
    start: &Start,
) -> (Vec<Vec3>, Vec<Vec3>) {
    let n = grid.len();
    let chunk = photons.div_ceil(CHUNKS).max(1);
    let chunks = photons.div_ceil(chunk);
    let mut length = vec![Vec3::ZERO; n];
    let mut moment = vec![Vec3::ZERO; n];
    // Chunks traced in parallel a batch at a time and summed in their
    // order: the same light from the same seed on any number of threads.
    for batch in (0..chunks).step_by(CHUNKS_AT_ONCE as usize) {
        let parts: Vec<_> = (batch..(batch + CHUNKS_AT_ONCE).min(chunks))
            .into_par_iter()
            .map(|c| {
                let mut length = vec![Vec3::ZERO; n];
                let mut moment = vec![Vec3::ZERO; n];
                for p in c * chunk..((c + 1) * chunk).min(photons) {
                    let mut rng = Rng::new(p, seed);
                    let (pos, dir, colour) = start(&mut rng);
                    let tracks = Tracks {
                        length: &mut length,
                        moment: &mut moment,
                    };
                    follow(
                        grid,
                        sigma,
                        (pos, dir, colour),
                        scattered_only,
                        &mut rng,
                        tracks,
                    );
                }
                (length, moment)
            })
            .collect();
        for (l, m) in parts {
            length.iter_mut().zip(&l).for_each(|(a, b)| *a += *b);
            moment.iter_mut().zip(&m).for_each(|(a, b)| *a += *b);
        }
    }
    (length, moment)
}

/// The photons are traced in this many chunks, [`CHUNKS_AT_ONCE`] at a
/// time, each into its own copy of the cells.
const CHUNKS: u32 = 64;
const CHUNKS_AT_ONCE: u32 = 8;

/// Where a walk adds its tracks: per cell, the lengths times the weight
/// and the lengths times the direction and the weight's luminance.
struct Tracks<'a> {
    length: &'a mut [Vec3],
    moment: &'a mut [Vec3],
}

/// One photon's walk from `start` (a grid position, a direction and an
/// RGB weight), its tracks added to `tracks` (after its first scattering
/// with `scattered_only`).
fn follow(
    grid: &DiffusionGrid,
    sigma: &[f32],
    start: (Vec3, Vec3, Vec3),
    scattered_only: bool,
    rng: &mut Rng,
    tracks: Tracks,
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
            // Distance (m) to the cell's faces along `dir`.
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
                tracks.length[idx] += colour * (weight * travel);
                tracks.moment[idx] += dir * (weight * travel * lum);
            }
            pos += dir * travel / h;
            if !pos.is_finite() {
                return;
            }
            if hit {
                break;
            }
            // Step just past the face, and wrap across the domain.
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
mod tests {
    use glam::UVec3;

    use super::*;

    /// A band `layers` cells of 50 m high over a 640 m square that
    /// repeats (so, endless), of uniform extinction `sigma` per metre.
    fn layer(sigma: f32, layers: u32) -> (DiffusionGrid, Vec<f32>) {
        let grid = DiffusionGrid {
            cells: UVec3::new(8, layers, 8),
            cell_m: Vec3::new(80.0, 50.0, 80.0),
            bottom_m: 1000.0,
        };
        let n = grid.len();
        (grid, vec![sigma; n])
    }

    /// The mean of `values` over layer `j`.
    fn layer_mean<T: Copy + std::iter::Sum<T> + std::ops::Div<f32, Output = T>>(
        grid: &DiffusionGrid,
        values: &[T],
        j: u32,
    ) -> T {
        let n = (grid.cells.x * grid.cells.z) as usize;
        let j = j as usize;
        values[j * n..(j + 1) * n].iter().copied().sum::<T>() / n as f32
    }

    #[test]
    fn clear_air_under_a_uniform_sky_holds_its_radiance() {
        // Radiance L from every direction of the upper hemisphere: the
        // fluence is 2π L and the net flux π L straight down, at every
        // height (nothing scatters or absorbs it).
        let (grid, sigma) = layer(0.0, 6);
        let sky = Vec3::new(0.2, 0.5, 1.0);
        let (phi, flux) = trace_sky(&grid, &sigma, &|_| sky, true, 400_000, 3);
        let lum = luminance(sky);
        for j in 0..6 {
            let p = layer_mean(&grid, &phi, j);
            let f = layer_mean(&grid, &flux, j);
            let expected = sky * 2.0 * PI;
            assert!(
                ((p - expected) / expected).abs().max_element() < 0.03,
                "layer {j}: {p} vs {expected}"
            );
            assert!((f.y / (-PI * lum) - 1.0).abs() < 0.01, "layer {j}: {f}");
            assert!(f.x.abs().max(f.z.abs()) < 0.02 * PI * lum, "layer {j}: {f}");
        }
        // From below instead, the flux points up.
        let (_, flux) = trace_sky(&grid, &sigma, &|_| sky, false, 100_000, 4);
        assert!(layer_mean(&grid, &flux, 3).y > 0.99 * PI * lum);
    }

    #[test]
    fn deep_in_a_thick_layer_the_light_decays_at_the_diffusion_rate() {
        // Far from a thick layer's faces the scattered light settles into
        // its slowest mode, which falls as e^{-κ z}; for weak absorption
        // κ = σ √(3 (1 - ϖ)(1 - g)) (the diffusion length; Case & Zweifel's
        // asymptotic mode to first order in 1 - ϖ), 0.0072/m here. Every
        // layer of 50 m deeper keeps e^{-50 κ} = 0.70 of the light.
        let sigma_t = 0.06;
        let (grid, sigma) = layer(sigma_t, 24);
        let (phi, flux) = trace(&grid, &sigma, Vec3::Y, 400_000, 5);
        let kappa = sigma_t * (3.0 * (1.0 - ALBEDO) * (1.0 - 0.525_f32)).sqrt();
        // Layers 9-15: 450-750 m from the top (optical depth 27-45),
        // 450 m and more from the floor.
        let rate = (layer_mean(&grid, &phi, 15) / layer_mean(&grid, &phi, 9)).ln() / (6.0 * 50.0);
        assert!(
            (rate / kappa - 1.0).abs() < 0.1,
            "decay {rate} /m against {kappa} /m"
        );
        // The light flows down, away from the sun's side.
        assert!(layer_mean(&grid, &flux, 12).y < 0.0);
        // Near the top, what the layer reflects flows back up.
        assert!(layer_mean(&grid, &flux, 23).y > 0.0);
    }

    #[test]
    fn no_light_without_a_sun_or_photons() {
        let (grid, sigma) = layer(0.02, 4);
        let low = Vec3::new(1.0, 0.5 * LIGHT_SUN_MIN, 0.0).normalize();
        for (sun, photons) in [(low, 1000), (Vec3::Y, 0)] {
            let (phi, flux) = trace(&grid, &sigma, sun, photons, 1);
            assert!(phi.iter().all(|p| *p == 0.0));
            assert!(flux.iter().all(|f| *f == Vec3::ZERO));
        }
    }

    #[test]
    fn the_same_seed_gives_the_same_light() {
        // However rayon splits the photons among threads.
        let (grid, sigma) = layer(0.03, 6);
        let sun = Vec3::new(0.3, 0.8, 0.2).normalize();
        let a = trace(&grid, &sigma, sun, 20_000, 9);
        let b = trace(&grid, &sigma, sun, 20_000, 9);
        assert_eq!(a, b);
        let c = trace(&grid, &sigma, sun, 20_000, 10);
        assert_ne!(a.0, c.0);
    }
}
