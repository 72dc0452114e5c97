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
    let n = 400;
    let woods = (0..n * n)
        .filter(|&k| {
            let (x, z) = (
                (k % n) as f32 * 97.3 - 9000.0,
                (k / n) as f32 * 101.7 + 300.0,
            );
            woods_cover(x, z, 1.0, &v) > 0.5
        })
        .count() as f32
        / (n * n) as f32;
    assert!((0.22..0.38).contains(&woods), "woods {woods}");
    let spread = all.iter().map(|a| (a.x / mean.x - 1.0).abs()).sum::<f32>() / all.len() as f32;
    assert!(spread > 0.15, "red channel's mean deviation {spread}");
}

#[test]
fn the_tints_means_are_the_crops_and_the_woods() {
    // CROPS_MEAN, HEDGE_SHARE, FIELDS_MEAN and LAND_TINT_MEAN are
    // written out (their WGSL twins are literals); they must stay
    // what they stand for.
    let crops = (0..4).map(crop).sum::<Vec3>() / 4.0;
    assert!((crops - CROPS_MEAN).abs().max_element() < 1e-6, "{crops}");
    let rows = HEDGE_CHANCE * HEDGE_M / FIELD_WIDTH_M;
    let lengths = (0..256)
        .map(|k| 1.0 / (FIELD_LENGTH_M * (0.6 + 0.8 * k as f32 / 255.0)))
        .sum::<f32>()
        / 256.0;
    let fields = HEDGE_CHANCE * HEDGE_M * lengths;
    let share = rows + fields - rows * fields;
    assert!((share - HEDGE_SHARE).abs() < 1e-6, "{share}");
    let mean = CROPS_MEAN * (1.0 - HEDGE_SHARE) + HEDGE * HEDGE_SHARE;
    assert!((mean - FIELDS_MEAN).abs().max_element() < 1e-6, "{mean}");
    let land = WOODS * WOODS_SHARE + FIELDS_MEAN * (1.0 - WOODS_SHARE);
    assert!((land - LAND_TINT_MEAN).abs().max_element() < 1e-6, "{land}");
}

#[test]
fn hedges_cover_their_share() {
    // Averaged over a parcel, the box-filtered strips cover the
    // strip's width over the parcel's, whatever the footprint (the
    // part of this parcel's strip that a window spills before 0 is
    // the part of the next one's it takes in before `period`).
    for footprint_m in [0.0, 1.0, 7.0, 60.0, 120.0] {
        let n = 20_000;
        let mean = (0..n)
            .map(|k| {
                hedge_cover(
                    (k as f32 + 0.5) * 130.0 / n as f32,
                    130.0,
                    footprint_m,
                    1.0,
                    1.0,
                )
            })
            .sum::<f32>()
            / n as f32;
        assert!(
            (mean - HEDGE_M / 130.0).abs() < 2e-4,
            "{footprint_m} m: {mean}"
        );
    }
    // A point sample is the strip itself; no hedge, no cover.
    assert!(hedge_cover(2.0, 130.0, 0.0, 1.0, 0.0) > 0.999);
    assert_eq!(hedge_cover(5.0, 130.0, 0.0, 1.0, 1.0), 0.0);
    assert_eq!(hedge_cover(2.0, 130.0, 0.0, 0.0, 1.0), 0.0);
    // Half a 4 m footprint over the strip's edge.
    assert!((hedge_cover(4.0, 130.0, 4.0, 1.0, 1.0) - 0.5).abs() < 1e-6);
    // On the land, the hedges' share is HEDGE_SHARE: the points
    // wholly under a hedge, seen sharp.
    let v = volume();
    let n = 400;
    let hedges = (0..n * n)
        .filter(|k| {
            let (x, z) = ((k % n) as f32 * 9.73 + 1.1, (k / n) as f32 * 10.17 - 3.0);
            (field_tint(x, z, 0.0, &v) - HEDGE).abs().max_element() < 2e-3
        })
        .count() as f32
        / (n * n) as f32;
    assert!((hedges / HEDGE_SHARE - 1.0).abs() < 0.1, "{hedges}");
}

#[test]
fn the_canopy_keeps_the_woods_mean_and_fades() {
    // CROWN_LIGHT_MEAN is the crowns' mean light (written out: its
    // WGSL twin is a literal), so the canopy's mean factor is 1.
    let n = 600;
    let points = |k: usize| ((k % n) as f32 * 0.731 + 3.0, (k / n) as f32 * 0.697 - 40.0);
    let light = (0..n * n)
        .map(|k| {
            let (x, z) = points(k);
            crown_light(x, z)
        })
        .sum::<f32>()
        / (n * n) as f32;
    assert!(
        (light / CROWN_LIGHT_MEAN - 1.0).abs() < 0.01,
        "mean light {light}"
    );
    let at = |footprint_m: f32| -> Vec<f32> {
        (0..n * n)
            .map(|k| {
                let (x, z) = points(k);
                canopy(x, z, footprint_m)
            })
            .collect()
    };
    let sharp = at(1.0);
    let mean = sharp.iter().sum::<f32>() / sharp.len() as f32;
    let sd = (sharp.iter().map(|c| (c - mean).powi(2)).sum::<f32>() / sharp.len() as f32).sqrt();
    assert!((mean - 1.0).abs() < 0.01, "mean {mean}");
    assert!(sd > 0.15, "sd {sd}");
    // The gaps between crowns are dark, the crowns' middles bright.
    let darkest = sharp.iter().cloned().fold(f32::MAX, f32::min);
    let brightest = sharp.iter().cloned().fold(0.0, f32::max);
    assert!(darkest < 0.62 && brightest > 1.35, "{darkest}..{brightest}");
    // Half faded at three quarters of a crown's square; gone at one.
    let half = at(0.75 * CROWN_M);
    let sd_half = (half.iter().map(|c| (c - 1.0).powi(2)).sum::<f32>() / half.len() as f32).sqrt();
    assert!((sd_half / sd - 0.5).abs() < 0.02, "{sd_half} against {sd}");
    assert!(at(CROWN_M).iter().all(|&c| c == 1.0));
    // No tile: the crowns 1 km apart differ.
    let apart = (0..1000)
        .filter(|&k| {
            let x = k as f32 * 9.0 + 4.5;
            (crown_light(x, 4.5) - crown_light(x + 1000.0 * CROWN_M, 4.5)).abs() > 0.01
        })
        .count();
    assert!(apart > 800, "{apart} of 1000 differ");
}

#[test]
fn fields_fade_to_their_mean_where_a_pixel_covers_them() {
    // Up to half a field's width each parcel keeps its crop; from a
    // whole width on, every point has the fields' mean; between, the
    // spread around that mean falls.
    let v = volume();
    let spread = |footprint_m: f32| {
        (0..4000)
            .map(|k| {
                let (x, z) = (k as f32 * 37.1, (k % 61) as f32 * 53.9);
                (field_tint(x, z, footprint_m, &v) - FIELDS_MEAN)
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
    // (At 0.75 of the width, half faded; the patches and the hedges
    // are read with the wider footprint too.)
    assert!(
        half > 0.35 * sharp && half < 0.6 * sharp,
        "{half} against {sharp}"
    );
    assert_eq!(blurred, 0.0);
}

#[test]
fn neighbouring_fields_differ() {
    // Along a row, about two fields on: most change crop or shade.
    let v = volume();
    let mut changed = 0;
    for k in 0..400 {
        let (x, z) = (k as f32 * 613.7, (k % 17) as f32 * 419.3);
        let (s, c) = (FIELD_ANGLE + FARM_TURN * (farm(x, z) & 3) as f32).sin_cos();
        let step = 1.5 * FIELD_LENGTH_M;
        let (a, b) = (
            field_tint(x, z, 1.0, &v),
            field_tint(x + step * c, z + step * s, 1.0, &v),
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
