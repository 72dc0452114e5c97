//! The sky demo in a real (virtual) window: under Xvfb with whatever
//! Vulkan driver exists (lavapipe in CI), `--screenshot` renders a few
//! frames and saves the last. Needs `xvfb-run` and a GPU adapter; without
//! them the test prints `SKIPPED` and passes, unless
//! `CUMULUS_REQUIRE_GPU=1` (set by `.ci/run`, which installs both).

mod common;

use std::path::PathBuf;
use std::process::Command;

fn required() -> bool {
    std::env::var("CUMULUS_REQUIRE_GPU").ok().as_deref() == Some("1")
}

/// The demo binary, which `cargo test` builds with the other examples.
fn sky() -> PathBuf {
    let exe = std::env::current_exe().expect("test path");
    let dir = exe.parent().and_then(|d| d.parent()).expect("target dir");
    dir.join("examples")
        .join(format!("sky{}", std::env::consts::EXE_SUFFIX))
}

fn xvfb() -> bool {
    let ok = Command::new("xvfb-run").arg("--help").output().is_ok();
    if !ok {
        assert!(!required(), "CUMULUS_REQUIRE_GPU=1 but xvfb-run is missing");
        eprintln!("SKIPPED: no xvfb-run");
    }
    ok
}

fn run(args: &[&str], env: &[(&str, &str)]) -> std::process::Output {
    let runtime = tempfile::tempdir().unwrap();
    let mut c = Command::new("xvfb-run");
    c.args(["-a", "-s", "-screen 0 1024x768x24"])
        .arg(sky())
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("XDG_RUNTIME_DIR", runtime.path());
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("xvfb-run runs")
}

/// The demo on fair weather in a `width x height` window, `--screenshot`
/// after `frames` frames: its output (it must succeed) and the picture.
fn screenshot(frames: u32, width: u32, height: u32) -> (std::process::Output, image::RgbImage) {
    let dir = tempfile::tempdir().unwrap();
    let shot = dir.path().join("shot.png");
    let (frames, width, height) = (frames.to_string(), width.to_string(), height.to_string());
    let o = run(
        &[
            "--scene",
            "scenes/fair_weather.toml",
            "--screenshot",
            shot.to_str().unwrap(),
            "--frames",
            &frames,
            "--width",
            &width,
            "--height",
            &height,
        ],
        &[],
    );
    assert!(
        o.status.success(),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    let img = image::open(&shot).expect("a PNG").to_rgb8();
    (o, img)
}

#[test]
fn screenshot_shows_sky_and_clouds_in_a_real_window() {
    if !xvfb() {
        return;
    }
    if common::gpu().is_none() {
        return;
    }
    let (o, img) = screenshot(3, 800, 450);
    // --screenshot says how far it has got.
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("frame 1 of 3") && err.contains("frame 3 of 3"),
        "{err}"
    );
    assert_eq!(img.dimensions(), (800, 450));
    // Right of the control panel (about 300 px), the upper two thirds are
    // sky (blue) with clouds (bright and grey-white).
    let (mut sky, mut cloud, mut lo, mut hi) = (0, 0, 255u8, 0u8);
    for y in 0..300 {
        for x in 400..800 {
            let [r, g, b] = img.get_pixel(x, y).0;
            lo = lo.min(g);
            hi = hi.max(g);
            if b as f32 > 1.2 * r as f32 && b > 80 {
                sky += 1;
            } else if r > 120 && (b as f32) < 1.15 * r as f32 {
                cloud += 1;
            }
        }
    }
    eprintln!("sky {sky}, cloud {cloud}, green range {lo}..{hi}");
    assert!(sky > 5_000, "sky pixels: {sky}");
    assert!(cloud > 100, "cloud pixels: {cloud}");
    assert!(hi - lo > 40, "not uniform");
}

#[test]
fn no_adapter_is_a_clear_message() {
    if !xvfb() {
        return;
    }
    let backend = if cfg!(windows) { "metal" } else { "dx12" };
    let o = run(
        &["--frames", "1", "--screenshot", "/dev/null"],
        &[("WGPU_BACKEND", backend)],
    );
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("no GPU adapter") && err.contains("mesa-vulkan-drivers"),
        "{err}"
    );
}

#[test]
fn a_bad_scene_is_named_in_the_error() {
    if !xvfb() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[render]\nsteps = -3\n").unwrap();
    let o = run(
        &[
            "--scene",
            bad.to_str().unwrap(),
            "--frames",
            "1",
            "--screenshot",
            "/dev/null",
        ],
        &[],
    );
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("bad.toml:2"), "{err}");
}

/// In a small window the control panel starts hidden behind a button, so
/// the sky fills the window: at 320x180 the left half, where a 300-pixel
/// panel would sit, is sky and cloud, not the panel's grey.
#[test]
fn a_small_window_keeps_its_sky() {
    if !xvfb() {
        return;
    }
    if common::gpu().is_none() {
        return;
    }
    let (_, img) = screenshot(1, 320, 180);
    assert_eq!(img.dimensions(), (320, 180));
    // Below the button, the left half's upper part: blue sky or cloud.
    let (mut sky, mut n) = (0, 0);
    for y in 30..70 {
        for x in 0..160 {
            let [r, _, b] = img.get_pixel(x, y).0;
            n += 1;
            if (b as f32 > 1.2 * r as f32 && b > 80) || r > 120 {
                sky += 1;
            }
        }
    }
    assert!(sky * 10 > n * 9, "{sky} of {n} pixels are sky or cloud");
}
