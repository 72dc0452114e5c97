//! The pseudo-spheroid renderer's CPU twin (Jimenez de Parga & Gomez
//! Palomo 2018; WGSL in `shaders/spheroids.wgsl`, each function of the
//! same name): every cloudy parcel a flattened ellipsoid whose surface an
//! fBm moves in and out (their Eq. 2), the ray marched only across the
//! spheroids it meets (the nearest [`MAX_CANDIDATES`], their spans merged
//! so that no stretch is marched twice), and the sun's optical depth read
//! from a [`LightGrid`] precomputed on the CPU (their illumination pass)
//! instead of a shadow ray per sample. The light is the cloud map's own:
//! the same phase functions and multiple-scattering octaves
//! ([`super::lighting::sun_scattering`]), ambient and sky, under the analytic sky (its
//! pipeline binds no sky tables).

use bytemuck::{Pod, Zeroable};
use glam::{Vec3, Vec4};
use rayon::prelude::*;

use super::frame::Frame;
use super::sky::sun_direction;
use super::standalone::{
    StandaloneMarch, analytic, hazed_clouds, render_standalone, standalone_light, standalone_step,
};
use super::tone_map::to_srgb8;

/// How far the fBm moves a spheroid's surface (κ of their Eq. 2).
pub const SPHEROID_KAPPA: f32 = 0.35;
/// The spheroids a ray keeps (the nearest, by entry distance).
pub const MAX_CANDIDATES: u32 = 16;
/// Octaves of the fBm.
pub const FBM_OCTAVES: u32 = 4;
/// The fBm's spread about 0.5 is widened by this (clamped to 0..1): four
/// octaves of value noise deviate about 0.1 from their mean, which moved
/// the surface by ±7 % and left smooth balls; widened, it moves by up to
/// κ, the lumpy surface of their Fig. 6.
pub const FBM_CONTRAST: f32 = 3.0;
/// The light grid's voxels along x, y (up) and z.
pub const LIGHT_GRID_DIMS: [usize; 3] = [96, 24, 96];

// Keep in sync with shaders/spheroids.wgsl: Spheroid.
/// One cloudy parcel as a pseudo-spheroid: world centre and horizontal
/// semi-axis (m); fill (0..1) and the vertical semi-axis over the
/// horizontal one (`crate::prepare::spheroids` makes them).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Spheroid {
    pub centre_radius: [f32; 4],
    pub shape: [f32; 4],
}

const _: () = assert!(size_of::<Spheroid>() == 32);

impl Spheroid {
    fn centre(&self) -> Vec3 {
        Vec3::from_slice(&self.centre_radius[..3])
    }
}

/// The sun's optical depth on a grid over the spheroids' box, built on
/// the CPU whenever the spheroids or the sun change.
#[derive(Debug, Clone, PartialEq)]
pub struct LightGrid {
    /// The box's lowest corner, m.
    pub origin: Vec3,
    /// The box's size, m.
    pub extent: Vec3,
    /// Voxels along x, y, z.
    pub dims: [usize; 3],
    /// Optical depth towards the sun at each voxel centre, x fastest.
    pub depth: Vec<f32>,
}

impl LightGrid {
    /// The grid for `spheroids` lit from `sun_dir`, the densest cloud's
    /// extinction `extinction_per_m`: each voxel's density is the
    /// spheroids' mean profile (the fBm at its mean, 0.5), and its depth
    /// the density integrated towards the sun across the box, in steps of
    /// at most half a voxel on every axis.
    pub fn build(spheroids: &[Spheroid], sun_dir: Vec3, extinction_per_m: f32) -> Self {
        if spheroids.is_empty() {
            return Self {
                origin: Vec3::ZERO,
                extent: Vec3::ONE,
                dims: [1, 1, 1],
                depth: vec![0.0],
            };
        }
        let grow = 1.0 + SPHEROID_KAPPA;
        let half = |s: &Spheroid| {
            let r = s.centre_radius[3] * grow;
            Vec3::new(r, r * s.shape[1], r)
        };
        let lo = spheroids
            .iter()
            .map(|s| s.centre() - half(s))
            .fold(Vec3::splat(f32::MAX), Vec3::min);
        let hi = spheroids
            .iter()
            .map(|s| s.centre() + half(s))
            .fold(Vec3::splat(f32::MIN), Vec3::max);
        let dims = LIGHT_GRID_DIMS;
        let extent = (hi - lo).max(Vec3::splat(1.0));
        let voxel = extent / Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32);
        let at = |i: usize, j: usize, k: usize| (k * dims[1] + j) * dims[0] + i;
        let centre = |i: usize, j: usize, k: usize| {
            lo + (Vec3::new(i as f32, j as f32, k as f32) + 0.5) * voxel
        };
        // The density: every spheroid splatted over the voxels of its box.
        let mut sum = vec![0.0f32; dims[0] * dims[1] * dims[2]];
        for s in spheroids {
            let (a, b) = (s.centre() - half(s), s.centre() + half(s));
            let first = ((a - lo) / voxel - 0.5).ceil().max(Vec3::ZERO);
            let last = ((b - lo) / voxel - 0.5).floor();
            let weight = 0.3 + 0.7 * s.shape[0];
            for k in first.z as usize..=(last.z.max(0.0) as usize).min(dims[2] - 1) {
                for j in first.y as usize..=(last.y.max(0.0) as usize).min(dims[1] - 1) {
                    for i in first.x as usize..=(last.x.max(0.0) as usize).min(dims[0] - 1) {
                        let d = spheroid_distance(centre(i, j, k), s);
                        sum[at(i, j, k)] += weight * spheroid_profile(d, 0.5);
                    }
                }
            }
        }
        let sigma: Vec<f32> = sum.iter().map(|s| extinction_per_m * s.min(1.0)).collect();
        let density = LightGrid {
            origin: lo,
            extent,
            dims,
            depth: sigma,
        };
        let reach = (sun_dir.abs() / voxel).max_element();
        let h = 0.5 / reach.max(1e-6);
        let max_steps = 4 * (dims[0] + dims[1] + dims[2]);
        let mut depth = vec![0.0f32; sum.len()];
        depth
            .par_chunks_mut(dims[0] * dims[1])
            .enumerate()
            .for_each(|(k, slice)| {
                for j in 0..dims[1] {
                    for i in 0..dims[0] {
                        let p0 = centre(i, j, k);
                        let mut tau = 0.0;
                        for n in 0..max_steps {
                            let p = p0 + sun_dir * ((n as f32 + 0.5) * h);
                            if p.cmplt(lo).any() || p.cmpgt(lo + extent).any() {
                                break;
                            }
                            tau += light_grid_depth(p, &density) * h;
                        }
                        slice[j * dims[0] + i] = tau;
                    }
                }
            });
        Self {
            origin: lo,
            extent,
            dims,
            depth,
        }
    }

    /// The storage buffer's words: origin, extent (vec4 each), dims
    /// (vec4u), then the depths (the WGSL `LightGrid`), padded to 16 bytes.
    pub fn to_words(&self) -> Vec<u32> {
        let mut w = Vec::with_capacity(12 + self.depth.len());
        for v in [self.origin, self.extent] {
            w.extend(v.to_array().map(f32::to_bits));
            w.push(0);
        }
        w.extend(self.dims.map(|d| d as u32));
        w.push(0);
        w.extend(self.depth.iter().map(|d| d.to_bits()));
        // The struct's size is a whole number of its 16-byte alignment.
        w.resize(w.len().div_ceil(4) * 4, 0);
        w
    }
}

/// A 24-bit hash of an integer lattice point, in 0..1.
#[inline]
pub fn spheroid_hash(x: i32, y: i32, z: i32) -> f32 {
    let mut h = (x as u32).wrapping_mul(0x8da6_b343)
        ^ (y as u32).wrapping_mul(0xd816_3841)
        ^ (z as u32).wrapping_mul(0xcb1a_b31f);
    h ^= h >> 13;
    h = h.wrapping_mul(0x5bd1_e995);
    h ^= h >> 15;
    (h & 0x00ff_ffff) as f32 / 16_777_216.0
}

/// Smoothly interpolated value noise on the integer lattice, in 0..1.
#[inline]
pub fn spheroid_value_noise(q: Vec3) -> f32 {
    let f = q.floor();
    let t = q - f;
    let w = t * t * (Vec3::splat(3.0) - 2.0 * t);
    let (x, y, z) = (f.x as i32, f.y as i32, f.z as i32);
    let mix = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = mix(spheroid_hash(x, y, z), spheroid_hash(x + 1, y, z), w.x);
    let x10 = mix(
        spheroid_hash(x, y + 1, z),
        spheroid_hash(x + 1, y + 1, z),
        w.x,
    );
    let x01 = mix(
        spheroid_hash(x, y, z + 1),
        spheroid_hash(x + 1, y, z + 1),
        w.x,
    );
    let x11 = mix(
        spheroid_hash(x, y + 1, z + 1),
        spheroid_hash(x + 1, y + 1, z + 1),
        w.x,
    );
    mix(mix(x00, x10, w.y), mix(x01, x11, w.y), w.z)
}

/// Fractal Brownian motion in 0..1: [`FBM_OCTAVES`] octaves of value
/// noise, each at about twice the frequency and half the weight of the
/// last, normalised by the weights, its spread widened by
/// [`FBM_CONTRAST`]; features of `scale_m`.
#[inline]
pub fn spheroid_fbm(p: Vec3, scale_m: f32) -> f32 {
    let mut q = p / scale_m;
    let (mut sum, mut weight, mut total) = (0.0, 0.5, 0.0);
    for i in 0..FBM_OCTAVES {
        sum += weight * spheroid_value_noise(q + Vec3::splat(i as f32 * 17.31));
        total += weight;
        weight *= 0.5;
        q *= 2.03;
    }
    (0.5 + (sum / total - 0.5) * FBM_CONTRAST).clamp(0.0, 1.0)
}

/// Their Eq. 2, `γ = exp(-d / ((1 - κ) + 2κ fbm))` at ellipsoidal
/// distance `d`, mapped to 0 where γ falls to e⁻¹ (the surface the fBm has
/// moved) and 1 at the centre: the spheroid's density profile.
#[inline]
pub fn spheroid_profile(d: f32, fbm: f32) -> f32 {
    let gamma = (-d / ((1.0 - SPHEROID_KAPPA) + 2.0 * SPHEROID_KAPPA * fbm)).exp();
    let edge = (-1.0f32).exp();
    ((gamma - edge) / (1.0 - edge)).clamp(0.0, 1.0)
}

/// The ellipsoidal distance of `p` from `s` (1 on its nominal surface).
#[inline]
pub fn spheroid_distance(p: Vec3, s: &Spheroid) -> f32 {
    let d = p - s.centre();
    (Vec3::new(d.x, d.y / s.shape[1], d.z) / s.centre_radius[3]).length()
}

/// Entry and exit distances of the ray through `s` grown by `1 + κ` (the
/// farthest the fBm moves its surface); `x > y`: missed.
#[inline]
pub fn spheroid_hit(origin: Vec3, dir: Vec3, s: &Spheroid) -> (f32, f32) {
    let scale =
        Vec3::new(1.0, 1.0 / s.shape[1], 1.0) / (s.centre_radius[3] * (1.0 + SPHEROID_KAPPA));
    let o = (origin - s.centre()) * scale;
    let d = dir * scale;
    let a = d.dot(d);
    let b = o.dot(d);
    let c = o.dot(o) - 1.0;
    let h = b * b - a * c;
    if h <= 0.0 {
        return (1.0, 0.0);
    }
    let r = h.sqrt();
    ((-b - r) / a, (-b + r) / a)
}

/// Extinction (1/m) at `p` from the candidates `ids`: each spheroid's
/// profile weighted by its fill, summed and capped at the densest cloud.
#[inline]
pub fn spheroid_density(
    p: Vec3,
    ids: &[u32],
    spheroids: &[Spheroid],
    fbm: f32,
    extinction_per_m: f32,
) -> f32 {
    let sum: f32 = ids
        .iter()
        .map(|&i| {
            let s = &spheroids[i as usize];
            (0.3 + 0.7 * s.shape[0]) * spheroid_profile(spheroid_distance(p, s), fbm)
        })
        .sum();
    extinction_per_m * sum.min(1.0)
}

/// The sun's optical depth at `p`, read trilinearly from `grid` (0
/// outside its box).
#[inline]
pub fn light_grid_depth(p: Vec3, grid: &LightGrid) -> f32 {
    let dims = Vec3::new(
        grid.dims[0] as f32,
        grid.dims[1] as f32,
        grid.dims[2] as f32,
    );
    let g = (p - grid.origin) / grid.extent * dims - 0.5;
    if g.cmplt(Vec3::splat(-0.5)).any() || g.cmpgt(dims - 0.5).any() {
        return 0.0;
    }
    let hi = dims - 1.0;
    let f = g.clamp(Vec3::ZERO, hi);
    let i0 = f.floor();
    let i1 = (i0 + 1.0).min(hi);
    let t = f - i0;
    let (nx, ny) = (grid.dims[0], grid.dims[1]);
    let at = |x: f32, y: f32, z: f32| grid.depth[(z as usize * ny + y as usize) * nx + x as usize];
    let mix = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = mix(at(i0.x, i0.y, i0.z), at(i1.x, i0.y, i0.z), t.x);
    let x10 = mix(at(i0.x, i1.y, i0.z), at(i1.x, i1.y, i0.z), t.x);
    let x01 = mix(at(i0.x, i0.y, i1.z), at(i1.x, i0.y, i1.z), t.x);
    let x11 = mix(at(i0.x, i1.y, i1.z), at(i1.x, i1.y, i1.z), t.x);
    mix(mix(x00, x10, t.y), mix(x01, x11, t.y), t.z)
}

/// The nearest [`MAX_CANDIDATES`] spheroids the ray meets before
/// `max_t`, sorted by entry: (index, entry, exit).
fn spheroid_candidates(
    origin: Vec3,
    dir: Vec3,
    max_t: f32,
    spheroids: &[Spheroid],
) -> Vec<(u32, f32, f32)> {
    let mut out: Vec<(u32, f32, f32)> = Vec::with_capacity(MAX_CANDIDATES as usize);
    for (i, s) in spheroids.iter().enumerate() {
        let (h0, h1) = spheroid_hit(origin, dir, s);
        let (a, b) = (h0.max(0.0), h1.min(max_t));
        if b <= a {
            continue;
        }
        if out.len() == MAX_CANDIDATES as usize {
            if a >= out[out.len() - 1].1 {
                continue;
            }
            out.pop();
        }
        let k = out.partition_point(|c| c.1 <= a);
        out.insert(k, (i as u32, a, b));
    }
    out
}

/// The march of one ray through the spheroids (the twin of the WGSL
/// `march_spheroids`): premultiplied cloud radiance and opacity.
pub fn march_spheroids(
    origin: Vec3,
    dir: Vec3,
    dither: f32,
    spheroids: &[Spheroid],
    grid: &LightGrid,
    fr: &Frame,
) -> Vec4 {
    let q = &fr.quality;
    let d = &fr.density;
    let sky = &analytic(fr);
    let cand = spheroid_candidates(origin, dir, q.max_distance_m, spheroids);
    if cand.is_empty() {
        return Vec4::ZERO;
    }
    let ids: Vec<u32> = cand.iter().map(|c| c.0).collect();
    let mut segs: Vec<(f32, f32)> = vec![(cand[0].1, cand[0].2)];
    for c in &cand[1..] {
        let last = segs.len() - 1;
        if c.1 <= segs[last].1 {
            segs[last].1 = segs[last].1.max(c.2);
        } else {
            segs.push((c.1, c.2));
        }
    }
    let total: f32 = segs.iter().map(|s| s.1 - s.0).sum();
    let sun_dir = sun_direction(fr.sun_elevation_deg, fr.sun_azimuth_deg);
    let steps = q.steps.max(1);
    let dt = total / steps as f32;
    let l = standalone_light(sky, dir, sun_dir, fr);
    let mut march = StandaloneMarch::START;
    let (mut seg, mut before) = (0usize, 0.0f32);
    for i in 0..steps {
        let s = (i as f32 + dither) * dt;
        while seg + 1 < segs.len() && s >= before + segs[seg].1 - segs[seg].0 {
            before += segs[seg].1 - segs[seg].0;
            seg += 1;
        }
        let t = segs[seg].0 + (s - before);
        let p = origin + dir * t;
        let fbm = if d.detail_strength > 0.0 {
            spheroid_fbm(p, d.detail_scale_m)
        } else {
            0.5
        };
        let sigma_t = spheroid_density(p, &ids, spheroids, fbm, d.extinction_per_m);
        if sigma_t <= 0.0 {
            continue;
        }
        let tau_sun = light_grid_depth(p, grid);
        if standalone_step(&mut march, &l, p, t, dt, sigma_t, tau_sun, fr) {
            break;
        }
    }
    hazed_clouds(sky, &march, dir, sun_dir)
}

/// A `width x height` image of linear radiance (row-major), the twin of
/// the GPU's `fs_spheroids`: one march per pixel through its centre.
pub fn render_spheroids(
    width: u32,
    height: u32,
    fr: &Frame,
    spheroids: &[Spheroid],
    grid: &LightGrid,
) -> Vec<Vec3> {
    render_standalone(width, height, fr, 1, |origin, dir, dither| {
        march_spheroids(origin, dir, dither, spheroids, grid, fr)
    })
}

/// [`render_spheroids`] tone-mapped to sRGB8 with the frame's exposure.
pub fn render_spheroids_srgb8(
    width: u32,
    height: u32,
    fr: &Frame,
    spheroids: &[Spheroid],
    grid: &LightGrid,
) -> Vec<u8> {
    to_srgb8(
        &render_spheroids(width, height, fr, spheroids, grid),
        fr.quality.exposure,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(centre: Vec3, r: f32) -> Spheroid {
        Spheroid {
            centre_radius: [centre.x, centre.y, centre.z, r],
            shape: [1.0, 0.6, 0.0, 0.0],
        }
    }

    #[test]
    fn the_profile_is_one_at_the_centre_and_zero_past_the_moved_surface() {
        assert!((spheroid_profile(0.0, 0.5) - 1.0).abs() < 1e-6);
        // With the fBm at its mean the surface is the nominal one.
        assert!(spheroid_profile(1.0, 0.5).abs() < 1e-6);
        // The fBm pushes it out to 1 + κ and in to 1 - κ.
        assert!(spheroid_profile(1.2, 1.0) > 0.0);
        assert_eq!(spheroid_profile(1.0, 0.0), 0.0);
        assert_eq!(spheroid_profile(1.0 + SPHEROID_KAPPA, 1.0), 0.0);
    }

    #[test]
    fn rays_meet_the_grown_ellipsoid_where_geometry_says() {
        let s = one(Vec3::new(0.0, 1000.0, 0.0), 100.0);
        // Horizontal ray through the centre: enters at 100·(1+κ) before it.
        let (a, b) = spheroid_hit(Vec3::new(-1000.0, 1000.0, 0.0), Vec3::X, &s);
        let r = 100.0 * (1.0 + SPHEROID_KAPPA);
        assert!((a - (1000.0 - r)).abs() < 1e-2 && (b - (1000.0 + r)).abs() < 1e-2);
        // Vertical ray: the flattened axis, 0.6 of it.
        let (a, b) = spheroid_hit(Vec3::new(0.0, 0.0, 0.0), Vec3::Y, &s);
        assert!((b - a - 2.0 * 0.6 * r).abs() < 1e-2, "{a} {b}");
        // A ray passing above misses.
        let (a, b) = spheroid_hit(Vec3::new(-1000.0, 1100.0, 0.0), Vec3::X, &s);
        assert!(a > b);
    }

    #[test]
    fn candidates_are_the_nearest_sorted_by_entry() {
        let spheroids: Vec<Spheroid> = (0..40)
            .rev()
            .map(|k| one(Vec3::new(200.0 * k as f32, 0.0, 0.0), 50.0))
            .collect();
        let c = spheroid_candidates(Vec3::new(-100.0, 0.0, 0.0), Vec3::X, 1e6, &spheroids);
        assert_eq!(c.len(), MAX_CANDIDATES as usize);
        assert!(c.windows(2).all(|w| w[0].1 <= w[1].1));
        // The nearest: centres at 0, 200, ... (stored in reverse).
        let last = spheroids[c[c.len() - 1].0 as usize].centre_radius[0];
        assert_eq!(last, 200.0 * (MAX_CANDIDATES - 1) as f32);
    }

    #[test]
    fn the_light_grid_darkens_below_a_cloud_and_not_beside_it() {
        let s = one(Vec3::new(0.0, 1000.0, 0.0), 300.0);
        let far = one(Vec3::new(3000.0, 1000.0, 0.0), 300.0);
        let sun = Vec3::Y;
        let g = LightGrid::build(&[s, far], sun, 0.05);
        let below = light_grid_depth(Vec3::new(0.0, 1000.0 - 150.0, 0.0), &g);
        let top = light_grid_depth(Vec3::new(0.0, 1000.0 + 170.0, 0.0), &g);
        let beside = light_grid_depth(Vec3::new(1500.0, 900.0, 0.0), &g);
        // Through the cloud above: the profile's integral over about
        // 330 m of a 0.05/m core is several optical depths.
        assert!(below > 3.0, "below {below}");
        assert!(top < 0.5 * below, "top {top} below {below}");
        assert!(beside < 1e-3, "beside {beside}");
        let words = g.to_words();
        assert_eq!(words.len(), 12 + 96 * 24 * 96);
        assert_eq!(f32::from_bits(words[0]), g.origin.x);
    }

    #[test]
    fn the_fbm_stays_in_range_with_the_spread_of_noise() {
        let v: Vec<f32> = (0..2000)
            .map(|i| spheroid_fbm(Vec3::new(i as f32 * 37.1, 13.0 * i as f32, 5.0), 300.0))
            .collect();
        assert!(v.iter().all(|x| (0.0..=1.0).contains(x)));
        let mean = v.iter().sum::<f32>() / v.len() as f32;
        assert!((mean - 0.5).abs() < 0.05, "mean {mean}");
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / v.len() as f32).sqrt();
        assert!(sd > 0.2, "sd {sd}: the surface must move");
    }
}
