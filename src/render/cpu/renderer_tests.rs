use super::*;
use crate::render::cpu::lighting::{AMBIENT_GAIN_ALONE, GROUND_LIGHT_GAIN_ALONE};

/// The coarse steps span the segment exactly, grow with distance along
/// a long horizontal ray, and are uniform looking down on the band.
#[test]
fn march_steps_span_the_segment_and_grow_with_distance() {
    for (t0, t1) in [
        (0.0_f32, 50_000.0_f32),
        (7_500.0, 9_000.0),
        (120.0, 4_000.0),
    ] {
        let lr = ((t1 + NEAR_M) / (t0 + NEAR_M)).ln();
        assert!((march_distance(t0, lr, 0.0) - t0).abs() < 1e-3);
        assert!((march_distance(t0, lr, 1.0) - t1).abs() < 1e-3 * t1.max(1.0));
        let step = |i: u32| {
            march_distance(t0, lr, (i + 1) as f32 / 48.0) - march_distance(t0, lr, i as f32 / 48.0)
        };
        let (first, last) = (step(0), step(47));
        assert!(first > 0.0 && last >= first, "{first} {last}");
        if t0 == 0.0 {
            // 50 km from inside the band: 185 m near, 3.1 km far.
            assert!((150.0..220.0).contains(&first) && (2_900.0..3_500.0).contains(&last));
        }
        if t0 == 7_500.0 {
            assert!(last / first < 1.2, "{first} {last}");
        }
    }
}

/// The ground's light fills the band's bottom and none of its top;
/// the sky's fills the top and 0.35 of the bottom.
#[test]
fn ground_light_reaches_the_base_not_the_top() {
    let (sky, ground) = (Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 0.0));
    // Without a light volume (the gains with a ground's light).
    let g = &crate::render::cpu::lighting::LightGains::ALONE;
    let top = ambient_light(sky, ground, 1.0, g);
    let base = ambient_light(sky, ground, 0.0, g);
    assert_eq!(top.x, 0.0, "ground light at the top: {top}");
    assert!((base.x - GROUND_LIGHT_GAIN_ALONE).abs() < 1e-6, "{base}");
    assert!((top.z - AMBIENT_GAIN_ALONE).abs() < 1e-6, "{top}");
    assert!((base.z - 0.35 * AMBIENT_GAIN_ALONE).abs() < 1e-6, "{base}");
    // Halfway up, half the ground's light.
    let mid = ambient_light(sky, ground, 0.5, g);
    assert!(
        (mid.x - 0.5 * GROUND_LIGHT_GAIN_ALONE).abs() < 1e-6,
        "{mid}"
    );
}

/// A ray 3° up from 60 m under the default band (579-1600 m) crosses it
/// from about 10 to 30 km: its coarse steps stay short enough, for their
/// distance, to hit the clouds there (at the scene's 48 steps alone they
/// would be 250-640 m long, and clouds between two steps' ends would come
/// and go with the dither: stripes along the horizon). Rays that look up steeply
/// keep the scene's steps, and none takes more than the cap.
#[test]
fn grazing_rays_take_more_steps() {
    let steps = 48;
    let segment = |elevation_deg: f32| {
        let s = elevation_deg.to_radians().sin();
        ((579.0 - 60.0) / s, (1600.0 - 60.0) / s)
    };
    let longest_step = |t0: f32, t1: f32| {
        let lr = ((t1 + NEAR_M) / (t0 + NEAR_M)).ln();
        let n = march_step_count(steps, lr);
        let s = |i: u32| march_distance(t0, lr, i as f32 / n as f32);
        (n, (0..n).map(|i| s(i + 1) - s(i)).fold(0.0_f32, f32::max))
    };
    let (t0, t1) = segment(3.0);
    let (n, longest) = longest_step(t0, t1);
    assert!(n > 2 * steps, "{n}");
    assert!(
        longest < 260.0,
        "longest coarse step {longest} m over {t0}-{t1} m"
    );
    for elevation in [45.0, 60.0, 90.0] {
        let (t0, t1) = segment(elevation);
        assert_eq!(longest_step(t0, t1).0, steps, "{elevation}°");
    }
    // A horizontal ray through 40 km of band from inside it: capped.
    assert_eq!(
        march_step_count(steps, (43_000.0_f32 / NEAR_M).ln()),
        (MARCH_STEP_FACTOR_MAX * steps as f32) as u32
    );
    assert_eq!(march_step_count(0, 0.1), 1);
}
