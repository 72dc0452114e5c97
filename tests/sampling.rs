//! Sampling without patterns (CPU): the blue-noise dither with its
//! per-frame golden-ratio offsets leaves only unstructured grain, which
//! the frames TSAA accumulates remove, measured as the high-pass energy
//! of cloud pixels against a 512-step reference and the error's
//! correlation with itself (`render_quality::measure_highpass`).

use cumulus::prepare::Prepared;
use cumulus::report::render_quality::measure_highpass;
use cumulus::scene::{RenderSettings, Scene};

fn scene(name: &str) -> Scene {
    let mut sc =
        Scene::load(std::path::Path::new(&format!("scenes/{name}.toml"))).expect("shipped scene");
    // A quick light volume: the scenes' 1024 photons a column take a
    // minute to build on lavapipe, and no test here measures the light.
    sc.render.light_photons = 16;
    sc
}

/// The 16 frames TSAA accumulates at the scene's 48 steps carry about
/// the reference's fine detail and no more (grain or patterns would raise
/// it, blur would lower it), and one frame carries more (its dither's
/// grain), so the measure sees the grain it is there to catch.
#[test]
fn converged_frames_have_the_references_high_pass_energy() {
    for (name, pitch) in [("fair_weather", None), ("fair_weather", Some(4.0_f32))] {
        let mut sc = scene(name);
        if let Some(p) = pitch {
            // Toward the horizon, where distant clouds are smallest.
            sc.render.camera_pitch_deg = p;
        }
        let prepared = Prepared::from_scene(&sc, || {}).expect("prepare");
        let r = RenderSettings {
            width: 120,
            height: 90,
            ..sc.render.clone()
        };
        let hp = measure_highpass(&prepared.frame(&r, r.quality()), r.width, r.height);
        eprintln!(
            "{name} pitch {pitch:?}: {} cloud pixels, reference {:.3e}, one frame {:.2}x, converged {:.2}x, pattern {:.3}",
            hp.cloud_pixels,
            hp.reference,
            hp.one_frame_ratio(),
            hp.converged_ratio(),
            hp.one_frame_pattern
        );
        assert!(hp.cloud_pixels > 500, "{} cloud pixels", hp.cloud_pixels);
        let c = hp.converged_ratio();
        assert!((0.8..=1.2).contains(&c), "converged ratio {c}");
        assert!(
            hp.one_frame_ratio() > c,
            "one frame {} vs converged {c}",
            hp.one_frame_ratio()
        );
        // The error of one frame is unstructured: its largest positive
        // correlation at a lag measured 0.084 and 0.057 (negative ones are
        // left out: the blue noise's own ring, -0.16 at a lag of (5, 4),
        // is most of what is left toward the horizon). This guards
        // against patterned error in the image, such as banding; it does
        // not tell the dithers apart (an interleaved gradient noise
        // passes it too). The dither's own pattern is tested in
        // `render::sampling`.
        assert!(
            hp.one_frame_pattern < 0.095,
            "one frame's error correlates {} with itself at some lag",
            hp.one_frame_pattern
        );
    }
}
