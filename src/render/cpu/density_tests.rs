use super::*;
use crate::render::cloud_map::CloudMapConfig;

/// The skipping of reads changes nothing: `detail_profile` equals the
/// profile of the full `detail_noise` bit for bit.
#[test]
fn detail_profile_is_the_profile_of_the_full_noise() {
    let map = CloudMap::generate(&CloudMapConfig::default());
    let v = map.noise();
    let mut decided = 0;
    for k in 0..20_000 {
        let t = k as f32;
        let p = Vec3::new(t * 41.3, 900.0 + (t * 0.37).sin() * 500.0, t * 17.9);
        let m = (t * 0.618_034).fract();
        let threshold = 0.3 + 0.7 * (t * 0.414_213).fract();
        let s = [0.3, 0.6, 1.0][k % 3];
        let footprint = [0.0, 4.5, 30.0, 400.0][(k / 3) % 4];
        let fine = k % 7 != 0;
        let full = surface_profile(m, detail_noise(p, 180.0, footprint, fine, v), s, threshold);
        let d = DensityParams {
            band_bottom_m: 600.0,
            band_top_m: 1600.0,
            coverage: 0.75,
            extinction_per_m: 0.04,
            map_extent_m: 10_000.0,
            detail_strength: s,
            detail_scale_m: 180.0,
            fine_detail: fine,
        };
        let fast = detail_profile(p, m, threshold, s, footprint, &d, v);
        assert_eq!(full.to_bits(), fast.to_bits(), "at {p}: {full} vs {fast}");
        decided += usize::from(fast == 0.0 || fast == 1.0);
    }
    assert!(decided > 1000 && decided < 19_000, "{decided} decided");
}

/// The fine billows are about 0 on the mean, break the surface near
/// the camera, and are gone from twice [`FINE_SHARP_M`] on.
#[test]
fn fine_billows_are_near_only() {
    let map = CloudMap::generate(&CloudMapConfig::default());
    let v = map.noise();
    let at = |footprint: f32| -> Vec<f32> {
        (0..20_000)
            .map(|k| {
                let k = k as f32;
                let p = Vec3::new(k * 3.1, 800.0 + (k * 0.37).sin() * 300.0, k * 1.7);
                detail_fine(p, 180.0, footprint, true, v)
            })
            .collect()
    };
    let near = at(1.0);
    let mean = near.iter().sum::<f32>() / near.len() as f32;
    let sd = (near.iter().map(|f| (f - mean).powi(2)).sum::<f32>() / near.len() as f32).sqrt();
    assert!(mean.abs() < 0.01, "mean {mean}");
    assert!(sd > 0.2 * FINE_WEIGHT, "sd {sd}");
    assert!(at(2.0 * FINE_SHARP_M).iter().all(|&f| f == 0.0));
    assert!(at(9.8).iter().all(|&f| f == 0.0));
    // Off, nothing near either.
    assert_eq!(fine_weight(0.0, false), 0.0);
}

/// [`DETAIL_CONTRAST`] widens the detail noise to about a uniform
/// variable's spread (0.29) at full resolution, and far away, where
/// the ranked mips are read, the spread stays (the same erosion, at
/// the coarser level's larger features).
#[test]
fn detail_contrast_matches_the_volume() {
    let map = CloudMap::generate(&CloudMapConfig::default());
    let spread = |footprint: f32| {
        let n = 20_000;
        let vals: Vec<f32> = (0..n)
            .map(|k| {
                let k = k as f32;
                let p = Vec3::new(k * 37.1, (k * 0.61).sin() * 900.0 + 1200.0, k * 13.7);
                detail_noise(p, 180.0, footprint, false, map.noise())
            })
            .collect();
        let mean = vals.iter().sum::<f32>() / n as f32;
        let var = vals.iter().map(|v| (v - mean).powi(2)).sum::<f32>() / n as f32;
        (mean, var.sqrt())
    };
    let (mean, sd) = spread(0.0);
    assert!((mean - 0.5).abs() < 0.02, "mean {mean}");
    let widened = sd * DETAIL_CONTRAST;
    assert!((widened - 0.289).abs() < 0.03, "sd {sd}, widened {widened}");
    let (far_mean, far) = spread(200.0);
    // (Level 4 has 4³ texels: its mean is known to about 0.29/8.)
    assert!(
        (far_mean - 0.5).abs() < 0.05,
        "mean {far_mean} at a 200 m footprint"
    );
    assert!(
        (far - sd).abs() < 0.15 * sd,
        "sd {sd} near, {far} at a 200 m footprint"
    );
    let (_, very_far) = spread(2_000.0);
    assert!(
        (very_far - sd).abs() < 0.2 * sd,
        "sd {sd} near, {very_far} at 2 km"
    );
}

/// No cloud is cut off flat at its local top: even the field's highest
/// value (map and noise both 1, above 1 for any mix) fades out before
/// the top, whatever the mix, the cover and the top. With a threshold
/// that stopped at 1 a mixed field's core kept its full density up to
/// the top (the profile 1 at `s` 0.6) and ended in a flat lid.
#[test]
fn cloud_tops_are_rounded_not_cut() {
    for s in [0.0, 0.3, 0.6, 1.0] {
        for cover in [0.2, 0.6, 1.0] {
            for top in [0.3, 0.7, 1.0] {
                let near_top = |eta: f32| {
                    let threshold = cumulus_threshold(eta, top, cover, 1.0, s);
                    surface_profile(1.0, 1.0, s, threshold)
                };
                let at_top = near_top(0.9999 * top);
                assert!(
                    at_top < 0.01,
                    "s {s} cover {cover} top {top}: {at_top} at the top"
                );
                // Below the rounding the dome is as it was: the core is whole.
                let below = near_top(0.7 * top);
                assert!(
                    below > 0.99,
                    "s {s} cover {cover} top {top}: {below} under the top"
                );
            }
        }
    }
}

/// Clouds end before the parcels' spread coverage does. `footprint`
/// cuts the density off where P's coverage falls to 1e-3; with a
/// threshold that went to 1 as the cover went to 0, the mixed field's
/// values over 1 (map and noise both high) would keep their full density
/// up to that contour and end in a vertical wall there (the profile 1 at
/// `s` 0.3 and 0.6). The densest field fades out before it, grows back
/// smoothly over the fringe, and from [`FRINGE_PRESENCE`] on the
/// threshold is the one without a fringe, for any scene coverage.
#[test]
fn clouds_fade_out_at_the_fringe_of_the_parcels_coverage() {
    let (eta, top) = (0.3, 0.8);
    for s in [0.0, 0.3, 0.6, 1.0] {
        for coverage in [0.1, 0.6, 1.0] {
            let threshold =
                |presence: f32| cumulus_threshold(eta, top, coverage * presence, presence, s);
            let densest = |presence: f32| surface_profile(1.0, 1.0, s, threshold(presence));
            // Where P's coverage ends, under the strongest weather too.
            let at_cut = densest(1e-3).max(densest(WEATHER_MAX * P_COVERAGE_MIN));
            assert!(
                at_cut < 0.02,
                "s {s} coverage {coverage}: {at_cut} where P's coverage ends"
            );
            let mut last = densest(1e-3);
            for i in 1..=2000 {
                let now = densest(1e-3 + 0.02 * i as f32 / 2000.0);
                assert!(
                    now >= last && now - last < 0.05,
                    "s {s} coverage {coverage}: {last} -> {now} at step {i}"
                );
                last = now;
            }
            // Beyond the fringe the threshold is the one without it, at
            // a top climbing (eta 0.9 of the top) or not.
            for presence in [FRINGE_PRESENCE, 0.5, 1.0] {
                let cover = coverage * presence;
                for eta in [eta, 0.9 * top] {
                    let t = eta / top;
                    let plain = 1.0
                        - cover * smoothstep(0.0, BASE_RAMP, eta) * (1.0 - t * t).max(0.0)
                        + (field_max(s) - 1.0) * smoothstep(TOP_ROUNDING, 1.0, t);
                    let now = cumulus_threshold(eta, top, cover, presence, s);
                    assert_eq!(now, plain, "s {s} coverage {coverage} eta {eta}");
                }
            }
        }
    }
}
