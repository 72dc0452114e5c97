//! The land's albedo where the ground is land (`[render.ground] land`):
//! plain, one colour ([`LAND_ALBEDO`]), or fields, a patchwork of fields
//! in rows with woods across it, whose mean over the land is that colour,
//! so the light the ground sends up to the clouds and the sky's tables
//! keep the plain land's albedo; the flat ground's albedo where a ray
//! meets it, and the terrain's. Each function has a WGSL twin of the same
//! name in `shaders/land.wgsl` (`terrain_albedo`'s is in
//! `shaders/terrain.wgsl`).
//!
//! The woods are a threshold of the detail volume's base channel
//! ([`crate::render::noise_volume`]) read on a horizontal slice at two
//! scales, at the mip level of the pixel's footprint, with a canopy of
//! tree crowns placed by a hash; the fields are parcels in rows, the
//! rows of each farm (a block about 1.7 km across) on one of four
//! headings, each row's fields of their own length, each parcel one of
//! four crops by a hash of its cell, in patches, behind hedges on most
//! of its boundaries. Where a pixel
//! covers more than half a field's width the parcels fade to their mean;
//! the woods' edges soften as the footprint grows past 40 m, and from a
//! footprint of 1 km to 2 km the woods fade to their share of the land,
//! so the far land neither aliases nor shimmers, and is the plain land's
//! colour where no pattern can be resolved.

use glam::Vec3;

use super::density::{NOISE_MAX_LOD, gained, lod_of};
use super::frame::Frame;
use super::sky::LAND_ALBEDO;
use crate::render::noise_volume::{NoiseVolume, SIZE as NOISE_SIZE};

/// The fields' length along their rows, m.
pub const FIELD_LENGTH_M: f32 = 210.0;
/// The rows' width (a field's width), m.
pub const FIELD_WIDTH_M: f32 = 130.0;
/// The rows' direction against the x (east) axis on the first of a
/// farm's four headings, radians.
pub const FIELD_ANGLE: f32 = 0.41;
/// The turn between a farm's possible headings, radians (22°).
pub const FARM_TURN: f32 = 0.39;
/// A farm's size, m: a block whose fields share their rows' heading.
pub const FARM_M: f32 = 1700.0;
/// How far the farms' edges bend from straight lines, m.
pub const FARM_BEND_M: f32 = 300.0;
/// The woods' larger scale: the detail volume's tile, m.
pub const WOODS_TILE_M: f32 = 7300.0;
/// The woods' smaller scale, m (about a third of the larger, not a
/// divisor of it, so the two tiles' pattern does not repeat soon).
pub const WOODS_DETAIL_TILE_M: f32 = 2330.0;
/// The two scales' noise, weighted, above which the land is wood: about
/// 30 % of it (measured in the tests).
pub const WOODS_THRESHOLD: f32 = 0.617;
/// Half the width of the woods' edge in the noise's units, up to a
/// footprint of [`WOODS_SHARP_M`]; wider in proportion beyond.
pub const WOODS_EDGE: f32 = 0.02;
/// The footprint up to which the woods' edge is sharpest, m: about the
/// smaller tile's texel (36 m).
pub const WOODS_SHARP_M: f32 = 40.0;
/// The widest the woods' edge grows, in units of [`WOODS_EDGE`]: wider,
/// the threshold's soft ramp would shift the woods' share (measured: 42 %
/// at a footprint of 1.5 km with no cap).
pub const WOODS_SOFTEST: f32 = 5.0;
/// The footprint from which the woods fade to [`WOODS_SHARE`], fully at
/// twice it, m.
pub const WOODS_FADE_M: f32 = 1000.0;
/// The share of the land that is wood, what the woods fade to.
pub const WOODS_SHARE: f32 = 0.3;

/// Grass's albedo over the plain land's, before the normalisation
/// ([`LAND_TINT_MEAN`]).
pub const CROP_GRASS: Vec3 = Vec3::new(0.95, 1.10, 0.85);
/// A young crop's.
pub const CROP_YOUNG: Vec3 = Vec3::new(1.30, 1.25, 0.85);
/// Bare soil's.
pub const CROP_SOIL: Vec3 = Vec3::new(1.35, 0.95, 0.85);
/// Stubble's.
pub const CROP_STUBBLE: Vec3 = Vec3::new(1.65, 1.35, 1.30);
/// The woods' albedo over the plain land's, before the normalisation.
pub const WOODS: Vec3 = Vec3::new(0.45, 0.55, 0.45);
/// The crops' mean.
pub const CROPS_MEAN: Vec3 = Vec3::new(1.3125, 1.1625, 0.9625);
/// A hedgerow's width, m.
pub const HEDGE_M: f32 = 4.0;
/// The chance that a field's boundary is hedged.
pub const HEDGE_CHANCE: f32 = 0.7;
/// The hedges' albedo over the plain land's, before the normalisation:
/// a darker green than the woods'.
pub const HEDGE: Vec3 = Vec3::new(0.40, 0.50, 0.36);
/// The share of the fields' land under hedges: [`HEDGE_CHANCE`] of the
/// boundaries between rows (`HEDGE_M / FIELD_WIDTH_M`) and of those
/// between fields along a row (`HEDGE_M` times the mean of `1 / length`
/// over the rows' 256 lengths), less their crossings.
pub const HEDGE_SHARE: f32 = 0.035_362_66;
/// The fields' mean tint: the crops' mean with [`HEDGE_SHARE`] of hedges.
pub const FIELDS_MEAN: Vec3 = Vec3::new(1.280_231_2, 1.139_072, 0.941_193_8);
/// The mean of the land's tint before the normalisation: [`WOODS_SHARE`]
/// woods, the rest the fields' mean; the tint is divided by it, so the
/// land's mean albedo is [`LAND_ALBEDO`].
pub const LAND_TINT_MEAN: Vec3 = Vec3::new(1.031_161_8, 0.962_350_4, 0.793_835_6);
/// The patches within a field (wetter and drier soil, thinner and
/// denser crop): the detail volume's base channel over tiles of this
/// size, m (features from a quarter of it, 130 m, down to a few metres).
pub const PATCH_TILE_M: f32 = 530.0;
/// How far the patches lift or darken a field's crop, at most.
pub const PATCH_CONTRAST: f32 = 0.12;
/// The woods' canopy: one crown in each square of this side, m, at a
/// place within it and of a brightness drawn from a hash of the square
/// (cellular, with no tile to repeat).
pub const CROWN_M: f32 = 9.0;
/// The smaller trees' squares, m (not a divisor of [`CROWN_M`]).
pub const SMALL_CROWN_M: f32 = 5.5;
/// What lifts the darkest gap between crowns off black: a canopy point's
/// value is this plus its crown's light ([`crown_light`], 0 to 1).
pub const CANOPY_FLOOR: f32 = 0.7;
/// The mean of [`crown_light`] over the land (measured over 9 million
/// points across 19 x 21 km; the tests check it on others): the canopy
/// divides by it, with [`CANOPY_FLOOR`], to keep the woods' mean albedo.
pub const CROWN_LIGHT_MEAN: f32 = 0.534;

/// A 32-bit integer hash of a field's cell (the rows' index `i`, the
/// field's `j` along its row).
#[inline]
pub fn field_hash(i: i32, j: i32) -> u32 {
    let mut h = (i as u32).wrapping_mul(0x8da6_b343) ^ (j as u32).wrapping_mul(0xd816_3841);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2c1b_3c6d);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297a_2d39);
    h ^ (h >> 15)
}

/// Crop `k`'s albedo over the plain land's (`k` modulo 4).
#[inline]
pub fn crop(k: u32) -> Vec3 {
    match k & 3 {
        0 => CROP_GRASS,
        1 => CROP_YOUNG,
        2 => CROP_SOIL,
        _ => CROP_STUBBLE,
    }
}

/// The hash of the farm at world `(x, z)`: square blocks of [`FARM_M`],
/// their edges bent by a few hundred metres, each with its own rows.
#[inline]
pub fn farm(x: f32, z: f32) -> u32 {
    let bx = ((x + FARM_BEND_M * (z / 900.0).sin()) / FARM_M).floor() as i32;
    let bz = ((z + FARM_BEND_M * (x / 1100.0).sin()) / FARM_M).floor() as i32;
    field_hash(2 * bx + 1, 2 * bz)
}

/// The fields' tint at world `(x, z)`: the crop of the parcel there,
/// brighter or darker by up to 12 % and in patches within it
/// ([`PATCH_CONTRAST`]), behind [`HEDGE_M`]-wide hedges on
/// [`HEDGE_CHANCE`] of its boundaries ([`hedge_cover`]); faded to the
/// fields' mean ([`FIELDS_MEAN`]) as the footprint `footprint_m` grows
/// from half a field's width to a whole one. Each farm ([`farm`]) turns
/// its rows by a multiple of [`FARM_TURN`]; each row has its own fields'
/// length (0.6 to 1.4 of [`FIELD_LENGTH_M`]) and start.
#[inline]
pub fn field_tint(x: f32, z: f32, footprint_m: f32, volume: &NoiseVolume) -> Vec3 {
    let fade = (2.0 - 2.0 * footprint_m / FIELD_WIDTH_M).clamp(0.0, 1.0);
    if fade <= 0.0 {
        return FIELDS_MEAN;
    }
    let b = farm(x, z);
    let (s, c) = (FIELD_ANGLE + FARM_TURN * (b & 3) as f32).sin_cos();
    let along = x * c + z * s;
    let across = -x * s + z * c;
    let row = (across / FIELD_WIDTH_M).floor() as i32;
    let r = field_hash(row, (b >> 8) as i32);
    let length = FIELD_LENGTH_M * (0.6 + 0.8 * ((r >> 12) & 255) as f32 / 255.0);
    let u = along / length + (r & 1023) as f32 / 1024.0;
    let field = u.floor() as i32;
    let h = field_hash(row, field) ^ b;
    let shade = 1.0 + 0.24 * (((h >> 8) & 255) as f32 / 255.0 - 0.5);
    let patches = 1.0
        + 2.0
            * PATCH_CONTRAST
            * (woods_noise(x, z, footprint_m, PATCH_TILE_M, 0.375, volume) - 0.5);
    // The hedges at the start of this row and of the next, and at the
    // start of this field and of the next along the row.
    let next_row = field_hash(row + 1, (b >> 8) as i32);
    let between_rows = hedge_cover(
        across - row as f32 * FIELD_WIDTH_M,
        FIELD_WIDTH_M,
        footprint_m,
        hedged(r),
        hedged(next_row),
    );
    let between_fields = hedge_cover(
        (u - field as f32) * length,
        length,
        footprint_m,
        hedged(h),
        hedged(field_hash(row, field + 1) ^ b),
    );
    let hedge = 1.0 - (1.0 - between_rows) * (1.0 - between_fields);
    let tint = (crop(h) * (shade * patches)).lerp(HEDGE, hedge);
    FIELDS_MEAN.lerp(tint, fade)
}

/// 1 where the boundary of hash `h` is hedged ([`HEDGE_CHANCE`] of
/// them, by its top ten bits), else 0.
#[inline]
pub fn hedged(h: u32) -> f32 {
    if ((h >> 22) as f32) < HEDGE_CHANCE * 1024.0 {
        1.0
    } else {
        0.0
    }
}

/// How much of a footprint `footprint_m` wide centred `a` m into a
/// parcel `period` m across (`0 <= a < period`) the hedges cover: the
/// parcel's own, `[0, HEDGE_M]` when `start` is 1, and the next
/// parcel's, `[period, period + HEDGE_M]` when `end` is 1 (the box
/// filter of the two strips, exact for footprints up to `period`; a point
/// sample as the footprint vanishes).
#[inline]
pub fn hedge_cover(a: f32, period: f32, footprint_m: f32, start: f32, end: f32) -> f32 {
    let half = 0.5 * footprint_m.max(1e-3);
    let (lo, hi) = (a - half, a + half);
    let overlap = |s: f32| (hi.min(s + HEDGE_M) - lo.max(s)).max(0.0);
    ((start * overlap(0.0) + end * overlap(period)) / (2.0 * half)).min(1.0)
}

/// The light of the tree crowns at world `(x, z)`, 0 to 1: the brighter
/// of two layers of crowns ([`crown_layer`]), one in squares of
/// [`CROWN_M`] and one of smaller trees in squares of
/// [`SMALL_CROWN_M`] at 0.8 of the light, so the crowns vary in size and
/// cluster.
#[inline]
pub fn crown_light(x: f32, z: f32) -> f32 {
    crown_layer(x / CROWN_M, z / CROWN_M, 0)
        .max(0.8 * crown_layer(x / SMALL_CROWN_M + 0.37, z / SMALL_CROWN_M + 0.61, 7919))
}

/// One layer of tree crowns at `(u, w)` in units of its squares, 0 to 1:
/// each square's crown sits at a place in it drawn from the square's
/// hash (`salt` apart from the other layer's), of a radius of 0.55 to 0.8
/// of a square, bright at its middle and falling with the square of the
/// distance to nothing at its edge (the gaps between crowns), times a
/// brightness of 0.6 to 1; the nearest crown's light.
#[inline]
pub fn crown_layer(u: f32, w: f32, salt: i32) -> f32 {
    let (ci, ck) = (u.floor() as i32, w.floor() as i32);
    let mut nearest = f32::MAX;
    let mut light = 0.0;
    for dk in -1..=1 {
        for di in -1..=1 {
            let h = field_hash(ci + di + salt, ck + dk).wrapping_mul(0x9e37_79b9);
            let px = (ci + di) as f32 + ((h & 255) as f32 + 0.5) / 256.0;
            let pz = (ck + dk) as f32 + (((h >> 8) & 255) as f32 + 0.5) / 256.0;
            let d2 = (u - px) * (u - px) + (w - pz) * (w - pz);
            if d2 < nearest {
                nearest = d2;
                let radius = 0.55 + 0.25 * ((h >> 24) & 255) as f32 / 255.0;
                let shade = 0.6 + 0.4 * ((h >> 16) & 255) as f32 / 255.0;
                light = (1.0 - d2 / (radius * radius)).max(0.0) * shade;
            }
        }
    }
    light
}

/// The woods' canopy at world `(x, z)`: a factor on their albedo, 1 on
/// the mean, `(CANOPY_FLOOR + crown_light) / (CANOPY_FLOOR +
/// CROWN_LIGHT_MEAN)` (crowns up to 1.38 times the mean, the gaps
/// 0.57), faded to 1 as the footprint grows from half a crown's square to
/// a whole one (no mip level to read: the crowns are computed, so they
/// fade before they alias).
#[inline]
pub fn canopy(x: f32, z: f32, footprint_m: f32) -> f32 {
    let fade = (2.0 - 2.0 * footprint_m / CROWN_M).clamp(0.0, 1.0);
    if fade <= 0.0 {
        return 1.0;
    }
    let crowns = (CANOPY_FLOOR + crown_light(x, z)) / (CANOPY_FLOOR + CROWN_LIGHT_MEAN);
    1.0 + (crowns - 1.0) * fade
}

/// How much of the land at world `(x, z)` is wood, 0..1: the detail
/// volume's base channel on a slice at two scales, at the mip level of
/// the footprint, through a threshold whose edge widens with the
/// footprint beyond [`WOODS_SHARP_M`] (at most [`WOODS_SOFTEST`] times
/// as wide), faded to [`WOODS_SHARE`] as the
/// footprint grows from [`WOODS_FADE_M`] to twice it.
#[inline]
pub fn woods_cover(x: f32, z: f32, footprint_m: f32, volume: &NoiseVolume) -> f32 {
    let fade = (footprint_m / WOODS_FADE_M - 1.0).clamp(0.0, 1.0);
    if fade >= 1.0 {
        return WOODS_SHARE;
    }
    let n = 0.65 * woods_noise(x, z, footprint_m, WOODS_TILE_M, 0.37, volume)
        + 0.35 * woods_noise(x, z, footprint_m, WOODS_DETAIL_TILE_M, 0.71, volume);
    let edge = WOODS_EDGE * (footprint_m / WOODS_SHARP_M).clamp(1.0, WOODS_SOFTEST);
    let cover = smoothstep(WOODS_THRESHOLD - edge, WOODS_THRESHOLD + edge, n);
    cover + (WOODS_SHARE - cover) * fade
}

/// One scale of the woods' noise: the detail volume's base channel at
/// `(x / tile_m, y, z / tile_m)`, at the mip level of the footprint (at
/// most [`NOISE_MAX_LOD`]), its spread restored ([`gained`]).
#[inline]
pub fn woods_noise(
    x: f32,
    z: f32,
    footprint_m: f32,
    tile_m: f32,
    y: f32,
    volume: &NoiseVolume,
) -> f32 {
    let lod = lod_of(footprint_m, tile_m / NOISE_SIZE as f32).min(NOISE_MAX_LOD);
    gained(
        volume.sample_level(Vec3::new(x / tile_m, y, z / tile_m), lod)[0],
        lod,
    )
}

/// The fields' land's albedo at world `(x, z)` seen with a footprint
/// `footprint_m` wide: [`LAND_ALBEDO`] times the woods' or the fields'
/// tint over [`LAND_TINT_MEAN`] (the plain land's is [`LAND_ALBEDO`]
/// itself; the callers choose).
#[inline]
pub fn land_albedo(x: f32, z: f32, footprint_m: f32, volume: &NoiseVolume) -> Vec3 {
    let woods = woods_cover(x, z, footprint_m, volume);
    let trees = if woods > 0.0 {
        WOODS * canopy(x, z, footprint_m)
    } else {
        WOODS
    };
    let tint = field_tint(x, z, footprint_m, volume).lerp(trees, woods);
    LAND_ALBEDO * tint / LAND_TINT_MEAN
}

/// The terrain's albedo where it is flat (grass) and where its slope,
/// `1 - n.y`, is a third or more (bare rock and soil), linear between
/// (`TERRAIN_ALBEDO_FLAT` and `TERRAIN_ALBEDO_STEEP` in
/// `shaders/terrain.wgsl`).
pub const TERRAIN_ALBEDO_FLAT: Vec3 = Vec3::new(0.07, 0.11, 0.04);
pub const TERRAIN_ALBEDO_STEEP: Vec3 = Vec3::new(0.16, 0.13, 0.09);

/// The terrain's albedo at `p` of normal `n` (seen along `dir` from `t`
/// away by a pixel of cone angle `spread`): level ground's
/// [`TERRAIN_ALBEDO_FLAT`], times the land's tint over the plain land's
/// when `land_fields` ([`land_albedo`] seen with the pixel's
/// [`ground_footprint`]), toward [`TERRAIN_ALBEDO_STEEP`] as the slope
/// `1 - n.y` grows to a third.
pub fn terrain_albedo(p: Vec3, n: Vec3, dir: Vec3, t: f32, spread: f32, fr: &Frame) -> Vec3 {
    let flat = if fr.quality.land_fields {
        let footprint_m = ground_footprint(spread, t, dir.dot(n));
        TERRAIN_ALBEDO_FLAT * land_albedo(p.x, p.z, footprint_m, fr.fields.cloud_map.noise())
            / LAND_ALBEDO
    } else {
        TERRAIN_ALBEDO_FLAT
    };
    flat.lerp(TERRAIN_ALBEDO_STEEP, ((1.0 - n.y) * 3.0).min(1.0))
}

/// The width on the ground of a pixel of cone angle `spread` at distance
/// `t`, its ray meeting the ground at cosine `cos_n` to the normal: the
/// footprint's long axis, `spread · t / |cos_n|` (at most 20 times the
/// short one, at grazing incidence).
#[inline]
pub fn ground_footprint(spread: f32, t: f32, cos_n: f32) -> f32 {
    spread * t / cos_n.abs().max(0.05)
}

/// The flat ground's albedo where a ray of cone angle `spread` from
/// `origin` along `dir` meets it (y = 0): the fields' [`land_albedo`]
/// there when `land_fields`, faded to [`LAND_ALBEDO`] over the last
/// quarter of `max_distance_m` (where the rays stop, so the land seen
/// further has no seam); [`LAND_ALBEDO`] when off, when the ray looks
/// up, or beyond `max_distance_m`.
pub fn flat_ground_albedo(origin: Vec3, dir: Vec3, spread: f32, fr: &Frame) -> Vec3 {
    if !fr.quality.land_fields || dir.y >= 0.0 || origin.y <= 0.0 {
        return LAND_ALBEDO;
    }
    let t = origin.y / -dir.y;
    if t > fr.quality.max_distance_m {
        return LAND_ALBEDO;
    }
    let (x, z) = (origin.x + dir.x * t, origin.z + dir.z * t);
    let land = land_albedo(
        x,
        z,
        ground_footprint(spread, t, dir.y),
        fr.fields.cloud_map.noise(),
    );
    let far = (4.0 * t / fr.quality.max_distance_m - 3.0).clamp(0.0, 1.0);
    land.lerp(LAND_ALBEDO, far)
}

#[inline]
fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
#[path = "land_tests.rs"]
mod tests;
