//! The `cumulus` binary from the outside: outputs, and bad input giving a
//! clear error (file, line, key), a non-zero exit, no panic and no output
//! file.

mod common;

use std::path::PathBuf;
use std::process::{Command, Output};

fn cumulus(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cumulus"))
        .args(args)
        .output()
        .expect("binary runs")
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs `simulate` on a scene written to a temp dir; asserts failure with a
/// message containing every `needle`, no panic, no output file.
fn assert_simulate_fails(scene: &str, sounding: Option<&str>, needles: &[&str]) {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene_path = dir.path().join("bad.toml");
    std::fs::write(&scene_path, scene).expect("write scene");
    if let Some(s) = sounding {
        std::fs::write(dir.path().join("snd.csv"), s).expect("write sounding");
    }
    let out = dir.path().join("curves.csv");
    let o = cumulus(&[
        "simulate",
        "--scene",
        scene_path.to_str().unwrap(),
        "--duration-s",
        "10",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert!(!o.status.success(), "should fail: {err}");
    assert_eq!(
        o.status.code(),
        Some(1),
        "clean error exit, not a panic (101): {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "stderr lacks `{n}`: {err}");
    }
    assert!(!out.exists(), "no output file on error");
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        leftovers.len(),
        1 + usize::from(sounding.is_some()),
        "no temp files left: {leftovers:?}"
    );
}

const GOOD_SOUNDING: &str =
    "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,20,15\n1000,,12,8\n3000,,0,-5\n";

#[test]
fn simulate_refuses_the_automaton_and_bad_methods_clearly() {
    assert_simulate_fails(
        "[simulation]\nmethod = \"automaton\"\n",
        None,
        &["bad.toml", "automaton", "no parcels"],
    );
    assert_simulate_fails(
        "[simulation]\nmethod = \"voxels\"\n",
        None,
        &["bad.toml:2:", "parcels", "automaton", "endless"],
    );
    assert_simulate_fails(
        "[simulation.endless]\ncells = [4, 4000, 4]\n",
        None,
        &["bad.toml:2:", "simulation.endless.cells"],
    );
}

#[test]
fn malformed_toml_names_file_and_line() {
    assert_simulate_fails(
        "name = \"x\"\n[physics\nparcels = 3\n",
        None,
        &["bad.toml:2:"],
    );
}

#[test]
fn unknown_key_names_file_line_and_key() {
    assert_simulate_fails(
        "[physics]\nparcels = 3\nradiuss_m = 5\n",
        None,
        &["bad.toml:3:", "radiuss_m"],
    );
}

#[test]
fn negative_radius_names_key() {
    assert_simulate_fails(
        "[physics]\nradius_m = -300\n",
        None,
        &["bad.toml:2", "physics.radius_m", "-300"],
    );
}

/// A value past a key's upper bound gets an error that states the whole
/// range, not "expected > 0", which 1e6 (exposure) and 2e5 m (a parcel's
/// radius) both are.
#[test]
fn out_of_range_errors_state_the_range() {
    assert_simulate_fails(
        "[physics]\nradius_m = 200000\n",
        None,
        &["bad.toml:2", "physics.radius_m", "200000", "1e-3..=1e5 m"],
    );
    assert_simulate_fails(
        "[physics.recycling]\nmax_age_s = 1e10\n",
        None,
        &["bad.toml:2", "physics.recycling.max_age_s", "1e-3..=1e9 s"],
    );
    let dir = tempfile::tempdir().unwrap();
    for (key, value, range) in [
        ("exposure", "1e6", "0.001..=1000"),
        ("extinction_per_m", "1e-7", "1e-6..=10 1/m"),
        ("max_distance_m", "1e8", "1..=1e7 m"),
        ("haze_distance_m", "0.5", "1..=1e7 m"),
        // A scale of 0 would divide by zero in the density (NaN pixels
        // in release builds).
        ("detail_scale_m", "0", "1..=1e5 m"),
        ("detail_strength", "2", "0..=1"),
    ] {
        let p = dir.path().join("s.toml");
        std::fs::write(&p, format!("[render]\n{key} = {value}\n")).unwrap();
        let o = cumulus(&["scene", "check", p.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(1), "{key}");
        let e = stderr(&o);
        assert!(
            e.contains(&format!("s.toml:2: `render.{key}`")) && e.contains(range),
            "{key}: {e}"
        );
    }
}

#[test]
fn nan_field_is_rejected() {
    assert_simulate_fails(
        "[physics]\ndt_s = nan\n",
        None,
        &["bad.toml:2", "physics.dt_s"],
    );
}

#[test]
fn unsorted_sounding_names_line() {
    let s = "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,20,15\n900,,12,8\n800,,11,7\n";
    assert_simulate_fails(
        "[atmosphere]\nsounding = \"snd.csv\"\n",
        Some(s),
        &["snd.csv:4:", "strictly increasing"],
    );
}

#[test]
fn non_numeric_sounding_names_line_and_column() {
    let s = "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,20,15\n900,,twelve,8\n";
    assert_simulate_fails(
        "[atmosphere]\nsounding = \"snd.csv\"\n",
        Some(s),
        &["snd.csv:3:", "temperature_C", "twelve"],
    );
}

#[test]
fn missing_sounding_file_is_named() {
    assert_simulate_fails(
        "[atmosphere]\nsounding = \"nowhere.csv\"\n",
        None,
        &["nowhere.csv", "cannot read sounding"],
    );
}

#[test]
fn missing_scene_file_is_named() {
    let o = cumulus(&[
        "simulate",
        "--scene",
        "/no/such/scene.toml",
        "--out",
        "/tmp/never.csv",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("/no/such/scene.toml"), "{}", stderr(&o));
}

#[test]
fn bad_flag_value_is_an_error_after_overrides() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c.csv");
    let scene = root().join("scenes/bomex.toml");
    let o = cumulus(&[
        "simulate",
        "--scene",
        scene.to_str().unwrap(),
        "--dt-s",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("physics.dt_s"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn simulate_writes_the_fig5_columns_for_every_parcel() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("curves.csv");
    let scene = root().join("scenes/bomex.toml");
    let o = cumulus(&[
        "simulate",
        "--scene",
        scene.to_str().unwrap(),
        "--duration-s",
        "1200",
        "--every-s",
        "600",
        "--parcels",
        "5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut r = csv::Reader::from_path(&out).unwrap();
    let header = r.headers().unwrap().clone();
    for col in [
        "t_s",
        "id",
        "x_m",
        "y_m",
        "z_m",
        "w_mps",
        "theta_v_K",
        "theta_v_env_K",
        "T_K",
        "qv_gkg",
        "qc_gkg",
        "qt_gkg",
        "buoyancy_mps2",
        "condensed_fraction",
        "fill",
    ] {
        assert!(header.iter().any(|h| h == col), "missing column {col}");
    }
    let rows: Vec<_> = r.records().map(|x| x.unwrap()).collect();
    // t = 0, 600, 1200: three output steps of five parcels.
    assert_eq!(rows.len(), 15);
    for row in &rows {
        for f in row.iter() {
            assert!(
                f.parse::<f64>().map(f64::is_finite).unwrap_or(false),
                "non-numeric field {f}"
            );
        }
    }
}

#[test]
fn profile_prints_lcl_and_writes_one_row_per_level() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p.csv");
    let snd = root().join("scenes/bomex_sounding.csv");
    let o = cumulus(&[
        "profile",
        "--sounding",
        snd.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let z: f64 = stdout
        .lines()
        .find_map(|l| l.strip_prefix("lcl_height_m="))
        .expect("lcl_height_m line")
        .parse()
        .unwrap();
    // MetPy: 576.0 m (tests/reference/lcl.csv).
    assert!((z - 576.0).abs() < 10.0, "{z}");
    assert!(stdout.contains("lcl_pressure_hPa=") && stdout.contains("lcl_temperature_K="));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with(
        "height_m,pressure_hPa,env_T_K,parcel_T_K,parcel_qv_gkg,parcel_qc_gkg,buoyancy_mps2\n"
    ));
    let levels = std::fs::read_to_string(&snd)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .count()
        - 1;
    assert_eq!(text.lines().count() - 1, levels);
}

/// Printing into a pipe whose reader is gone ends the run quietly, as Unix
/// tools do (`println!` would panic: "failed printing to stdout: Broken pipe").
#[cfg(unix)]
#[test]
fn a_closed_pipe_on_stdout_ends_the_run_without_a_panic() {
    use std::process::Stdio;
    let scene = root().join("scenes/fair_weather.toml");
    let mut child = Command::new(env!("CARGO_BIN_EXE_cumulus"))
        .args(["scene", "check", scene.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("runs");
    // The reader goes before the scene is read and checked.
    drop(child.stdout.take());
    let o = child.wait_with_output().expect("waits");
    let err = stderr(&o);
    assert!(!err.contains("panicked"), "{err}");
    assert_ne!(o.status.code(), Some(101), "{err}");
}

/// `--out /dev/stdout` with the output redirected into a log appends to
/// the log: a temporary file renamed over it would replace the log and
/// what the run had printed into it.
#[cfg(unix)]
#[test]
fn out_to_dev_stdout_appends_to_a_redirected_log() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("log.txt");
    std::fs::write(&log, "kept\n").unwrap();
    let file = std::fs::OpenOptions::new().append(true).open(&log).unwrap();
    let snd = root().join("scenes/bomex_sounding.csv");
    let o = Command::new(env!("CARGO_BIN_EXE_cumulus"))
        .args([
            "profile",
            "--sounding",
            snd.to_str().unwrap(),
            "--out",
            "/dev/stdout",
        ])
        .stdout(file)
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&log).unwrap();
    assert!(text.starts_with("kept\nlcl_pressure_hPa="), "{text}");
    assert!(text.contains("\nheight_m,pressure_hPa,"), "{text}");
    assert!(std::fs::metadata(&log).unwrap().is_file());
}

/// Where there is no LCL the three lines say so alike: dry air printed an
/// LCL of 0 hPa and 0 K beside a height of "none".
#[test]
fn profile_says_none_where_there_is_no_lcl() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let lines = |p: &std::path::Path| {
        let o = cumulus(&["profile", "--sounding", p.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let dry = write(
        "dry.csv",
        "height_m,pressure_hPa,temperature_C,relative_humidity_pct\n0,1000,25,0\n500,950,20,0\n",
    );
    let out = lines(&dry);
    for key in ["lcl_pressure_hPa", "lcl_temperature_K", "lcl_height_m"] {
        assert!(out.contains(&format!("{key}=none (")), "{out}");
    }
    assert!(out.contains("never saturates"), "{out}");
    // Moist air whose LCL lies above a short sounding: its pressure and
    // temperature (as MetPy's `lcl` gives them), no height, and why.
    let short = write(
        "short.csv",
        "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,25,15\n100,988.5,24,14.8\n",
    );
    let out = lines(&short);
    let p: f64 = out
        .lines()
        .find_map(|l| l.strip_prefix("lcl_pressure_hPa="))
        .expect("pressure")
        .parse()
        .expect("a number");
    assert!((850.0..950.0).contains(&p), "{out}");
    assert!(
        out.contains(
            "lcl_height_m=none (the LCL lies above the sounding's top, 988.5 hPa at 100 m)"
        ),
        "{out}"
    );
}

#[test]
fn scene_check_accepts_shipped_scenes_and_rejects_bad_ones() {
    for s in ["bomex", "fair_weather", "strong_inversion"] {
        let o = cumulus(&[
            "scene",
            "check",
            root().join(format!("scenes/{s}.toml")).to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{s}: {}", stderr(&o));
    }
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.toml");
    std::fs::write(&p, "[physics.sph]\nsound_speed_mps = -1\n").unwrap();
    let o = cumulus(&["scene", "check", p.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("s.toml:2: `physics.sph.sound_speed_mps`"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn sounding_flag_replaces_the_scene_atmosphere() {
    let dir = tempfile::tempdir().unwrap();
    let snd = dir.path().join("good.csv");
    std::fs::write(&snd, GOOD_SOUNDING).unwrap();
    let out = dir.path().join("c.csv");
    let scene = root().join("scenes/fair_weather.toml");
    let o = cumulus(&[
        "simulate",
        "--scene",
        scene.to_str().unwrap(),
        "--sounding",
        snd.to_str().unwrap(),
        "--duration-s",
        "60",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The environment comes from the 3-level sounding: θ_v,env at the
    // release height (50 m) is that of 20 °C at ~994 hPa with 15 °C dewpoint.
    let mut r = csv::Reader::from_path(&out).unwrap();
    let h = r.headers().unwrap().clone();
    let col = h.iter().position(|c| c == "theta_v_env_K").unwrap();
    let row = r.records().next().unwrap().unwrap();
    let thv: f64 = row[col].parse().unwrap();
    assert!((thv - 295.2).abs() < 1.0, "θ_v,env {thv}");
}

#[test]
fn render_writes_a_deterministic_sky_png_and_refuses_missing_backends() {
    let dir = tempfile::tempdir().unwrap();
    let scene = root().join("scenes/fair_weather.toml");
    let run = |name: &str| {
        let out = dir.path().join(name);
        let o = cumulus(&[
            "render",
            "--light-photons",
            "16",
            "--scene",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--width",
            "96",
            "--height",
            "72",
            "--backend",
            "cpu",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("backend: cpu"),
            "says which backend it used"
        );
        std::fs::read(out).unwrap()
    };
    let (a, b) = (run("a.png"), run("b.png"));
    assert_eq!(a, b, "same scene, same bytes");
    let img = image::load_from_memory(&a).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (96, 72));
    let upper = img.enumerate_pixels().filter(|(_, y, _)| *y < 24);
    let (mut sky, mut cloud) = (0, 0);
    for (_, _, p) in upper {
        let [r, _, b] = p.0;
        if b as f32 > 1.25 * r as f32 {
            sky += 1
        } else if r > 120 {
            cloud += 1
        }
    }
    assert!(sky > 100, "sky pixels: {sky}");
    let all_cloud = img
        .pixels()
        .filter(|p| p.0[2] as f32 <= 1.15 * p.0[0] as f32 && p.0[0] > 120)
        .count();
    assert!(
        all_cloud > 20,
        "cloud pixels: {all_cloud} (upper third: {cloud})"
    );

    // No adapter (WGPU_BACKEND names a backend this platform lacks): gpu
    // is a clear error that says how to get one; auto falls back to the CPU
    // and says why.
    let out = dir.path().join("gpu.png");
    let args = [
        "render",
        "--light-photons",
        "16",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--width",
        "32",
        "--height",
        "24",
    ];
    let no_adapter = |backend: &str| {
        let mut a = args.to_vec();
        a.extend(["--backend", backend]);
        Command::new(env!("CARGO_BIN_EXE_cumulus"))
            .args(&a)
            .env("WGPU_BACKEND", if cfg!(windows) { "metal" } else { "dx12" })
            .output()
            .expect("binary runs")
    };
    let o = no_adapter("gpu");
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("no GPU adapter") && stderr(&o).contains("--backend cpu"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
    let o = no_adapter("auto");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("backend: cpu (no GPU adapter"),
        "{}",
        stderr(&o)
    );
    std::fs::remove_file(&out).unwrap();
    assert!(!out.exists());
    let o = cumulus(&[
        "render",
        "--light-photons",
        "16",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--steps",
        "0",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("render.steps"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn render_on_the_gpu_writes_the_png_and_times_frames() {
    if common::gpu().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("gpu.png");
    let scene = root().join("scenes/fair_weather.toml");
    let o = cumulus(&[
        "render",
        "--light-photons",
        "16",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--width",
        "40",
        "--height",
        "30",
        "--backend",
        "gpu",
        "--frames",
        "3",
        "--time-frames",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("backend: gpu"), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("frame 40x30: median"), "{stdout}");
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (40, 30));
}

/// `--dt-s 7 --duration-s 60` simulated 63 s (nine whole frames); it must
/// simulate 60 s, the last frame 4 s long, and say so.
#[test]
fn a_step_that_does_not_divide_the_duration_simulates_exactly_the_duration() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("curves.csv");
    let scene = root().join("scenes/fair_weather.toml");
    let o = cumulus(&[
        "simulate",
        "--scene",
        scene.to_str().unwrap(),
        "--parcels",
        "3",
        "--dt-s",
        "7",
        "--duration-s",
        "60",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("simulated 60 s in 9 frames (8 of 7 s, the last of 4 s)"),
        "{err}"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    let last_t: f64 = text
        .lines()
        .last()
        .and_then(|l| l.split(',').next())
        .and_then(|t| t.parse().ok())
        .expect("a t_s column");
    assert!((last_t - 60.0).abs() < 1e-9, "last row at {last_t} s");
}

#[test]
fn stats_writes_the_field_statistics() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("stats");
    let scene = root().join("scenes/fair_weather.toml");
    let o = cumulus(&[
        "stats",
        "--scene",
        scene.to_str().unwrap(),
        "--resolution",
        "96",
        "--levels",
        "12",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("cloud_fraction="), "{stdout}");
    for f in [
        "clouds.csv",
        "size_density.csv",
        "cloud_fraction_profile.csv",
        "stats.json",
        "area_perimeter.png",
        "size_density.png",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("stats.json")).unwrap()).unwrap();
    let cf = json["cloud_fraction"].as_f64().expect("cloud_fraction");
    assert!(cf > 0.0 && cf < 1.0, "{cf}");
    assert_eq!(json["profile"].as_array().map(Vec::len), Some(12));
}

#[test]
fn stats_rejects_a_bad_resolution_before_simulating() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("stats");
    let scene = root().join("scenes/fair_weather.toml");
    let o = cumulus(&[
        "stats",
        "--scene",
        scene.to_str().unwrap(),
        "--resolution",
        "5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--resolution is 5"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn render_refuses_a_missing_folder_or_a_directory_before_simulating() {
    let dir = tempfile::tempdir().unwrap();
    let scene = root().join("scenes/fair_weather.toml");
    let missing = dir.path().join("no/such/folder/sky.png");
    for (out, says) in [
        (missing.as_path(), "does not exist"),
        (dir.path(), "is a directory"),
    ] {
        let o = cumulus(&[
            "render",
            "--light-photons",
            "16",
            "--scene",
            scene.to_str().unwrap(),
            "--backend",
            "cpu",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(1));
        let err = stderr(&o);
        assert!(err.contains(says), "{err}");
        // Refused up front: nothing was simulated or rendered.
        assert!(
            !err.contains("backend:") && !err.contains("rendered"),
            "{err}"
        );
    }
}

/// A successful run prints no "error" (not even the Wayland probe's
/// complaint about an unset XDG_RUNTIME_DIR, which the test provokes) and
/// names its backend once.
#[test]
fn a_successful_render_prints_no_error_and_one_backend_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sky.png");
    let scene = root().join("scenes/fair_weather.toml");
    let o = Command::new(env!("CARGO_BIN_EXE_cumulus"))
        .args([
            "render",
            "--light-photons",
            "16",
            "--scene",
            scene.to_str().unwrap(),
            "--backend",
            "auto",
        ])
        .args(["--width", "32", "--height", "24", "--time-s", "60", "--out"])
        .arg(&out)
        .env_remove("XDG_RUNTIME_DIR")
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(!err.to_lowercase().contains("error"), "{err}");
    assert_eq!(err.matches("backend:").count(), 1, "{err}");
}

/// Every command's `--help` ends with an example, and `render --help` says
/// when `--out` may be left out.
#[test]
fn every_help_shows_an_example() {
    for cmd in [
        &["simulate"][..],
        &["profile"],
        &["convergence"],
        &["render"],
        &["bench"],
        &["stats"],
        &["export"],
        &["scene", "check"],
    ] {
        let mut args = cmd.to_vec();
        args.push("--help");
        let o = cumulus(&args);
        assert!(o.status.success(), "{cmd:?}");
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(text.contains("Example:\n  cumulus "), "{cmd:?}:\n{text}");
    }
    let o = cumulus(&["render", "--help"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("unless --quality-report"));
}

/// Errors say where the bad value came from, once.
#[test]
fn errors_name_where_the_value_came_from() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    // A missing scene: the OS error once.
    let o = cumulus(&["scene", "check", "nothere.toml"]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        stderr(&o).matches("No such file").count(),
        1,
        "{}",
        stderr(&o)
    );
    // A missing sounding: the scene file, line and key that name it.
    let s = write(
        "s1.toml",
        "name = \"x\"\n[atmosphere]\nsounding = \"missing.csv\"\n",
    );
    let o = cumulus(&["scene", "check", s.to_str().unwrap()]);
    let err = stderr(&o);
    assert!(
        err.contains("s1.toml:3: `atmosphere.sounding`: names") && err.contains("missing.csv"),
        "{err}"
    );
    // A flag's value: the flag, not a line of the scene.
    let s = write("s2.toml", "[physics]\nparcels = 12\n");
    let out = dir.path().join("c.csv");
    let o = cumulus(&[
        "simulate",
        "--scene",
        s.to_str().unwrap(),
        "--parcels",
        "10000000",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert!(
        err.contains("--parcels is 10000000, expected 0..=200000"),
        "{err}"
    );
    assert!(!err.contains("s2.toml:2"), "{err}");
    // A TOML type error: the key.
    let s = write("s3.toml", "[physics]\nparcels = \"many\"\n");
    let o = cumulus(&["scene", "check", s.to_str().unwrap()]);
    assert!(
        stderr(&o).contains("s3.toml:2:11: `physics.parcels`: invalid type"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn odd_values_get_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.png");
    let scene = root().join("scenes/fair_weather.toml");
    let sc = scene.to_str().unwrap();
    let o = cumulus(&[
        "render",
        "--light-photons",
        "16",
        "--scene",
        sc,
        "--width",
        "-5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("invalid value '-5' for '--width"),
        "{}",
        stderr(&o)
    );
    // A camera so far away that nothing could be drawn.
    let far = dir.path().join("far.toml");
    std::fs::write(&far, "[render]\ncamera_position_m = [0, 1e9, 0]\n").unwrap();
    let o = cumulus(&[
        "render",
        "--light-photons",
        "16",
        "--scene",
        far.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("`render.camera_position_m`"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
    // A duration with no bound.
    let csv = dir.path().join("c.csv");
    let o = cumulus(&[
        "simulate",
        "--scene",
        sc,
        "--duration-s",
        "1e15",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("--duration-s is 1000000000000000"),
        "{}",
        stderr(&o)
    );
    // Off a terminal, a run reports its progress in plain lines.
    let o = cumulus(&[
        "simulate",
        "--scene",
        sc,
        "--parcels",
        "3",
        "--duration-s",
        "600",
        "--out",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("simulating: 50 % (60 of 120)") && err.contains("simulating: 100 %"),
        "{err}"
    );
}

/// SIGINT and SIGTERM remove the run's temporary file (left, it would
/// stay, up to 50 MB, as `.NAME.PID.tmp`); a later run into the same folder
/// removes the ones that runs which are gone (SIGKILL) left.
#[test]
fn interrupted_runs_leave_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = root().join("scenes/fair_weather.toml");
    let out = dir.path().join("curves.csv");
    let stale = dir.path().join(format!(".curves.csv.{}.tmp", u32::MAX));
    std::fs::write(&stale, "left by a killed run").unwrap();
    for signal in ["-INT", "-TERM"] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_cumulus"))
            .args(["simulate", "--scene", scene.to_str().unwrap()])
            .args(["--parcels", "400", "--duration-s", "1e6", "--out"])
            .arg(&out)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("runs");
        let tmp = dir.path().join(format!(".curves.csv.{}.tmp", child.id()));
        let start = std::time::Instant::now();
        while !tmp.exists() {
            assert!(
                start.elapsed().as_secs() < 120,
                "no temporary file appeared"
            );
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        if std::path::Path::new("/proc/self").exists() {
            assert!(
                !stale.exists(),
                "the stale file of a gone process was not removed"
            );
        }
        let kill = Command::new("kill")
            .args([signal, &child.id().to_string()])
            .status()
            .expect("kill runs");
        assert!(kill.success());
        let status = child.wait().expect("exits");
        assert_eq!(status.code(), Some(130), "{signal}");
        assert!(!tmp.exists(), "{signal}: {} left behind", tmp.display());
        assert!(!out.exists());
    }
}

/// Run outside the repository, the default scene paths (`bench`'s
/// `scenes/fair_weather.toml`, the sky demo's `scenes/evening.toml`) fall
/// back to the scenes built into the binary, and say so.
#[test]
fn shipped_scenes_work_outside_the_repository() {
    let dir = tempfile::tempdir().unwrap();
    let render = |scene: &str| {
        Command::new(env!("CARGO_BIN_EXE_cumulus"))
            .args([
                "render",
                "--light-photons",
                "16",
                "--scene",
                scene,
                "--backend",
                "cpu",
                "--out",
                "sky.png",
            ])
            .args(["--width", "16", "--height", "12", "--time-s", "10"])
            .current_dir(dir.path())
            .output()
            .expect("runs")
    };
    let o = render("scenes/fair_weather.toml");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("using the built-in copy"),
        "{}",
        stderr(&o)
    );
    assert!(dir.path().join("sky.png").is_file());
    // Not a shipped scene's name: the usual error.
    let o = render("scenes/mine.toml");
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("cannot read scene"), "{}", stderr(&o));
    // `scene check` reads a scene as the other commands do (it said "No
    // such file" for the name `render` takes).
    let o = Command::new(env!("CARGO_BIN_EXE_cumulus"))
        .args(["scene", "check", "scenes/fair_weather.toml"])
        .current_dir(dir.path())
        .output()
        .expect("runs");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("using the built-in copy"),
        "{}",
        stderr(&o)
    );
    assert!(String::from_utf8_lossy(&o.stdout).contains(": ok ("));
}

#[test]
fn a_bad_ground_names_its_key() {
    assert_simulate_fails(
        "[render.ground]\nsurface = \"lake\"\n",
        None,
        &["bad.toml", "lake", "land", "sea"],
    );
    assert_simulate_fails(
        "[render.ground]\nwind_speed_mps = 50.0\n",
        None,
        &["bad.toml", "render.ground.wind_speed_mps", "0..=30"],
    );
    assert_simulate_fails(
        "[render.ground]\nland = \"forest\"\n",
        None,
        &["bad.toml", "forest", "fields", "plain"],
    );
}

#[test]
fn an_endless_database_is_written_once_then_read_and_rebuilt_for_new_settings() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = |coverage: f32| {
        format!(
            "[simulation]\nmethod = \"endless\"\n\n[simulation.endless]\nvolumes = 3\ninterval_s = 20.0\n\
             cells = [16, 4, 16]\ndatabase = \"sky.volumes\"\n\n[render]\ntime_s = 300.0\ncoverage = {coverage}\n"
        )
    };
    let path = dir.path().join("e.toml");
    let render = |out: &str| {
        let o = cumulus(&[
            "render",
            "--light-photons",
            "16",
            "--scene",
            path.to_str().unwrap(),
            "--backend",
            "cpu",
            "--width",
            "32",
            "--height",
            "24",
            "--out",
            dir.path().join(out).to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
    };
    std::fs::write(&path, scene(0.6)).unwrap();
    assert!(
        render("a.png").contains("wrote"),
        "first run builds and writes"
    );
    let second = render("b.png");
    assert!(second.contains("read from"), "{second}");
    assert_eq!(
        std::fs::read(dir.path().join("a.png")).unwrap(),
        std::fs::read(dir.path().join("b.png")).unwrap(),
        "the read database draws the same picture"
    );
    std::fs::write(&path, scene(0.5)).unwrap();
    let third = render("c.png");
    assert!(
        third.contains("built") && third.contains("wrote"),
        "{third}"
    );
    // A file that is not a database is an error, never overwritten.
    std::fs::write(dir.path().join("sky.volumes"), "not volumes").unwrap();
    let o = cumulus(&[
        "render",
        "--light-photons",
        "16",
        "--scene",
        path.to_str().unwrap(),
        "--backend",
        "cpu",
        "--out",
        dir.path().join("d.png").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("not a cumulus volume database"),
        "{}",
        stderr(&o)
    );
    assert_eq!(
        std::fs::read(dir.path().join("sky.volumes")).unwrap(),
        b"not volumes"
    );
}

/// `render`s `scene` into `out` as a 48x36 CPU picture, with `extra`
/// flags; asserts success and reads the picture back.
fn render_small_cpu(
    scene: &std::path::Path,
    out: &std::path::Path,
    extra: &[&str],
) -> image::RgbImage {
    let mut args = vec![
        "render",
        "--light-photons",
        "16",
        "--scene",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--width",
        "48",
        "--height",
        "36",
        "--backend",
        "cpu",
    ];
    args.extend_from_slice(extra);
    let o = cumulus(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    image::open(out).unwrap().to_rgb8()
}

/// `render --single-scattering`: the sun's once-scattered light alone, so
/// where no cloud is the picture is black (the sky behind is left out);
/// refused with a clear error for what it does not cover (the spheroid
/// renderer here), before anything is simulated or written.
#[test]
fn render_single_scattering_leaves_the_sky_out_and_refuses_other_renderers() {
    let dir = tempfile::tempdir().unwrap();
    let scene = root().join("scenes/fair_weather.toml");
    let render = |name: &str, single: bool| {
        let extra: &[&str] = if single {
            &["--single-scattering"]
        } else {
            &[]
        };
        render_small_cpu(&scene, &dir.path().join(name), extra)
    };
    let black = |img: &image::RgbImage| img.pixels().filter(|p| p.0 == [0, 0, 0]).count();
    let (full, single) = (render("full.png", false), render("single.png", true));
    assert_eq!(black(&full), 0, "the full picture has its sky");
    assert!(
        black(&single) > 200,
        "the sky is left out: {} black pixels of {}",
        black(&single),
        48 * 36
    );
    assert!(
        black(&single) < 48 * 36,
        "the clouds' once-scattered light is there"
    );

    let out = dir.path().join("spheroids.png");
    let o = cumulus(&[
        "render",
        "--light-photons",
        "16",
        "--scene",
        root().join("scenes/spheroids.toml").to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--backend",
        "cpu",
        "--single-scattering",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("--single-scattering") && stderr(&o).contains("cloud_map"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}

/// Under a sun below the horizon the picture is exposed for the twilight
/// (`render.auto_exposure`, on by default): the sky above the clouds is a
/// dusk blue, not black. With it off, at the day's exposure, it is
/// black.
#[test]
fn render_exposes_a_twilight_sky() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("scenes/fair_weather.toml")).unwrap();
    let twilight = text.replace("sun_elevation_deg = 28.0", "sun_elevation_deg = -6.0");
    assert_ne!(twilight, text, "the shipped scene's sun moved");
    let sky = |extra: &str, name: &str| {
        let scene = dir.path().join(format!("{name}.toml"));
        let with = twilight.replacen("[render]\n", &format!("[render]\n{extra}"), 1);
        std::fs::write(&scene, with).unwrap();
        let img = render_small_cpu(
            &scene,
            &dir.path().join(format!("{name}.png")),
            &["--time-s", "600"],
        );
        // The top rows: sky above the clouds.
        let mut sum = [0.0f64; 3];
        let top: Vec<_> = img.enumerate_pixels().filter(|(_, y, _)| *y < 8).collect();
        for (_, _, p) in &top {
            for (s, v) in sum.iter_mut().zip(p.0) {
                *s += v as f64 / top.len() as f64;
            }
        }
        sum
    };
    let metered = sky("", "metered");
    let fixed = sky("auto_exposure = false\n", "fixed");
    assert!(
        fixed.iter().all(|&c| c < 3.0),
        "at the day's exposure: {fixed:?}"
    );
    // Measured: about (18, 12, 32) of 255; at the day's exposure (0, 0, 0).
    assert!(metered[2] > 20.0, "metered: {metered:?}");
    assert!(
        metered[2] > metered[0] && metered[2] > metered[1],
        "a dusk blue: {metered:?}"
    );
}

/// lavapipe ends a shader's loops after 65,535 iterations, which the
/// cloud pass's march passes at 1024 steps or more: `render` says so
/// there, and not on hardware or at fewer steps.
#[test]
fn lavapipe_at_a_thousand_steps_is_warned_about() {
    let Some(ctx) = common::gpu() else { return };
    let dir = tempfile::tempdir().expect("dir");
    let out = dir.path().join("s.png");
    let scene = root().join("scenes/fair_weather.toml");
    let run = |steps: &str| {
        let o = cumulus(&[
            "render",
            "--light-photons",
            "16",
            "--scene",
            scene.to_str().expect("utf-8"),
            "--out",
            out.to_str().expect("utf-8"),
            "--backend",
            "gpu",
            "--width",
            "8",
            "--height",
            "6",
            "--frames",
            "1",
            "--steps",
            steps,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o).contains("on lavapipe, which ends a shader's loops after 65535 iterations")
    };
    assert_eq!(run("1024"), ctx.is_llvmpipe());
    assert!(!run("512"));
}
