//! The `cumulus` binary from the outside: outputs, and bad input giving a
//! clear error (file, line, key), a non-zero exit, no panic and no output
//! file.

mod common;

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary with `args`, not yet run.
fn cumulus(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_cumulus"));
    c.args(args);
    c
}

/// `cumulus COMMAND --scene SCENE --out OUT`, then `extra`.
fn on_scene(
    command: &str,
    scene: impl AsRef<OsStr>,
    out: impl AsRef<OsStr>,
    extra: &[&str],
) -> Command {
    let mut c = cumulus(&[command, "--scene"]);
    c.arg(scene).arg("--out").arg(out).args(extra);
    c
}

/// `render` with 16 light photons (quick), then `extra`.
fn render(scene: impl AsRef<OsStr>, out: impl AsRef<OsStr>, extra: &[&str]) -> Command {
    let mut c = on_scene("render", scene, out, &["--light-photons", "16"]);
    c.args(extra);
    c
}

/// `cumulus simulate --scene SCENE --out OUT`, then `extra`.
fn simulate(scene: impl AsRef<OsStr>, out: impl AsRef<OsStr>, extra: &[&str]) -> Command {
    on_scene("simulate", scene, out, extra)
}

/// A file shipped under `scenes/`.
fn shipped(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn path(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 path")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Writes `text` to `name` in `dir`; returns its path.
fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write file");
    p
}

/// The names in `dir`, sorted.
fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .expect("read dir")
        .map(|e| {
            e.expect("dir entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    names.sort();
    names
}

/// Runs `cmd`, which must succeed.
fn succeeds(cmd: &mut Command) -> Output {
    succeeds_saying(cmd, &[])
}

/// Runs `cmd`, which must succeed with every needle in its stderr.
fn succeeds_saying(cmd: &mut Command, needles: &[&str]) -> Output {
    let o = cmd.output().expect("binary runs");
    let err = stderr(&o);
    assert!(o.status.success(), "{cmd:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "{cmd:?}: stderr lacks `{n}`: {err}");
    }
    o
}

/// A failed run `run` (named in the messages) must have exited with `code`
/// (a clean error, not a panic's 101), without "panicked", with every
/// needle in its stderr, which it returns.
fn assert_failed(run: &str, o: &Output, code: i32, needles: &[&str]) -> String {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(code), "{run}: {err}");
    assert!(!err.contains("panicked"), "{run}: {err}");
    for n in needles {
        assert!(err.contains(n), "{run}: stderr lacks `{n}`: {err}");
    }
    err
}

/// Runs `cmd`, which must fail as `assert_failed` says; returns stderr.
fn fails(cmd: &mut Command, code: i32, needles: &[&str]) -> String {
    let o = cmd.output().expect("binary runs");
    assert_failed(&format!("{cmd:?}"), &o, code, needles)
}

/// Runs `simulate` on `scene` (written as `bad.toml`, with `sounding`
/// beside it as `snd.csv` where given); asserts a clean failure naming
/// every needle, and no output or temporary file left.
fn assert_simulate_fails(scene: &str, sounding: Option<&str>, needles: &[&str]) {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene_path = write(dir.path(), "bad.toml", scene);
    let mut kept = vec!["bad.toml"];
    if let Some(s) = sounding {
        write(dir.path(), "snd.csv", s);
        kept.push("snd.csv");
    }
    let out = dir.path().join("curves.csv");
    let o = simulate(&scene_path, &out, &["--duration-s", "10"])
        .output()
        .expect("binary runs");
    let run = format!("simulate on {scene:?} with sounding {sounding:?}");
    assert_failed(&run, &o, 1, needles);
    assert_eq!(names_in(dir.path()), kept, "{run}: no output or temp file");
}

/// `assert_simulate_fails` for each (scene, needles), without a sounding.
fn simulate_refuses(cases: &[(&str, &[&str])]) {
    for (scene, needles) in cases {
        assert_simulate_fails(scene, None, needles);
    }
}

/// Writes `text` to `name` in `dir`; `scene check` on it must fail cleanly
/// (exit 1) naming every needle.
fn assert_scene_check_fails(dir: &Path, name: &str, text: &str, needles: &[&str]) {
    let o = cumulus(&["scene", "check", path(&write(dir, name, text))])
        .output()
        .expect("binary runs");
    assert_failed(&format!("scene check on {text:?}"), &o, 1, needles);
}

#[test]
fn simulate_refuses_the_automaton_and_bad_methods_clearly() {
    simulate_refuses(&[
        (
            "[simulation]\nmethod = \"automaton\"\n",
            &["bad.toml", "automaton", "no parcels"],
        ),
        (
            "[simulation]\nmethod = \"voxels\"\n",
            &["bad.toml:2:", "parcels", "automaton", "endless"],
        ),
        (
            "[simulation.endless]\ncells = [4, 4000, 4]\n",
            &["bad.toml:2:", "simulation.endless.cells"],
        ),
    ]);
}

/// Malformed TOML names the file and line; an unknown, negative or NaN
/// value also its key.
#[test]
fn bad_scene_values_name_file_line_and_key() {
    simulate_refuses(&[
        ("name = \"x\"\n[physics\nparcels = 3\n", &["bad.toml:2:"]),
        (
            "[physics]\nparcels = 3\nradiuss_m = 5\n",
            &["bad.toml:3:", "radiuss_m"],
        ),
        (
            "[physics]\nradius_m = -300\n",
            &["bad.toml:2", "physics.radius_m", "-300"],
        ),
        ("[physics]\ndt_s = nan\n", &["bad.toml:2", "physics.dt_s"]),
    ]);
}

/// A value past a key's upper bound gets an error that states the whole
/// range, not "expected > 0", which 1e6 (exposure) and 2e5 m (a parcel's
/// radius) both are.
#[test]
fn out_of_range_errors_state_the_range() {
    simulate_refuses(&[
        (
            "[physics]\nradius_m = 200000\n",
            &["bad.toml:2", "physics.radius_m", "200000", "1e-3..=1e5 m"],
        ),
        (
            "[physics.recycling]\nmax_age_s = 1e10\n",
            &["bad.toml:2", "physics.recycling.max_age_s", "1e-3..=1e9 s"],
        ),
    ]);
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
        assert_scene_check_fails(
            dir.path(),
            "s.toml",
            &format!("[render]\n{key} = {value}\n"),
            &[&format!("s.toml:2: `render.{key}`"), range],
        );
    }
}

/// A bad sounding names its file and line (and column); a missing one its
/// file.
#[test]
fn bad_soundings_name_file_line_and_column() {
    let scene = "[atmosphere]\nsounding = \"snd.csv\"\n";
    for (sounding, needles) in [
        (
            "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,20,15\n900,,12,8\n800,,11,7\n",
            &["snd.csv:4:", "strictly increasing"][..],
        ),
        (
            "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,20,15\n900,,twelve,8\n",
            &["snd.csv:3:", "temperature_C", "twelve"],
        ),
    ] {
        assert_simulate_fails(scene, Some(sounding), needles);
    }
    assert_simulate_fails(
        "[atmosphere]\nsounding = \"nowhere.csv\"\n",
        None,
        &["nowhere.csv", "cannot read sounding"],
    );
}

#[test]
fn a_bad_ground_names_its_key() {
    simulate_refuses(&[
        (
            "[render.ground]\nsurface = \"lake\"\n",
            &["bad.toml", "lake", "land", "sea"],
        ),
        (
            "[render.ground]\nwind_speed_mps = 50.0\n",
            &["bad.toml", "render.ground.wind_speed_mps", "0..=30"],
        ),
        (
            "[render.ground]\nland = \"forest\"\n",
            &["bad.toml", "forest", "fields", "plain"],
        ),
    ]);
}

#[test]
fn missing_scene_file_is_named() {
    fails(
        &mut simulate("/no/such/scene.toml", "/tmp/never.csv", &[]),
        1,
        &["/no/such/scene.toml"],
    );
}

/// A bad flag or scene value is a clear error (exit 2 from the argument
/// parser, 1 from the checks after it) that names it, and nothing is
/// written.
#[test]
fn odd_values_get_clear_errors_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (fair, bomex) = (shipped("fair_weather.toml"), shipped("bomex.toml"));
    // A camera so far away that nothing could be drawn.
    let far = write(
        dir.path(),
        "far.toml",
        "[render]\ncamera_position_m = [0, 1e9, 0]\n",
    );
    let [csv, png, stats] = ["c.csv", "x.png", "stats"].map(|n| dir.path().join(n));
    for (mut cmd, code, needles) in [
        // A flag's value is checked after it overrides the scene's.
        (
            simulate(&bomex, &csv, &["--dt-s", "0"]),
            1,
            &["physics.dt_s"][..],
        ),
        // A duration with no bound.
        (
            simulate(&fair, &csv, &["--duration-s", "1e15"]),
            1,
            &["--duration-s is 1e15"],
        ),
        (
            render(&fair, &png, &["--width", "-5"]),
            2,
            &["invalid value '-5' for '--width"],
        ),
        (render(&far, &png, &[]), 1, &["`render.camera_position_m`"]),
        (render(&fair, &png, &["--steps", "0"]), 1, &["render.steps"]),
        // Refused before simulating.
        (
            on_scene("stats", &fair, &stats, &["--resolution", "5"]),
            1,
            &["--resolution is 5"],
        ),
    ] {
        fails(&mut cmd, code, needles);
        assert_eq!(names_in(dir.path()), ["far.toml"], "{cmd:?} wrote a file");
    }
}

/// Off a terminal, a run reports its progress in plain lines.
#[test]
fn off_a_terminal_a_run_reports_progress_in_plain_lines() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("c.csv");
    let extra = ["--parcels", "3", "--duration-s", "600"];
    succeeds_saying(
        &mut simulate(shipped("fair_weather.toml"), &csv, &extra),
        &["simulating: 50 % (60 of 120)", "simulating: 100 %"],
    );
    // A CPU still reports each long phase, then each phase's time.
    let png = dir.path().join("sky.png");
    let extra = ["--backend", "cpu", "--width", "32", "--height", "24"];
    succeeds_saying(
        &mut render(shipped("fair_weather.toml"), &png, &extra),
        &[
            "simulating: 100 %",
            "light volume: 50 %",
            "light volume: 100 %",
            "rendering: 50 %",
            "rendering: 100 %",
            " s simulating and ",
            " s for the light volume",
            // The default adaptive still says what it marched and read.
            " marches, ",
            " density reads a pixel)",
        ],
    );
}

#[test]
fn simulate_writes_the_fig5_columns_for_every_parcel() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("curves.csv");
    let extra = ["--duration-s", "1200", "--every-s", "600", "--parcels", "5"];
    succeeds(&mut simulate(shipped("bomex.toml"), &out, &extra));
    let mut r = csv::Reader::from_path(&out).unwrap();
    let header = r.headers().unwrap().clone();
    let columns = "t_s id x_m y_m z_m w_mps theta_v_K theta_v_env_K T_K qv_gkg qc_gkg qt_gkg \
                   buoyancy_mps2 condensed_fraction fill";
    for col in columns.split_whitespace() {
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
    let snd = shipped("bomex_sounding.csv");
    let o = succeeds(&mut cumulus(&[
        "profile",
        "--sounding",
        path(&snd),
        "--out",
        path(&out),
    ]));
    let stdout = stdout(&o);
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
    let scene = shipped("fair_weather.toml");
    let mut child = cumulus(&["scene", "check", path(&scene)])
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
    let log = write(dir.path(), "log.txt", "kept\n");
    let file = std::fs::OpenOptions::new().append(true).open(&log).unwrap();
    let snd = shipped("bomex_sounding.csv");
    let args = ["profile", "--sounding", path(&snd), "--out", "/dev/stdout"];
    succeeds(cumulus(&args).stdout(file));
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
    let profile = |name: &str, sounding: &str| {
        let p = write(dir.path(), name, sounding);
        let args = ["profile", "--sounding", path(&p)];
        stdout(&succeeds(&mut cumulus(&args)))
    };
    let out = profile(
        "dry.csv",
        "height_m,pressure_hPa,temperature_C,relative_humidity_pct\n0,1000,25,0\n500,950,20,0\n",
    );
    for key in ["lcl_pressure_hPa", "lcl_temperature_K", "lcl_height_m"] {
        assert!(out.contains(&format!("{key}=none (")), "{out}");
    }
    assert!(out.contains("never saturates"), "{out}");
    // Moist air whose LCL lies above a short sounding: its pressure and
    // temperature (as MetPy's `lcl` gives them), no height, and why.
    let out = profile(
        "short.csv",
        "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,25,15\n100,988.5,24,14.8\n",
    );
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
    for s in ["bomex.toml", "fair_weather.toml", "strong_inversion.toml"] {
        succeeds(&mut cumulus(&["scene", "check", path(&shipped(s))]));
    }
    let dir = tempfile::tempdir().unwrap();
    assert_scene_check_fails(
        dir.path(),
        "s.toml",
        "[physics.sph]\nsound_speed_mps = -1\n",
        &["s.toml:2: `physics.sph.sound_speed_mps`"],
    );
}

#[test]
fn sounding_flag_replaces_the_scene_atmosphere() {
    let dir = tempfile::tempdir().unwrap();
    let snd = write(
        dir.path(),
        "good.csv",
        "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,20,15\n1000,,12,8\n3000,,0,-5\n",
    );
    // θ_v of the environment at the first parcel's release height (50 m)
    // in the first row, with and without the flag.
    let theta_v_env = |extra: &[&str], name: &str| -> f64 {
        let out = dir.path().join(name);
        succeeds(&mut simulate(shipped("fair_weather.toml"), &out, extra));
        let mut r = csv::Reader::from_path(&out).unwrap();
        let h = r.headers().unwrap().clone();
        let col = h.iter().position(|c| c == "theta_v_env_K").unwrap();
        let z = h.iter().position(|c| c == "z_m").unwrap();
        let row = r.records().next().unwrap().unwrap();
        assert_eq!(row[z].parse::<f64>().unwrap(), 50.0, "released at 50 m");
        row[col].parse().unwrap()
    };
    let with = theta_v_env(
        &["--sounding", path(&snd), "--duration-s", "60"],
        "with.csv",
    );
    let without = theta_v_env(&["--duration-s", "60"], "without.csv");
    // By hand from the 3-level sounding: at 50 m 19.6 °C with a 14.65 °C
    // dewpoint, 994.2 hPa from the hydrostatic fill, so a mixing ratio of
    // 10.6 g/kg and θ_v 295.13 K (Bolton's saturation pressure; the code's
    // Ambaum differs by 0.01 K). The scene's own atmosphere gives 296.1 K.
    assert!(
        (with - 295.13).abs() < 0.05,
        "θ_v,env {with} with --sounding"
    );
    assert!(
        (with - without).abs() > 0.5,
        "--sounding changed nothing: {with} K against the scene's {without} K"
    );
}

#[test]
fn render_writes_a_deterministic_sky_png_and_refuses_missing_backends() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shipped("fair_weather.toml");
    let run = |name: &str| {
        let out = dir.path().join(name);
        let extra = ["--width", "96", "--height", "72", "--backend", "cpu"];
        // It says which backend it used.
        succeeds_saying(&mut render(&scene, &out, &extra), &["backend: cpu"]);
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
    let no_adapter = |backend: &str| {
        let extra = ["--width", "32", "--height", "24", "--backend", backend];
        let mut c = render(&scene, &out, &extra);
        c.env("WGPU_BACKEND", if cfg!(windows) { "metal" } else { "dx12" });
        c
    };
    fails(
        &mut no_adapter("gpu"),
        1,
        &["no GPU adapter", "--backend cpu"],
    );
    assert!(!out.exists());
    succeeds_saying(&mut no_adapter("auto"), &["backend: cpu (no GPU adapter"]);
    assert!(out.is_file());
}

#[test]
fn render_on_the_gpu_writes_the_png_and_times_frames() {
    if common::gpu().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("gpu.png");
    let extra = ["--backend", "gpu", "--frames", "3", "--time-frames", "2"];
    let mut c = render(shipped("fair_weather.toml"), &out, &extra);
    let o = succeeds_saying(
        c.args(["--width", "40", "--height", "30"]),
        &["backend: gpu"],
    );
    let stdout = stdout(&o);
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
    let extra = ["--parcels", "3", "--dt-s", "7", "--duration-s", "60"];
    succeeds_saying(
        &mut simulate(shipped("fair_weather.toml"), &out, &extra),
        &["simulated 60 s in 9 frames (8 of 7 s, the last of 4 s)"],
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
    let scene = shipped("fair_weather.toml");
    let extra = ["--resolution", "96", "--levels", "12"];
    let o = succeeds(&mut on_scene("stats", &scene, &out, &extra));
    let stdout = stdout(&o);
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
fn render_refuses_a_missing_folder_or_a_directory_before_simulating() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shipped("fair_weather.toml");
    let missing = dir.path().join("no/such/folder/sky.png");
    for (out, says) in [
        (missing.as_path(), "does not exist"),
        (dir.path(), "is a directory"),
    ] {
        let err = fails(&mut render(&scene, out, &["--backend", "cpu"]), 1, &[says]);
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
    let mut c = render(
        shipped("fair_weather.toml"),
        &out,
        &["--backend", "auto", "--time-s", "60"],
    );
    c.args(["--width", "32", "--height", "24"])
        .env_remove("XDG_RUNTIME_DIR");
    let err = stderr(&succeeds(&mut c));
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
        let text = stdout(&succeeds(cumulus(cmd).arg("--help")));
        assert!(text.contains("Example:\n  cumulus "), "{cmd:?}:\n{text}");
        if cmd == ["render"] {
            assert!(text.contains("unless --quality-report"), "{text}");
        }
    }
}

/// Errors say where the bad value came from, once.
#[test]
fn errors_name_where_the_value_came_from() {
    let dir = tempfile::tempdir().unwrap();
    // A missing scene: the OS error once.
    let err = fails(&mut cumulus(&["scene", "check", "nothere.toml"]), 1, &[]);
    assert_eq!(err.matches("No such file").count(), 1, "{err}");
    // A missing sounding: the scene file, line and key that name it.
    assert_scene_check_fails(
        dir.path(),
        "s1.toml",
        "name = \"x\"\n[atmosphere]\nsounding = \"missing.csv\"\n",
        &["s1.toml:3: `atmosphere.sounding`: names", "missing.csv"],
    );
    // A flag's value: the flag, not a line of the scene.
    let s = write(dir.path(), "s2.toml", "[physics]\nparcels = 12\n");
    let err = fails(
        &mut simulate(&s, dir.path().join("c.csv"), &["--parcels", "10000000"]),
        1,
        &["--parcels is 10000000, expected 0..=200000"],
    );
    assert!(!err.contains("s2.toml:2"), "{err}");
    // A TOML type error: the key.
    assert_scene_check_fails(
        dir.path(),
        "s3.toml",
        "[physics]\nparcels = \"many\"\n",
        &["s3.toml:2:11: `physics.parcels`: invalid type"],
    );
}

/// SIGINT and SIGTERM remove the run's temporary file (left, it would
/// stay, up to 50 MB, as `.NAME.PID.tmp`); a later run into the same folder
/// removes the ones that runs which are gone (SIGKILL) left.
#[test]
fn interrupted_runs_leave_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shipped("fair_weather.toml");
    let out = dir.path().join("curves.csv");
    let stale = dir.path().join(format!(".curves.csv.{}.tmp", u32::MAX));
    std::fs::write(&stale, "left by a killed run").unwrap();
    for signal in ["-INT", "-TERM"] {
        let mut child = simulate(&scene, &out, &["--parcels", "400", "--duration-s", "1e6"])
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
    let render_here = |scene: &str| {
        let mut c = render(scene, "sky.png", &["--backend", "cpu", "--time-s", "10"]);
        c.args(["--width", "16", "--height", "12"])
            .current_dir(dir.path());
        c
    };
    // A shipped scene by its bare name: the built-in copy, said so.
    let built_in = ["the built-in copy of scenes/fair_weather.toml"];
    succeeds_saying(&mut render_here("fair_weather"), &built_in);
    assert!(dir.path().join("sky.png").is_file());
    // A path that names no file is an error, never the built-in copy in
    // its place; for a shipped scene's file name it names the built-in.
    for scene in ["scenes/fair_weather.toml", "/typo/fair_weather.toml"] {
        fails(
            &mut render_here(scene),
            1,
            &[scene, "no such file", "`--scene fair_weather`"],
        );
    }
    fails(
        &mut render_here("scenes/mine.toml"),
        1,
        &["scenes/mine.toml", "cannot read scene"],
    );
    fails(
        &mut render_here("mine"),
        1,
        &["`mine`", "built-in scenes: ", "fair_weather", "evening"],
    );
    // `scene check` reads a scene as the other commands do.
    let mut check = cumulus(&["scene", "check", "fair_weather"]);
    let o = succeeds_saying(check.current_dir(dir.path()), &built_in);
    assert!(stdout(&o).contains(": ok ("));
    let mut check = cumulus(&["scene", "check", "/some/missing/evening.toml"]);
    let o = check.current_dir(dir.path()).output().unwrap();
    assert_failed(
        "scene check /some/missing/evening.toml",
        &o,
        1,
        &["/some/missing/evening.toml", "no such file"],
    );
    assert!(!stdout(&o).contains("ok"), "{}", stdout(&o));
    // simulate too: a typo in the path is not silently the built-in scene.
    let out = dir.path().join("c.csv");
    fails(
        &mut simulate("/typo/fair_weather.toml", &out, &[]),
        1,
        &["/typo/fair_weather.toml", "no such file"],
    );
    assert!(!out.exists());
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
    let render_into = |out: &str| {
        let extra = ["--backend", "cpu", "--width", "32", "--height", "24"];
        stderr(&succeeds(&mut render(&path, dir.path().join(out), &extra)))
    };
    std::fs::write(&path, scene(0.6)).unwrap();
    assert!(
        render_into("a.png").contains("wrote"),
        "first run builds and writes"
    );
    let second = render_into("b.png");
    assert!(second.contains("read from"), "{second}");
    assert_eq!(
        std::fs::read(dir.path().join("a.png")).unwrap(),
        std::fs::read(dir.path().join("b.png")).unwrap(),
        "the read database draws the same picture"
    );
    std::fs::write(&path, scene(0.5)).unwrap();
    let third = render_into("c.png");
    assert!(
        third.contains("built") && third.contains("wrote"),
        "{third}"
    );
    // A file that is not a database is an error, never overwritten.
    std::fs::write(dir.path().join("sky.volumes"), "not volumes").unwrap();
    fails(
        &mut render(&path, dir.path().join("d.png"), &["--backend", "cpu"]),
        1,
        &["not a cumulus volume database"],
    );
    assert_eq!(
        std::fs::read(dir.path().join("sky.volumes")).unwrap(),
        b"not volumes"
    );
}

/// `render`s `scene` into `out` as a 48x36 CPU picture, with `extra`
/// flags; asserts success and reads the picture back.
fn render_small_cpu(scene: &Path, out: &Path, extra: &[&str]) -> image::RgbImage {
    let mut c = render(
        scene,
        out,
        &["--width", "48", "--height", "36", "--backend", "cpu"],
    );
    succeeds(c.args(extra));
    image::open(out).unwrap().to_rgb8()
}

/// `render --single-scattering`: the sun's once-scattered light alone, so
/// where no cloud is the picture is black (the sky behind is left out);
/// refused with a clear error for what it does not cover (the spheroid
/// renderer here), before anything is simulated or written.
#[test]
fn render_single_scattering_leaves_the_sky_out_and_refuses_other_renderers() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shipped("fair_weather.toml");
    let render_as =
        |name: &str, extra: &[&str]| render_small_cpu(&scene, &dir.path().join(name), extra);
    let black = |img: &image::RgbImage| img.pixels().filter(|p| p.0 == [0, 0, 0]).count();
    let full = render_as("full.png", &[]);
    let single = render_as("single.png", &["--single-scattering"]);
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
    let extra = ["--backend", "cpu", "--single-scattering"];
    fails(
        &mut render(shipped("spheroids.toml"), &out, &extra),
        1,
        &["--single-scattering", "cloud_map"],
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
    let text = std::fs::read_to_string(shipped("fair_weather.toml")).unwrap();
    let twilight = text.replace("sun_elevation_deg = 28.0", "sun_elevation_deg = -6.0");
    assert_ne!(twilight, text, "the shipped scene's sun moved");
    let sky = |extra: &str, name: &str| {
        let with = twilight.replacen("[render]\n", &format!("[render]\n{extra}"), 1);
        let scene = write(dir.path(), &format!("{name}.toml"), &with);
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
    let scene = shipped("fair_weather.toml");
    let run = |steps: &str| {
        let mut c = render(
            &scene,
            &out,
            &["--backend", "gpu", "--frames", "1", "--steps", steps],
        );
        stderr(&succeeds(c.args(["--width", "8", "--height", "6"])))
            .contains("on lavapipe, which ends a shader's loops after 65535 iterations")
    };
    assert_eq!(run("1024"), ctx.is_llvmpipe());
    assert!(!run("512"));
}

/// `--out` naming a file the run reads is refused before anything is
/// written: the scene's sounding, a `--sounding`, the profile's sounding.
#[test]
fn an_output_that_is_an_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for f in ["bomex.toml", "bomex_sounding.csv"] {
        std::fs::copy(root.join("scenes").join(f), dir.path().join(f)).unwrap();
    }
    let scene = dir.path().join("bomex.toml");
    let sounding = dir.path().join("bomex_sounding.csv");
    let before = std::fs::read(&sounding).unwrap();
    fails(
        &mut simulate(&scene, &sounding, &["--duration-s", "60"]),
        1,
        &[
            "bomex_sounding.csv",
            "is the scene's sounding this run reads",
            "choose another --out",
        ],
    );
    let other = write(
        dir.path(),
        "other.csv",
        "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,20,15\n1000,,12,8\n3000,,0,-5\n",
    );
    fails(
        &mut simulate(
            shipped("fair_weather.toml"),
            &other,
            &["--sounding", path(&other)],
        ),
        1,
        &["other.csv", "is the sounding this run reads"],
    );
    fails(
        &mut cumulus(&[
            "profile",
            "--sounding",
            path(&sounding),
            "--out",
            path(&sounding),
        ]),
        1,
        &["is the sounding this run reads"],
    );
    // The same file by another name is the same file.
    let dotted = dir.path().join(".").join("bomex_sounding.csv");
    fails(
        &mut simulate(&scene, &dotted, &["--duration-s", "60"]),
        1,
        &["is the scene's sounding this run reads"],
    );
    assert_eq!(
        std::fs::read(&sounding).unwrap(),
        before,
        "the input is untouched"
    );
    assert!(std::fs::read(&other).unwrap().starts_with(b"height_m"));
}

/// A huge or tiny value is reported as written, `1e308`, not as its 309
/// digits.
#[test]
fn huge_values_are_reported_in_scientific_notation() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(dir.path(), "big.toml", "[physics]\nradius_m = 1e308\n");
    let err = fails(
        &mut cumulus(&["scene", "check", path(&scene)]),
        1,
        &["`physics.radius_m`: is 1e308, expected"],
    );
    assert!(err.len() < 300, "{err}");
    let out = dir.path().join("c.csv");
    let err = fails(
        &mut simulate(
            shipped("fair_weather.toml"),
            &out,
            &["--duration-s", "1e308"],
        ),
        1,
        &["--duration-s is 1e308, expected"],
    );
    assert!(err.len() < 300, "{err}");
    let snd = write(
        dir.path(),
        "s.csv",
        "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1e308,20,15\n1000,,12,8\n",
    );
    let err = fails(
        &mut cumulus(&["profile", "--sounding", path(&snd)]),
        1,
        &["s.csv:2: `pressure_hPa` is 1e308, expected"],
    );
    assert!(err.len() < 300, "{err}");
}

/// `age_s` counts from a parcel's release: a parcel with a negative age
/// is still waiting at the release height, at rest and not projecting;
/// `z_m` is the height (the physics' axes, z up).
#[test]
fn parcels_not_yet_released_wait_at_the_release_height() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("curves.csv");
    let extra = ["--duration-s", "600", "--every-s", "300", "--parcels", "40"];
    succeeds(&mut simulate(shipped("fair_weather.toml"), &out, &extra));
    let mut r = csv::Reader::from_path(&out).unwrap();
    let h = r.headers().unwrap().clone();
    let col = |name: &str| h.iter().position(|c| c == name).unwrap();
    let (age, z, w, coverage) = (col("age_s"), col("z_m"), col("w_mps"), col("coverage"));
    let (mut waiting, mut released) = (0, 0);
    for row in r.records() {
        let row = row.unwrap();
        let num = |c: usize| row[c].parse::<f64>().unwrap();
        if num(age) < 0.0 {
            waiting += 1;
            assert_eq!(num(z), 50.0, "a waiting parcel at the release height");
            assert_eq!(num(w), 0.0, "a waiting parcel at rest");
            assert_eq!(num(coverage), 0.0, "a waiting parcel projects nothing");
        } else {
            released += 1;
        }
    }
    assert!(
        waiting > 0 && released > 0,
        "{waiting} waiting, {released} released"
    );
}

/// An endless database path that is a folder is an error naming the key
/// and the folder, before the volumes are built.
#[test]
fn an_endless_database_that_is_a_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("volumes")).unwrap();
    let scene = write(
        dir.path(),
        "e.toml",
        "[simulation]\nmethod = \"endless\"\n\n[simulation.endless]\nvolumes = 3\n\
         interval_s = 20.0\ncells = [16, 4, 16]\ndatabase = \"volumes\"\n",
    );
    let out = dir.path().join("e.png");
    fails(
        &mut render(
            &scene,
            &out,
            &["--backend", "cpu", "--width", "32", "--height", "24"],
        ),
        1,
        &[
            "e.toml:",
            "`simulation.endless.database`",
            "volumes, a folder",
            "expected a file",
        ],
    );
    assert!(!out.exists());
}

/// `render --stills-report DIR` writes the stills' error against cost
/// with no picture: each sampling's marches a pixel (uniform: its
/// offsets; adaptive: between one and its offsets) and its error.
#[test]
fn the_stills_report_counts_each_samplings_marches() {
    let dir = tempfile::tempdir().unwrap();
    let scene = shipped("fair_weather.toml");
    let mut c = cumulus(&["render", "--scene", path(&scene), "--backend", "cpu"]);
    c.args([
        "--width",
        "32",
        "--height",
        "24",
        "--light-photons",
        "16",
        "--time-s",
        "600",
    ]);
    c.arg("--stills-report").arg(dir.path());
    let out = stdout(&succeeds(&mut c));
    assert!(out.contains("stills.csv"), "{out}");
    let mut r = csv::Reader::from_path(dir.path().join("stills.csv")).unwrap();
    let rows: Vec<csv::StringRecord> = r.records().map(|x| x.unwrap()).collect();
    assert_eq!(rows.len(), 6);
    for row in &rows {
        let offsets: f64 = row[1].parse().unwrap();
        let marches: f64 = row[4].parse().unwrap();
        let error: f64 = row[5].parse().unwrap();
        match &row[0] {
            "uniform" => assert_eq!(marches, offsets),
            "adaptive" => assert!(marches >= 1.0 && marches < offsets, "{row:?}"),
            other => panic!("sampling {other}"),
        }
        assert!(error.is_finite() && error >= 0.0, "{row:?}");
    }
}
