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

/// Three octaves of [`value_noise3`] at world point `p` with features of
/// `scale_m`; tileable every 64 features.
#[inline]
pub fn detail_noise(p: Vec3, scale_m: f32) -> f32 {
    let q = p / scale_m;
    0.5 * value_noise3(q, 64)
        + 0.3 * value_noise3(q * 2.0 + Vec3::splat(17.3), 128)
        + 0.2 * value_noise3(q * 4.0 + Vec3::splat(5.9), 256)
}

/// Normalised height below which the base ramps up: the base is flat
/// because this ramp is the same everywhere.
pub const BASE_RAMP: f32 = 0.04;

/// Width of the density's ramp above the threshold, in units of the
/// cloud field's value: how soft a cloud's surface is.
pub const SURFACE_RAMP: f32 = 0.08;

/// The 2D part of the cloud at map coordinate `(u, v)`: `(cover, top,
/// fill, m)`. `cover` is the local cloud fraction the parcels ask for
/// (the scene's coverage times P's spread coverage), `top` the local
/// cloud top (normalised; from the parcels' height, taller where the
/// map's large-scale pattern is high), `fill` P's fill, and
/// `m` the cloud map's multi-scale value there. `(0, 0, 0, 0)` where P
/// has no coverage.
#[inline]
pub fn footprint(u: f32, v: f32, f: &Fields, d: &DensityParams) -> (f32, f32, f32, f32) {
    let [c, h, fill] = f.p.sample(u, v);
    if c <= 1e-3 {
        return (0.0, 0.0, 0.0, 0.0);
    }
    let [m, large] = f.cloud_map.sample(u, v);
    let cover = (d.coverage * c).clamp(0.0, 1.0);
    let top = (0.2 + 0.8 * h).clamp(0.0, 1.0) * (0.7 + 0.3 * large);
    (cover, top, fill, m)
}

/// Length scale of the domain warp, m: its sines have wavelengths of
/// 2π times this over 0.67-1.13 (50-85 km), in six directions, with
/// incommensurate frequencies, so they never line up again.
pub const WARP_SCALE_M: f32 = 9000.0;
/// Amplitude of each of the warp's three sines per axis, m (in metres, not
/// domain widths, so the warp's stretch stays under ~40 % whatever the
/// domain's size). Chosen with `cumulus stats`' repetition measure on the
/// 10 km domains: 1,500 m over 7-12 km left the period's correlation at
/// 0.08-0.2 (rows still there); 1,700 m over 9 km hides it (0.024 and
/// 0.032 against 0.045-0.049 at other lags).
pub const WARP_AMPLITUDE_M: f32 = 1700.0;

/// The displacement (map units, for a map of `extent_m`) of the lookups
/// into P and the cloud map at world `(x, z)`: a sum of sines of incommensurate wavelengths, smooth
/// (it stretches the clouds by up to ~40 % locally, in directions that
/// change across the sky) and not periodic. The
/// simulated domain tiles the sky; without the warp the same clouds came
/// back every domain width in rows to the horizon, and with it the copy
/// one domain width away is looked up up to a domain width elsewhere.
#[inline]
pub fn domain_warp(x: f32, z: f32, extent_m: f32) -> (f32, f32) {
    let (a, b) = (x / WARP_SCALE_M, z / WARP_SCALE_M);
    let amplitude = WARP_AMPLITUDE_M / extent_m;
    (
        amplitude
            * ((b + 1.3).sin()
                + ((0.8 * a + 0.6 * b) * 0.91 + 4.1).sin()
                + ((0.3 * a - 0.95 * b) * 0.73 + 0.5).sin()),
        amplitude
            * ((a * 1.13 + 0.7).sin()
                + ((0.6 * a - 0.8 * b) * 0.83 + 2.3).sin()
                + ((0.95 * a + 0.3 * b) * 0.67 + 5.2).sin()),
    )
}

/// Distances from the simulated domain's centre, in domain widths, over
/// which the warp and the weather grow from nothing to full: the
/// simulated copy of the domain (its corners are 0.71 from the centre) is
/// drawn where its parcels are, as P says (the per-parcel baseline and an
/// application's own use of the parcels agree with the picture), and the
/// copies around it are warped. A slower ramp (to 2.0 or 2.5) left the
/// period visible in `cumulus stats`' repetition measure.
pub const WARP_RAMP: (f32, f32) = (0.72, 1.3);

/// The weight of the [`domain_warp`] at world `(x, z)` (0 over the
/// simulated domain, 1 from [`WARP_RAMP`]'s outer distance on).
#[inline]
pub fn warp_weight(x: f32, z: f32, extent_m: f32) -> f32 {
    let (a, b) = (x / extent_m - 0.5, z / extent_m - 0.5);
    smoothstep(WARP_RAMP.0, WARP_RAMP.1, (a * a + b * b).sqrt())
}

/// Length scale of the weather modulation, m (wavelengths of 14-25 km).
pub const WEATHER_SCALE_M: f32 = 3000.0;

/// The weather modulation at world `(x, z)`, 0..=1.4, multiplying the
/// cover P asks for: sines of incommensurate wavelengths of 14-25 km, so
/// over tens of kilometres the sky has banks of cloud and clear patches
/// that do not follow the domain's tiling.
#[inline]
pub fn weather(x: f32, z: f32) -> f32 {
    let (a, b) = (x / WEATHER_SCALE_M, z / WEATHER_SCALE_M);
    let g = 0.5
        + 0.25
            * ((a + 0.4).sin() * (b * 0.81 + 1.9).sin() + ((0.6 * a + 0.8 * b) * 1.37 + 2.7).sin());
    1.4 * smoothstep(0.25, 0.75, g)
}

/// Where world `(x, z)` reads P and the cloud map: map coordinates through
/// the [`domain_warp`] at its [`warp_weight`], and that weight.
#[inline]
pub fn warped_lookup(x: f32, z: f32, extent_m: f32) -> (f32, f32, f32) {
    let (du, dv) = domain_warp(x, z, extent_m);
    let k = warp_weight(x, z, extent_m);
    (x / extent_m + k * du, z / extent_m + k * dv, k)
}

/// [`footprint`] at world `(x, z)` through the [`domain_warp`], the cover
/// modulated by the [`weather`] there.
#[inline]
pub fn world_footprint(x: f32, z: f32, f: &Fields, d: &DensityParams) -> (f32, f32, f32, f32) {
    let (u, v, k) = warped_lookup(x, z, d.map_extent_m);
    let (cover, top, fill, m) = footprint(u, v, f, d);
    if cover <= 0.0 {
        return (0.0, 0.0, 0.0, 0.0);
    }
    // The weather, like the warp, leaves the simulated domain to P.
    (cover * (1.0 + k * (weather(x, z) - 1.0)), top, fill, m)
}

/// The cumulus field's threshold at normalised height `eta` under a local
/// top `top` where the parcels ask for a cloud fraction `cover`: the
/// field must exceed it for cloud. Lowest just above the flat base (the
/// widest part of a cumulus), rising as a dome `1 - (η/top)²` to 1 (no
/// cloud) at the top, so the clouds that the field's high points make
/// are flat-based and domed, taller where the field is higher.
#[inline]
pub fn cumulus_threshold(eta: f32, top: f32, cover: f32) -> f32 {
    let t = eta / top;
    1.0 - cover * smoothstep(0.0, BASE_RAMP, eta) * (1.0 - t * t).max(0.0)
}

/// Spread of [`detail_noise`] about its mean 0.5 is widened by this to
/// about a uniform variable's (its three octaves of value noise have a
/// standard deviation near 0.11; a uniform one, 0.29).
pub const DETAIL_CONTRAST: f32 = 2.6;

/// The cloud field: the map's value `m` (uniform in 0..1) and the 3D
/// noise `n` mixed by `s` (0: the map alone, extruded; 1: the noise
/// alone), the noise's contrast widened and the mix's spread restored to
/// the map's, so a threshold `1 - f` leaves about the fraction `f` cloudy
/// whatever `s`.
#[inline]
pub fn cloud_field(m: f32, n: f32, s: f32) -> f32 {
    let n = (0.5 + (n - 0.5) * DETAIL_CONTRAST).clamp(0.0, 1.0);
    let norm = ((1.0 - s) * (1.0 - s) + s * s).sqrt().max(1e-3);
    0.5 + ((1.0 - s) * (m - 0.5) + s * (n - 0.5)) / norm
}

/// Extinction coefficient σ_t (1/m) at world point `p`: where the cloud
/// field (the cloud map's multi-scale value, mixed with the tileable 3D
/// detail noise by `detail_strength`) exceeds [`cumulus_threshold`],
/// ramping up over [`SURFACE_RAMP`], scaled by P's fill. Without the
/// detail noise (`detail` false: shadow rays) its mean, 0.5, stands in.
#[inline]
pub fn density_at(p: Vec3, f: &Fields, d: &DensityParams, detail: bool) -> f32 {
    let eta = height_fraction(p.y, d);
    if !(0.0..=1.0).contains(&eta) {
        return 0.0;
    }
    let (cover, top, fill, m) = world_footprint(p.x, p.z, f, d);
    if cover <= 0.0 || eta >= top {
        return 0.0;
    }
    let threshold = cumulus_threshold(eta, top, cover);
    let s = d.detail_strength;
    // The highest the field can be here: skip the noise when even that
    // stays under the threshold.
    if cloud_field(m, 1.0, s) < threshold {
        return 0.0;
    }
    let n = if detail && s > 0.0 {
        detail_noise(p, d.detail_scale_m)
    } else {
        0.5
    };
    let field = cloud_field(m, n, s);
    let profile = ((field - threshold) / SURFACE_RAMP).clamp(0.0, 1.0);
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
