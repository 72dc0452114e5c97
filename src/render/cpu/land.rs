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
//! scales, at the mip level of the pixel's footprint; the fields are
//! parcels in rows, the rows of each farm (a block about 1.7 km across)
//! on one of four headings, each row's fields of their own length, each
//! parcel one of four crops by a hash of its cell. Where a pixel
//! covers more than half a field's width the parcels fade to their mean;
//! the woods' edges soften as the footprint grows past 40 m, and from a
//! footprint of 1 km to 2 km the woods fade to their share of the land,
//! so the far land neither aliases nor shimmers, and is the plain land's
//! colour where no pattern can be resolved.

use glam::Vec3;

use super::density::{NOISE_MAX_LOD, gained, lod_of};
use super::renderer::Frame;
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
/// The mean of the land's tint before the normalisation: [`WOODS_SHARE`]
/// woods, the rest the crops' mean; the tint is divided by it, so the land's mean
/// albedo is [`LAND_ALBEDO`].
pub const LAND_TINT_MEAN: Vec3 = Vec3::new(1.05375, 0.97875, 0.80875);

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
/// brighter or darker by up to 12 %, faded to the crops' mean as the
/// footprint `footprint_m` grows from half a field's width to a whole one.
/// Each farm ([`farm`]) turns its rows by a multiple of [`FARM_TURN`];
/// each row has its own fields' length (0.6 to 1.4 of
/// [`FIELD_LENGTH_M`]) and start.
#[inline]
pub fn field_tint(x: f32, z: f32, footprint_m: f32) -> Vec3 {
    let fade = (2.0 - 2.0 * footprint_m / FIELD_WIDTH_M).clamp(0.0, 1.0);
    if fade <= 0.0 {
        return CROPS_MEAN;
    }
    let b = farm(x, z);
    let (s, c) = (FIELD_ANGLE + FARM_TURN * (b & 3) as f32).sin_cos();
    let along = x * c + z * s;
    let across = -x * s + z * c;
    let row = (across / FIELD_WIDTH_M).floor() as i32;
    let r = field_hash(row, (b >> 8) as i32);
    let length = FIELD_LENGTH_M * (0.6 + 0.8 * ((r >> 12) & 255) as f32 / 255.0);
    let field = (along / length + (r & 1023) as f32 / 1024.0).floor() as i32;
    let h = field_hash(row, field) ^ b;
    let shade = 1.0 + 0.24 * (((h >> 8) & 255) as f32 / 255.0 - 0.5);
    CROPS_MEAN.lerp(crop(h) * shade, fade)
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
    let tint = field_tint(x, z, footprint_m).lerp(WOODS, woods);
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
mod tests {
    use super::*;
    use crate::render::cloud_map::CloudMap;

    fn volume() -> std::sync::Arc<NoiseVolume> {
        CloudMap::generate(&Default::default()).noise_shared()
    }

    /// The land's albedo at `n x n` points 97 m apart (not a divisor of
    /// the fields' or the woods' scales) seen with `footprint_m`.
    fn samples(n: usize, footprint_m: f32, v: &NoiseVolume) -> Vec<Vec3> {
        (0..n * n)
            .map(|k| {
                let (x, z) = (
                    (k % n) as f32 * 97.3 - 9000.0,
                    (k / n) as f32 * 101.7 + 300.0,
                );
                land_albedo(x, z, footprint_m, v)
            })
            .collect()
    }

    fn mean_of(all: &[Vec3]) -> Vec3 {
        all.iter().sum::<Vec3>() / all.len() as f32
    }

    #[test]
    fn the_fields_mean_albedo_is_the_plain_lands() {
        // 400 x 400 points over 39 x 41 km: five of the woods' larger
        // tiles each way, some 12,000 fields.
        let v = volume();
        let all = samples(400, 1.0, &v);
        let mean = mean_of(&all);
        let ratio = mean / LAND_ALBEDO;
        assert!(
            (ratio - Vec3::ONE).abs().max_element() < 0.03,
            "mean over plain {ratio}"
        );
        // Seen from afar too: fields faded, woods at a coarse mip level
        // with soft edges (200 m, 600 m), half faded (1.5 km), and where
        // nothing is resolved, the plain land itself (2 km).
        for footprint_m in [200.0, 600.0, 1500.0] {
            let r = mean_of(&samples(200, footprint_m, &v)) / LAND_ALBEDO;
            assert!(
                (r - Vec3::ONE).abs().max_element() < 0.05,
                "{footprint_m} m: {r}"
            );
        }
        for a in samples(20, 2000.0, &v) {
            assert!((a - LAND_ALBEDO).abs().max_element() < 1e-6, "{a}");
        }
        // About 30 % of it is wood (the threshold's aim), and the rest
        // varies from field to field.
        let woods =
            all.iter().filter(|a| a.y < 0.7 * LAND_ALBEDO.y).count() as f32 / all.len() as f32;
        assert!((0.22..0.38).contains(&woods), "woods {woods}");
        let spread = all.iter().map(|a| (a.x / mean.x - 1.0).abs()).sum::<f32>() / all.len() as f32;
        assert!(spread > 0.15, "red channel's mean deviation {spread}");
    }

    #[test]
    fn the_tints_means_are_the_crops_and_the_woods() {
        // CROPS_MEAN and LAND_TINT_MEAN are written out (their WGSL twins
        // are literals); they must stay the means of what they stand for.
        let crops = (0..4).map(crop).sum::<Vec3>() / 4.0;
        assert!((crops - CROPS_MEAN).abs().max_element() < 1e-6, "{crops}");
        let land = WOODS * WOODS_SHARE + CROPS_MEAN * (1.0 - WOODS_SHARE);
        assert!((land - LAND_TINT_MEAN).abs().max_element() < 1e-6, "{land}");
    }

    #[test]
    fn fields_fade_to_their_mean_where_a_pixel_covers_them() {
        // Up to half a field's width each parcel keeps its crop; from a
        // whole width on, every point has the crops' mean; between, the
        // spread around that mean falls.
        let spread = |footprint_m: f32| {
            (0..4000)
                .map(|k| {
                    let (x, z) = (k as f32 * 37.1, (k % 61) as f32 * 53.9);
                    (field_tint(x, z, footprint_m) - CROPS_MEAN)
                        .abs()
                        .max_element()
                })
                .sum::<f32>()
                / 4000.0
        };
        let (sharp, half, blurred) = (
            spread(10.0),
            spread(0.75 * FIELD_WIDTH_M),
            spread(FIELD_WIDTH_M),
        );
        assert!(sharp > 0.15, "{sharp}");
        assert!(
            (half - 0.5 * sharp).abs() < 0.05 * sharp,
            "{half} against {sharp}"
        );
        assert_eq!(blurred, 0.0);
    }

    #[test]
    fn neighbouring_fields_differ() {
        // Along a row, about two fields on: most change crop or shade.
        let mut changed = 0;
        for k in 0..400 {
            let (x, z) = (k as f32 * 613.7, (k % 17) as f32 * 419.3);
            let (s, c) = (FIELD_ANGLE + FARM_TURN * (farm(x, z) & 3) as f32).sin_cos();
            let step = 1.5 * FIELD_LENGTH_M;
            let (a, b) = (
                field_tint(x, z, 1.0),
                field_tint(x + step * c, z + step * s, 1.0),
            );
            changed += ((a - b).abs().max_element() > 0.01) as u32;
        }
        assert!(changed > 300, "{changed} of 400 neighbours differ");
    }

    #[test]
    fn farms_turn_their_rows() {
        // Over 40 km all four headings occur, none on more than a third
        // of the farms.
        let mut count = [0u32; 4];
        for k in 0..2500 {
            let (x, z) = ((k % 50) as f32 * 811.0, (k / 50) as f32 * 797.0);
            count[(farm(x, z) & 3) as usize] += 1;
        }
        assert!(count.iter().all(|&n| (400..850).contains(&n)), "{count:?}");
    }
}
