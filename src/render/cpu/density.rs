//! Cloud density inside the height band, from P and the cloud map
//! (README, "The renderer").

use glam::Vec3;

use crate::render::cloud_map::CloudMap;
use crate::sim::ProjectedField;

/// What the density needs besides the textures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DensityParams {
    /// Cloud base, m.
    pub band_bottom_m: f32,
    /// Highest possible cloud top, m.
    pub band_top_m: f32,
    /// Fraction of each P-covered cloud cell that becomes cloud, 0..=1.
    pub coverage: f32,
    /// Extinction of the densest cloud, 1/m.
    pub extinction_per_m: f32,
    /// Side of the square that P and the cloud map span, m.
    pub map_extent_m: f32,
    /// Strength of the 3D detail noise that erodes edges into billows,
    /// 0..=1 (0: off, the noise is not evaluated).
    pub detail_strength: f32,
    /// Size of the detail noise's features, m.
    pub detail_scale_m: f32,
}

/// The textures the density reads.
#[derive(Clone, Copy)]
pub struct Fields<'a> {
    pub p: &'a ProjectedField,
    pub cloud_map: &'a CloudMap,
}

/// Normalised height `η` of `y_m` in the band (may lie outside 0..1).
#[inline]
pub fn height_fraction(y_m: f32, d: &DensityParams) -> f32 {
    (y_m - d.band_bottom_m) / (d.band_top_m - d.band_bottom_m)
}

/// The part `[t0, t1]` of the ray `origin + t dir` (`t >= 0`, `t <= max_t`)
/// inside the slab `bottom <= y <= top`: camera below, inside or above the
/// band alike. `None` where the ray misses it.
#[inline]
pub fn band_segment(
    origin: Vec3,
    dir: Vec3,
    bottom: f32,
    top: f32,
    max_t: f32,
) -> Option<(f32, f32)> {
    let (t0, t1) = if dir.y.abs() < 1e-8 {
        if origin.y < bottom || origin.y > top {
            return None;
        }
        (0.0, max_t)
    } else {
        let (ta, tb) = ((bottom - origin.y) / dir.y, (top - origin.y) / dir.y);
        (ta.min(tb).max(0.0), ta.max(tb).min(max_t))
    };
    (t1 > t0).then_some((t0, t1))
}

#[inline]
fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// An integer hash of a lattice point to `[0, 1)` (the same u32 arithmetic
/// runs in WGSL).
#[inline]
pub fn hash3(x: i32, y: i32, z: i32) -> f32 {
    let mut h = (x as u32).wrapping_mul(0x8da6_b343)
        ^ (y as u32).wrapping_mul(0xd816_3841)
        ^ (z as u32).wrapping_mul(0xcb1a_b31f);
    h ^= h >> 13;
    h = h.wrapping_mul(0x5bd1_e995);
    h ^= h >> 15;
    (h & 0x00ff_ffff) as f32 / 16_777_216.0
}

/// Trilinear value noise with smooth weights, periodic with `period`
/// lattice cells in each axis (tileable), in `[0, 1)`.
#[inline]
pub fn value_noise3(q: Vec3, period: i32) -> f32 {
    let f = q.floor();
    let t = q - f;
    let w = t * t * (Vec3::splat(3.0) - 2.0 * t);
    let (x, y, z) = (f.x as i32, f.y as i32, f.z as i32);
    let h = |dx: i32, dy: i32, dz: i32| {
        hash3(
            (x + dx).rem_euclid(period),
            (y + dy).rem_euclid(period),
            (z + dz).rem_euclid(period),
        )
    };
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = lerp(h(0, 0, 0), h(1, 0, 0), w.x);
    let x10 = lerp(h(0, 1, 0), h(1, 1, 0), w.x);
    let x01 = lerp(h(0, 0, 1), h(1, 0, 1), w.x);
    let x11 = lerp(h(0, 1, 1), h(1, 1, 1), w.x);
    lerp(lerp(x00, x10, w.y), lerp(x01, x11, w.y), w.z)
}

/// Two octaves of [`value_noise3`] at world point `p` with features of
/// `scale_m`; tileable every 64 features.
#[inline]
pub fn detail_noise(p: Vec3, scale_m: f32) -> f32 {
    let q = p / scale_m;
    0.65 * value_noise3(q, 64) + 0.35 * value_noise3(q * 2.0 + Vec3::splat(17.3), 128)
}

/// Normalised height below which the base ramps up: the base is flat
/// because this ramp is the same everywhere.
pub const BASE_RAMP: f32 = 0.04;

/// The 2D footprint of the cloud at map coordinate `(u, v)`:
/// `(shape, η_top, fill)`, where shape is the cloud-map cell remapped by
/// coverage and P's coverage, `η_top` the local cloud top (taller with the
/// parcel height `h` and in the cell's middle: rounded tops), and fill P's
/// fill density. `(0, 0, 0)` where there is no cloud.
#[inline]
pub fn footprint(u: f32, v: f32, f: &Fields, d: &DensityParams) -> (f32, f32, f32) {
    let [c, h, fill] = f.p.sample(u, v);
    if c <= 1e-3 {
        return (0.0, 0.0, 0.0);
    }
    let [n, coarse] = f.cloud_map.sample(u, v);
    let cov = (d.coverage * c).clamp(0.0, 1.0);
    let shape = ((n - (1.0 - cov)) / cov.max(1e-3)).clamp(0.0, 1.0);
    if shape <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    let top = (0.15 + 0.85 * h).clamp(0.0, 1.0) * shape.sqrt() * (0.75 + 0.25 * coarse);
    (shape, top, fill)
}

/// Extinction coefficient σ_t (1/m) at world point `p`: zero outside the
/// band and where P has no coverage; a flat base ramp, a dome falling to
/// zero at the local top, scaled by P's fill density.
#[inline]
pub fn density_at(p: Vec3, f: &Fields, d: &DensityParams) -> f32 {
    let eta = height_fraction(p.y, d);
    if !(0.0..=1.0).contains(&eta) {
        return 0.0;
    }
    let detail = d.detail_strength > 0.0;
    // With detail, the map lookup is warped by the noise so the edges of
    // P's parcel discs become billowed, not straight walls.
    let (mut x, mut z, mut n) = (p.x, p.z, 0.0);
    if detail {
        n = detail_noise(p, d.detail_scale_m);
        let warp = d.detail_scale_m * d.detail_strength;
        x += (n - 0.5) * 2.0 * warp;
        z += (value_noise3(p / d.detail_scale_m + Vec3::splat(31.1), 64) - 0.5) * 2.0 * warp;
    }
    let (shape, mut top, fill) = footprint(x / d.map_extent_m, z / d.map_extent_m, f, d);
    if detail {
        top *= 1.0 - 0.3 * d.detail_strength * n;
    }
    if shape <= 0.0 || eta >= top {
        return 0.0;
    }
    let base = smoothstep(0.0, BASE_RAMP, eta);
    let t = eta / top;
    let dome = ((1.0 - t * t) * 3.0).clamp(0.0, 1.0);
    let mut profile = base * dome * (shape * 4.0).min(1.0);
    if detail {
        // Erode the thin parts most (edges), the core little.
        profile = (profile - d.detail_strength * n * (1.0 - profile)).max(0.0);
    }
    d.extinction_per_m * (0.3 + 0.7 * fill) * profile
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_noise_tiles_and_stays_in_range() {
        for k in 0..500 {
            let q = Vec3::new(
                k as f32 * 0.731,
                k as f32 * 0.377 + 0.1,
                k as f32 * 0.119 + 0.3,
            );
            let a = value_noise3(q, 64);
            assert!((0.0..1.0).contains(&a));
            let b = value_noise3(q + Vec3::new(64.0, -64.0, 128.0), 64);
            assert!((a - b).abs() < 1e-4, "{a} vs {b}");
        }
    }
}
