//! The scene's parsing and checks: errors that name the file, line and
//! key, and the scene-wide rules `Scene::parse` applies.

use super::*;

#[test]
fn spheroids_and_the_endless_volumes_meter_the_analytic_sky_they_draw() {
    use crate::render::cpu::exposure::auto_exposure_factor;
    use crate::render::cpu::sky::SkyModel;
    let physical = |renderer: &str, method: &str| {
        let text = format!(
            "[simulation]\nmethod = \"{method}\"\n\n[render]\nrenderer = \"{renderer}\"\n\
             sun_elevation_deg = -10.0\n\n[render.atmosphere]\nmodel = \"physical\"\n"
        );
        Scene::parse(&text, Path::new("s.toml")).expect("valid")
    };
    for s in [
        physical("spheroids", "parcels"),
        physical("cloud_map", "endless"),
    ] {
        let r = &s.render;
        assert_eq!(r.atmosphere.model, SkyModel::Analytic);
        let analytic = auto_exposure_factor(&r.atmosphere, -10.0, r.camera_position_m[1]);
        assert_eq!(r.exposure_factor(), analytic);
    }
    // The cloud map keeps the physical sky, and at -10° it is metered
    // open by far more than the analytic sky (the burn-out).
    let s = physical("cloud_map", "parcels");
    let r = &s.render;
    assert_eq!(r.atmosphere.model, SkyModel::Physical);
    let mut analytic = r.atmosphere;
    analytic.model = SkyModel::Analytic;
    let open = r.exposure_factor() / auto_exposure_factor(&analytic, -10.0, r.camera_position_m[1]);
    assert!(open > 100.0, "physical over analytic {open}");
}

#[test]
fn terrain_tiles_too_small_for_the_longest_ray_are_refused() {
    let text = |enabled: bool| format!("[render.terrain]\nenabled = {enabled}\nextent_m = 30.0\n");
    // 40 km rays over 30 m tiles: 1334 repeats each way, over 512.
    let e = Scene::parse(&text(true), Path::new("s.toml")).expect_err("too small");
    assert_eq!(
        e.to_string(),
        "s.toml:3: `render.terrain.extent_m`: is 30, expected at least \
         render.max_distance_m / 512 = 78.125 m with the terrain on (it repeats every \
         extent_m, and the GPU draws a copy per repeat out to max_distance_m)"
    );
    // Off, the key is not used.
    Scene::parse(&text(false), Path::new("s.toml")).expect("terrain off");
    let ok =
        "[render]\nmax_distance_m = 15000.0\n\n[render.terrain]\nenabled = true\nextent_m = 30.0\n";
    Scene::parse(ok, Path::new("s.toml")).expect("15 km rays: 500 repeats");
}

#[test]
fn negative_radius_names_key_and_line() {
    let e = Scene::parse(
        "[physics]\nparcels = 3\nradius_m = -5\n",
        Path::new("s.toml"),
    )
    .expect_err("negative");
    assert_eq!(
        e.to_string(),
        "s.toml:3: `physics.radius_m`: is -5, expected 1e-3..=1e5 m"
    );
}

#[test]
fn the_automaton_s_keys_are_checked_and_spheroids_need_parcels() {
    let e = Scene::parse(
        "[simulation]\nmethod = \"automaton\"\n\n[simulation.automaton]\nextinction = 1.5\n",
        Path::new("s.toml"),
    )
    .expect_err("probability above 1");
    assert_eq!(
        e.to_string(),
        "s.toml:5: `simulation.automaton.extinction`: is 1.5, expected a probability in 0..=1"
    );
    let e = Scene::parse(
        "[simulation]\nmethod = \"automaton\"\n\n[render]\nrenderer = \"spheroids\"\n",
        Path::new("s.toml"),
    )
    .expect_err("no parcels to draw");
    assert!(
        e.to_string()
            .starts_with("s.toml:5: `render.renderer`: is \"spheroids\""),
        "{e}"
    );
    let s = Scene::parse("[render]\nrenderer = \"spheroids\"\n", Path::new("s.toml"))
        .expect("spheroids over parcels");
    assert_eq!(s.render.renderer, RenderMethod::Spheroids);
}

#[test]
fn release_and_band_above_the_atmospheres_top_are_refused() {
    let atm = |text: &str| {
        Scene::parse(text, Path::new("s.toml"))
            .expect("valid keys")
            .atmosphere(None)
    };
    // Parcels released above the table's 8000 m top sat there.
    let e = atm("[physics]\nrelease_height_m = 1e5\n")
        .map(|_| ())
        .expect_err("released above");
    assert_eq!(
        e.to_string(),
        "s.toml:2: `physics.release_height_m`: is 100000, expected below the \
         atmosphere's top at 8000 m (`atmosphere.parametric.top_m`)"
    );
    // A top under the (default) inversion, which the table then lacks:
    // blamed on the key the file wrote.
    let e = atm("[atmosphere.parametric]\ntop_m = 1000\n")
        .map(|_| ())
        .expect_err("top under the inversion");
    assert!(
        e.to_string().starts_with(
            "s.toml:2: `atmosphere.parametric.top_m`: the inversion (inversion_base_m 1500 m)"
        ),
        "{e}"
    );
    let e = atm("[atmosphere.parametric]\ninversion_base_m = 9000\n")
        .map(|_| ())
        .expect_err("inversion above the top");
    assert!(
        e.to_string()
            .starts_with("s.toml:2: `atmosphere.parametric.inversion_base_m`: the inversion"),
        "{e}"
    );
    // A band starting above a low top (the LCL is above it).
    let e = atm("[atmosphere.parametric]\ntop_m = 300\ninversion_base_m = 200\n")
        .map(|_| ())
        .expect_err("band above the top");
    assert!(e.to_string().contains("the cloud band starts at"), "{e}");
    // A band the user set is blamed on its own key.
    let e = atm("[projection]\nband_bottom_m = 700\nband_top_m = 9000\n")
        .map(|_| ())
        .expect_err("band_top above the top");
    assert!(
        e.to_string()
            .starts_with("s.toml:3: `projection.band_top_m`: the cloud band reaches 9000 m"),
        "{e}"
    );
    // The shipped default is within.
    atm("").expect("default scene");
    // A short sounding with no inversion: the default band (LCL +
    // 1500 m) ends at its top rather than being refused.
    let dir = tempfile::tempdir().expect("dir");
    let mut rows = String::from("height_m,pressure_hPa,temperature_C,dewpoint_C\n");
    for k in 0..=20 {
        let z = 100.0 * k as f64;
        rows += &format!("{z},,{},{}\n", 25.0 - 0.0065 * z, 10.0 - 0.002 * z);
    }
    crate::io::write_atomically(&dir.path().join("short.csv"), |o| {
        o.write_all(rows.as_bytes())
    })
    .expect("write");
    let path = dir.path().join("s.toml");
    let scene = Scene::parse("[atmosphere]\nsounding = \"short.csv\"\n", &path).expect("keys");
    let a = scene
        .atmosphere(None)
        .expect("a band within a 2 km sounding");
    let band = scene.band(&a);
    assert!(band.bottom_m > 500.0 && band.top_m == a.top_m(), "{band:?}");
}

#[test]
fn a_kernel_too_wide_for_the_domain_names_the_parcels_radius() {
    let e = Scene::parse("[physics]\nradius_m = 1e5\n", Path::new("s.toml"))
        .expect_err("kernel wider than the domain");
    let msg = e.to_string();
    assert!(
        msg.starts_with("s.toml:2: `physics.radius_m`: is 100000, expected at most"),
        "{msg}"
    );
    assert!(!msg.contains("`physics.sph.smoothing_radii`"), "{msg}");
}

#[test]
fn type_errors_speak_of_numbers_and_tables_not_rust_types() {
    for (text, said) in [
        (
            "[render]\nwidth = \"wide\"\n",
            "expected a whole number, 0 or more",
        ),
        ("[physics]\ndt_s = \"x\"\n", "expected a number"),
        ("render = 5\n", "expected a table of keys"),
        ("[render]\ntsaa = 3\n", "expected true or false"),
    ] {
        let e = Scene::parse(text, Path::new("s.toml")).expect_err("wrong type");
        let msg = e.to_string();
        assert!(msg.ends_with(said), "{msg}");
        for rust in ["u32", "f64", "struct", "RenderSettings"] {
            assert!(!msg.contains(rust), "{msg}");
        }
    }
}

#[test]
fn unknown_key_names_line() {
    let e = Scene::parse("[physics]\nparcels = 3\nradius = 5\n", Path::new("s.toml"))
        .expect_err("unknown");
    let msg = e.to_string();
    assert!(msg.starts_with("s.toml:3:"), "{msg}");
    assert!(msg.contains("unknown field `radius`"), "{msg}");
}
