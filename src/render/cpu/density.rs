//! Cloud density inside the height band, from P and the cloud map
//! (docs/renderer.md, "Density").
//!
//! Just over 600 lines on purpose: it is the twin of
//! `shaders/density.wgsl`, function for function, kept in one file so the
//! two read side by side (`tests/shader_twins.rs`); its tests are already
//! in `density_tests.rs`.

use glam::Vec3;

use crate::render::cloud_map::CloudMap;
use crate::render::noise_volume::{BASE_CELLS, NoiseVolume, SIZE as NOISE_SIZE};
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
    /// The fine billows near the camera ([`detail_fine`]; not evaluated
    /// when off).
    pub fine_detail: bool,
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
pub fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Tile periods of the detail volume in units of `detail_scale_m`: the
/// volume holds [`BASE_CELLS`] of its coarsest features across a tile, so
/// the base channel's coarsest features are `detail_scale_m` wide.
pub const DETAIL_TILE: f32 = BASE_CELLS as f32;

/// The billows channel is read at this many times the base channel's
/// frequency (features of 0.62 to 0.15 `detail_scale_m`): the golden
/// ratio, so the two channels' tiles never line up and their sum does not
/// repeat over the clouds. Chosen with [`BASE_WEIGHT`] by `cumulus
/// stats` on BOMEX and fair weather: area-perimeter D 1.37 on both, near
/// real fields' 1.35, where 2.13 with a base weight of 0.6 measures 1.43
/// and 1.40.
pub const BILLOW_FREQUENCY: f32 = 1.618;

/// Weight of the base channel in the detail noise (the billows have the
/// rest).
pub const BASE_WEIGHT: f32 = 0.85;

/// The mip level at which texels of `texel_m` match a pixel footprint of
/// `footprint_m`: 0 (the finest) until a pixel spans more than a texel,
/// rounded to the nearest level, so each read filters one level (a
/// blend of two cost lavapipe 1.2x the frame, side by side; the step
/// between levels falls where a pixel already spans a texel or more).
#[inline]
pub fn lod_of(footprint_m: f32, texel_m: f32) -> f32 {
    // The ratio is clamped before the log (a zero footprint: the first
    // sample from inside the band, terrain shadows), since the GPU's log2
    // of zero is undefined; WGSL's round sends halves to even.
    (footprint_m / texel_m).max(1.0).log2().round_ties_even()
}

/// The coarsest mip level of the detail volume that is read (2³ texels;
/// the 1³ level is a constant).
pub const NOISE_MAX_LOD: f32 = 5.0;

/// The gain that restores a mip level's spread: each level is ranked to a
/// uniform histogram, but a trilinear read between its texels narrows the
/// spread where they are nearly independent (coarse levels). The standard
/// deviation of reads at levels 0-5 is 0.285, 0.276, 0.254, 0.207, 0.159
/// and 0.113 (measured on seed 7; a uniform variable's is 0.289), and the
/// gains are their inverses relative to 0.289, so distant clouds are
/// eroded as strongly, and keep their cover, at the coarser features.
#[inline]
pub fn noise_gain(lod: f32) -> f32 {
    if lod < 0.5 {
        1.0
    } else if lod < 1.5 {
        1.05
    } else if lod < 2.5 {
        1.14
    } else if lod < 3.5 {
        1.4
    } else if lod < 4.5 {
        1.82
    } else {
        2.56
    }
}

/// A channel `value` read at `lod`, its spread restored by
/// [`noise_gain`], clamped to `0..1`.
#[inline]
pub fn gained(value: f32, lod: f32) -> f32 {
    (0.5 + (value - 0.5) * noise_gain(lod)).clamp(0.0, 1.0)
}

/// The detail volume's base channel (Perlin-Worley) at world point `p`
/// for features of `scale_m`, at the mip level of a pixel footprint of
/// `footprint_m`.
#[inline]
pub fn detail_base(p: Vec3, scale_m: f32, footprint_m: f32, volume: &NoiseVolume) -> f32 {
    let tile_m = DETAIL_TILE * scale_m;
    let texel_m = tile_m / NOISE_SIZE as f32;
    let lod = lod_of(footprint_m, texel_m).min(NOISE_MAX_LOD);
    gained(volume.sample_level(p / tile_m, lod)[0], lod)
}

/// The detail volume's billows channel (Worley fBm) at world point `p`,
/// read at [`BILLOW_FREQUENCY`] times the base's frequency, at the mip
/// level of a pixel footprint of `footprint_m`.
#[inline]
pub fn detail_billows(p: Vec3, scale_m: f32, footprint_m: f32, volume: &NoiseVolume) -> f32 {
    billows_channel(
        p,
        scale_m,
        footprint_m,
        BILLOW_FREQUENCY,
        Vec3::new(0.31, 0.17, 0.73),
        volume,
    )
}

/// The billows channel at `frequency` times the base channel's, its
/// lookup shifted by `offset` (in tiles), at the mip level of a pixel
/// footprint of `footprint_m`, its spread restored ([`gained`]): what
/// [`detail_billows`] and [`detail_fine`] read.
#[inline]
pub fn billows_channel(
    p: Vec3,
    scale_m: f32,
    footprint_m: f32,
    frequency: f32,
    offset: Vec3,
    volume: &NoiseVolume,
) -> f32 {
    let tile_m = DETAIL_TILE * scale_m;
    let texel_m = tile_m / NOISE_SIZE as f32;
    let lod = lod_of(footprint_m * frequency, texel_m).min(NOISE_MAX_LOD);
    let q = p * (frequency / tile_m) + offset;
    gained(volume.sample_level(q, lod)[1], lod)
}

/// The detail noise at world point `p` for features of `scale_m`, in
/// `0..1` (`±FINE_WEIGHT / 2` beyond with the fine billows): the
/// volume's base shape and billows weighted by [`BASE_WEIGHT`], each read
/// at the mip level of a pixel footprint of `footprint_m` (far away,
/// where a pixel covers many texels, the mips average the billows out
/// instead of aliasing them), and when `fine` the fine billows near the
/// camera ([`detail_fine`]).
#[inline]
pub fn detail_noise(
    p: Vec3,
    scale_m: f32,
    footprint_m: f32,
    fine: bool,
    volume: &NoiseVolume,
) -> f32 {
    let base = detail_base(p, scale_m, footprint_m, volume);
    BASE_WEIGHT * base
        + (1.0 - BASE_WEIGHT) * detail_billows(p, scale_m, footprint_m, volume)
        + detail_fine(p, scale_m, footprint_m, fine, volume)
}

/// The fine billows' frequency over the base channel's (the billows
/// channel read over tiles of 180 m at the default 180 m scale, texels
/// of 2.8 m): the small turrets of a cloud seen from a few hundred
/// metres. At 6.7 they are finer than the march's steps near the camera
/// (25 m from under the base) and show as grain.
pub const FINE_FREQUENCY: f32 = 4.0;
/// The fine billows' weight in the detail noise, near the camera.
pub const FINE_WEIGHT: f32 = 0.16;
/// The footprint (m) up to which the fine billows have all their
/// weight; none from twice it (6 m: clouds within about 1.5-2.5 km at
/// 640x480), so the far clouds, the field statistics and the volume
/// export's grid (read at a footprint of its cell, 9.8 m at 1024 cells
/// over 10 km) are the same as without them.
pub const FINE_SHARP_M: f32 = 3.0;

/// The weight of the fine billows at a footprint of `footprint_m`:
/// [`FINE_WEIGHT`] up to [`FINE_SHARP_M`], falling to 0 at twice it; 0
/// when they are off (`fine`; in WGSL the override `FINE_DETAIL`).
#[inline]
pub fn fine_weight(footprint_m: f32, fine: bool) -> f32 {
    if !fine {
        return 0.0;
    }
    FINE_WEIGHT * (2.0 - footprint_m / FINE_SHARP_M).clamp(0.0, 1.0)
}

/// The fine billows at `p`, about 0: the billows channel at
/// [`FINE_FREQUENCY`] times the base's frequency, less its mean, times
/// [`fine_weight`]. Near the camera they break a cloud's smooth surface
/// into the small turrets and wisps the coarser channels cannot hold.
#[inline]
pub fn detail_fine(
    p: Vec3,
    scale_m: f32,
    footprint_m: f32,
    fine: bool,
    volume: &NoiseVolume,
) -> f32 {
    let w = fine_weight(footprint_m, fine);
    if w <= 0.0 {
        return 0.0;
    }
    let offset = Vec3::new(0.57, 0.11, 0.29);
    w * (billows_channel(p, scale_m, footprint_m, FINE_FREQUENCY, offset, volume) - 0.5)
}

/// The density profile, `0..1`, where the cloud field of map value `m`
/// and noise `n` (mixed by `s`) meets `threshold`: ramping up over
/// [`SURFACE_RAMP`] above it.
#[inline]
pub fn surface_profile(m: f32, n: f32, s: f32, threshold: f32) -> f32 {
    ((cloud_field(m, n, s) - threshold) / SURFACE_RAMP).clamp(0.0, 1.0)
}

/// [`surface_profile`] with the [`detail_noise`] at `p`, reading the
/// volume only where it can change the result: the field grows with the
/// noise, so where even the lowest noise saturates the profile, or the
/// base channel's bounds on the noise decide it, the reads that remain are
/// skipped (inside a cloud, most samples). Exactly `surface_profile(m,
/// detail_noise(..), s, threshold)` at `d`'s `detail_scale_m`, with its
/// fine billows when `d.fine_detail`.
#[inline]
pub fn detail_profile(
    p: Vec3,
    m: f32,
    threshold: f32,
    s: f32,
    footprint_m: f32,
    d: &DensityParams,
    volume: &NoiseVolume,
) -> f32 {
    let (scale_m, fine_detail) = (d.detail_scale_m, d.fine_detail);
    let fine = 0.5 * fine_weight(footprint_m, fine_detail);
    if surface_profile(m, -fine, s, threshold) >= 1.0 {
        return 1.0;
    }
    let low = BASE_WEIGHT * detail_base(p, scale_m, footprint_m, volume);
    if surface_profile(m, low + (1.0 - BASE_WEIGHT) + fine, s, threshold) <= 0.0 {
        return 0.0;
    }
    if surface_profile(m, low - fine, s, threshold) >= 1.0 {
        return 1.0;
    }
    let n = low + (1.0 - BASE_WEIGHT) * detail_billows(p, scale_m, footprint_m, volume);
    if fine > 0.0 {
        if surface_profile(m, n + fine, s, threshold) <= 0.0 {
            return 0.0;
        }
        if surface_profile(m, n - fine, s, threshold) >= 1.0 {
            return 1.0;
        }
    }
    surface_profile(
        m,
        n + detail_fine(p, scale_m, footprint_m, fine_detail, volume),
        s,
        threshold,
    )
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
/// `m` the cloud map's multi-scale value there, read at the mip level
/// `map_lod`. `(0, 0, 0, 0)` where P has no coverage, or where the
/// normalised height `eta` of the point asking is at or above the highest
/// top P allows there (the map's factor is at most 1): no cloud there
/// whatever the map says, so the map is not read (the density is the
/// same, bit for bit).
#[inline]
pub fn footprint(
    u: f32,
    v: f32,
    map_lod: f32,
    eta: f32,
    f: &Fields,
    d: &DensityParams,
) -> (f32, f32, f32, f32) {
    let [c, h, fill] = f.p.sample(u, v);
    let highest = (0.2 + 0.8 * h).clamp(0.0, 1.0);
    if c <= P_COVERAGE_MIN || eta >= highest {
        return (0.0, 0.0, 0.0, 0.0);
    }
    let [m, large] = f.cloud_map.sample_level(u, v, map_lod);
    let cover = (d.coverage * c).clamp(0.0, 1.0);
    let top = highest * (0.7 + 0.3 * large);
    (cover, top, fill, m)
}

/// Length scale of the domain warp, m: its sines have wavelengths of
/// 2π times this over 0.67-1.13 (50-85 km), in six directions, with
/// incommensurate frequencies, so they never line up again.
pub const WARP_SCALE_M: f32 = 9000.0;
/// Amplitude of each of the warp's three sines per axis, m (in metres, not
/// domain widths, so the warp's stretch stays under ~50 % whatever the
/// domain's size). Chosen with `cumulus stats`' repetition measure on the
/// 10 km domains: at 2,000 m the correlation at the domain's period is
/// no higher than at other lags (BOMEX 0.038 against 0.044, fair weather
/// 0.029 against 0.051); 1,500 m leaves it at 0.08-0.2, rows to the
/// horizon, and 1,700 m is marginal with the erosion that grows with
/// height ([`EROSION_BASE`], which gives the map more say).
pub const WARP_AMPLITUDE_M: f32 = 2000.0;

/// The displacement (map units, for a map of `extent_m`) of the lookups
/// into P and the cloud map at world `(x, z)`: a sum of sines of incommensurate wavelengths, smooth
/// (it stretches the clouds by up to ~40 % locally, in directions that
/// change across the sky) and not periodic. The simulated domain tiles
/// the sky; without the warp the same clouds would come back every domain
/// width in rows to the horizon, and with it the copy one domain width
/// away is looked up up to a domain width elsewhere.
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
/// drawn where its parcels are, as P says (the per-parcel spheroids and an
/// application's own use of the parcels agree with the picture), and the
/// copies around it are warped. A slower ramp (to 2.0 or 2.5) leaves the
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

/// The most the [`weather`] multiplies the cover by (`WEATHER_MAX`).
pub const WEATHER_MAX: f32 = 1.4;

/// The weather modulation at world `(x, z)`, 0..=[`WEATHER_MAX`], multiplying the
/// cover P asks for: sines of incommensurate wavelengths of 14-25 km, so
/// over tens of kilometres the sky has banks of cloud and clear patches
/// that do not follow the domain's tiling.
#[inline]
pub fn weather(x: f32, z: f32) -> f32 {
    let (a, b) = (x / WEATHER_SCALE_M, z / WEATHER_SCALE_M);
    let g = 0.5
        + 0.25
            * ((a + 0.4).sin() * (b * 0.81 + 1.9).sin() + ((0.6 * a + 0.8 * b) * 1.37 + 2.7).sin());
    WEATHER_MAX * smoothstep(0.25, 0.75, g)
}

/// Where world `(x, z)` reads P and the cloud map: map coordinates through
/// the [`domain_warp`] at its [`warp_weight`], and that weight.
#[inline]
pub fn warped_lookup(x: f32, z: f32, extent_m: f32) -> (f32, f32, f32) {
    let k = warp_weight(x, z, extent_m);
    if k <= 0.0 {
        // Over the simulated domain: no warp (and its sines are skipped).
        return (x / extent_m, z / extent_m, 0.0);
    }
    let (du, dv) = domain_warp(x, z, extent_m);
    (x / extent_m + k * du, z / extent_m + k * dv, k)
}

/// The side of one cloud-map texel, m.
#[inline]
pub fn map_texel_m(f: &Fields, d: &DensityParams) -> f32 {
    d.map_extent_m / f.cloud_map.size() as f32
}

/// [`footprint`] at world `(x, z)` through the [`domain_warp`] (`lookup`,
/// its [`warped_lookup`]), the cover modulated by the [`weather`] there;
/// the map read at the mip level of a pixel footprint of `footprint_m`.
#[inline]
pub fn world_footprint(
    x: f32,
    z: f32,
    lookup: (f32, f32, f32),
    footprint_m: f32,
    eta: f32,
    f: &Fields,
    d: &DensityParams,
) -> (f32, f32, f32, f32) {
    let (u, v, k) = lookup;
    let (cover, top, fill, m) = footprint(u, v, lod_of(footprint_m, map_texel_m(f, d)), eta, f, d);
    if cover <= 0.0 {
        return (0.0, 0.0, 0.0, 0.0);
    }
    // The weather, like the warp, leaves the simulated domain to P.
    if k <= 0.0 {
        return (cover, top, fill, m);
    }
    (cover * (1.0 + k * (weather(x, z) - 1.0)), top, fill, m)
}

/// The fraction of the local top above which [`cumulus_threshold`] climbs
/// on from 1 to the cloud field's highest value ([`field_max`]).
pub const TOP_ROUNDING: f32 = 0.8;

/// The highest value [`cloud_field`] takes at mix `s` (map and noise both
/// 1): 1 for the map alone, up to 1.21 for an even mix.
#[inline]
pub fn field_max(s: f32) -> f32 {
    cloud_field(1.0, 1.0, s)
}

/// P's spread coverage at and under which [`footprint`] finds no cloud
/// (`P_COVERAGE_MIN` in WGSL).
pub const P_COVERAGE_MIN: f32 = 1e-3;

/// The presence ([`cumulus_threshold`]'s `presence`: P's spread coverage
/// times the weather) under which the threshold climbs toward the
/// field's highest value ([`field_max`]), reaching it at [`WEATHER_MAX`]
/// times [`P_COVERAGE_MIN`], the highest presence at `footprint`'s cut.
/// The mixed field exceeds 1 over a few percent of the sky, so a
/// threshold that stopped at 1 would make cloud at any coverage up to the
/// cut and slice it there in vertical walls, seen from below as straight
/// cut edges. The fringe is about 140 m wide beside the soft field's
/// Gaussian; what it takes away (specks a kilometre from any condensed
/// parcel) is under 0.01 of the cloud fraction (docs/renderer.md, "What
/// still looks wrong").
pub const FRINGE_PRESENCE: f32 = 0.005;

/// The cumulus field's threshold at normalised height `eta` under a local
/// top `top` where the parcels ask for a cloud fraction `cover`, for the
/// field mixed by `s`: the field must exceed it for cloud. Lowest just
/// above the flat base (the widest part of a cumulus), rising as a dome
/// `1 - (η/top)²` to 1 at the top, so the clouds that the field's high
/// points make are flat-based and domed, taller where the field is
/// higher. Over the top fifth ([`TOP_ROUNDING`]) it climbs on to the
/// field's highest value, which it reaches at the top: the mixed field
/// exceeds 1 in a cloud's core, and a threshold that stopped at 1 would
/// cut the core off flat at the local top, a smooth surface that reads as
/// a ruler-straight lid at the horizon; this way the noise rounds every
/// top off below it. Where the `presence` (P's spread coverage times the
/// weather) falls under [`FRINGE_PRESENCE`] it climbs the same way, so
/// clouds end before P does, not at its edge; over it the threshold is
/// the same, bit for bit.
#[inline]
pub fn cumulus_threshold(eta: f32, top: f32, cover: f32, presence: f32, s: f32) -> f32 {
    let t = eta / top;
    let fringe = 1.0 - smoothstep(P_COVERAGE_MIN * WEATHER_MAX, FRINGE_PRESENCE, presence);
    let climb = smoothstep(TOP_ROUNDING, 1.0, t).max(fringe);
    1.0 - cover * smoothstep(0.0, BASE_RAMP, eta) * (1.0 - t * t).max(0.0)
        + (field_max(s) - 1.0) * climb
}

/// Spread of [`detail_noise`] about its mean 0.5 is widened by this to
/// about a uniform variable's (its two ranked channels, weighted 0.85 and
/// 0.15 and read through trilinear filtering, have a standard deviation
/// near 0.24 at full resolution, checked in this module's tests; a
/// uniform one, 0.289).
pub const DETAIL_CONTRAST: f32 = 1.23;

/// Share of the detail strength that erodes a cloud at its base; it grows
/// linearly to the full strength at the local top. Chosen with `cumulus
/// stats` and the high-flight view: eroding evenly (1.0) perforates the
/// clouds seen from above with 50-150 m holes through the whole column;
/// 0.6 keeps their lower bodies whole under billowed tops (BOMEX and fair
/// weather D 1.34 and 1.33, size exponents -1.97 and -1.94).
pub const EROSION_BASE: f32 = 0.6;

/// The detail noise's weight at normalised height `eta` under a local top
/// `top`, for a scene strength `s`: erosion that grows with height.
#[inline]
pub fn erosion_strength(s: f32, eta: f32, top: f32) -> f32 {
    s * (EROSION_BASE + (1.0 - EROSION_BASE) * (eta / top).clamp(0.0, 1.0))
}

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

/// Where world point `p` reads the detail volume: `p` itself over the
/// simulated domain, the warped lookup (in metres) outside it, so the
/// copies of the domain around it do not repeat the detail either (the
/// volume's tile, 4 · 180 m, nearly divides a 10 km domain, and without
/// the warp `cumulus stats` sees the period again).
#[inline]
pub fn noise_point(p: Vec3, lookup: (f32, f32, f32), extent_m: f32) -> Vec3 {
    let (u, v, k) = lookup;
    if k <= 0.0 {
        return p;
    }
    Vec3::new(u * extent_m, p.y, v * extent_m)
}

/// Extinction coefficient σ_t (1/m) at world point `p`: where the cloud
/// field (the cloud map's multi-scale value, mixed with the tileable 3D
/// detail noise by `detail_strength`) exceeds [`cumulus_threshold`],
/// ramping up over [`SURFACE_RAMP`], scaled by P's fill. Without the
/// detail noise (`detail` false: shadow rays) its mean, 0.5, stands in.
/// `footprint_m` is the width of the pixel's cone there: the textures are
/// read at its level of detail.
#[inline]
pub fn density_at(p: Vec3, f: &Fields, d: &DensityParams, detail: bool, footprint_m: f32) -> f32 {
    let eta = height_fraction(p.y, d);
    if !(0.0..=1.0).contains(&eta) {
        return 0.0;
    }
    let lookup = warped_lookup(p.x, p.z, d.map_extent_m);
    let (cover, top, fill, m) = world_footprint(p.x, p.z, lookup, footprint_m, eta, f, d);
    if cover <= 0.0 || eta >= top {
        return 0.0;
    }
    let s = erosion_strength(d.detail_strength, eta, top);
    let presence = cover / d.coverage.max(1e-6);
    let threshold = cumulus_threshold(eta, top, cover, presence, s);
    // The highest the field can be here: skip the noise when even that
    // stays under the threshold.
    if cloud_field(m, 1.0, s) < threshold {
        return 0.0;
    }
    let profile = if detail && s > 0.0 {
        let volume = f.cloud_map.noise();
        let q = noise_point(p, lookup, d.map_extent_m);
        detail_profile(q, m, threshold, s, footprint_m, d, volume)
    } else {
        surface_profile(m, 0.5, s, threshold)
    };
    d.extinction_per_m * (0.3 + 0.7 * fill) * profile
}

#[cfg(test)]
#[path = "density_tests.rs"]
mod tests;
