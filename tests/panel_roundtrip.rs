//! The sky demo's panel state round-trips through a scene file: set every
//! control, save, load, and read the same panel back.

use cumulus::panel::PanelState;
use cumulus::scene::Scene;

fn roundtrip(name: &str) {
    let path = std::path::PathBuf::from(format!("scenes/{name}.toml"));
    let mut scene = Scene::load(&path).expect("shipped scene");
    let band = scene.band(&scene.atmosphere(None).expect("atmosphere"));
    let mut panel = PanelState::from_scene(&scene, band);
    // Every control moved away from the scene's value.
    panel.coverage = 0.63;
    panel.parcels = 333;
    panel.wind_speed_mps = 7.25;
    panel.wind_direction_deg = 212.5;
    panel.sun_elevation_deg = 17.5;
    panel.sun_azimuth_deg = 251.0;
    panel.band_bottom_m = 812.5;
    panel.band_top_m = 2104.0;
    panel.tsaa = !panel.tsaa;
    panel.steps = 37;
    panel.shadow_steps = 3;
    panel.octaves = 1;
    panel.terrain = !panel.terrain;
    panel.fields = !panel.fields;
    panel.fine_detail = !panel.fine_detail;
    panel.physical_sky = !panel.physical_sky;
    panel.aerosol_optical_depth = 0.42;
    panel.exposure = 2.5;
    panel.auto_exposure = !panel.auto_exposure;
    panel.sun_glare = 0.35;
    panel.apply(&mut scene);

    // Saved elsewhere: a sounding path must still find its file.
    let dir = tempfile::tempdir().unwrap();
    let saved = dir.path().join("tuned.toml");
    scene.save(&saved).expect("save");
    let loaded = Scene::load(&saved).expect("the saved scene loads");
    assert!(
        scene.same_settings(&loaded),
        "{name}: saved and loaded scenes differ"
    );
    let band = loaded.band(
        &loaded
            .atmosphere(None)
            .expect("the sounding is found from the new place"),
    );
    assert_eq!(PanelState::from_scene(&loaded, band), panel, "{name}");

    // The comparison can fail: one changed value is seen.
    let mut other = loaded.clone();
    other.render.octaves = 3;
    assert!(!scene.same_settings(&other));
}

#[test]
fn panel_state_round_trips_through_a_scene_file() {
    roundtrip("fair_weather");
    roundtrip("bomex"); // has a sounding file, relative to the scene
    roundtrip("evening");
}
