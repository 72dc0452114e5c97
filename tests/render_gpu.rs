//! The wgpu renderer against its CPU twin, TSAA, the passes a scene builds,
//! and robustness. Runs on whatever adapter exists (lavapipe in CI).
//! Without one each test prints `SKIPPED: no GPU adapter` and passes,
//! unless `CUMULUS_REQUIRE_GPU=1` (set by `.ci/run`).

use cumulus::render::cpu::renderer::{RenderSettings, render_linear, to_srgb8};
use cumulus::render::gpu::{GpuContext, GpuError, Headless};
use cumulus::render::prepare::Prepared;
use cumulus::scene::Scene;

fn gpu() -> Option<GpuContext> {
    match GpuContext::new() {
        Ok(c) => {
            eprintln!("adapter: {}", c.describe());
            Some(c)
        }
        Err(GpuError::NoAdapter) => {
            if std::env::var("CUMULUS_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("CUMULUS_REQUIRE_GPU=1 but no GPU adapter was found");
            }
            eprintln!("SKIPPED: no GPU adapter");
            None
        }
        Err(e) => panic!("GPU device: {e}"),
    }
}

fn scene(name: &str) -> Scene {
    Scene::load(std::path::Path::new(&format!("scenes/{name}.toml"))).expect("shipped scene")
}

/// Mean and max absolute difference of two RGB8 images, in 0..1 units.
fn diff(a: &[u8], b: &[u8]) -> (f64, f64) {
    assert_eq!(a.len(), b.len());
    let mut sum = 0.0;
    let mut max: f64 = 0.0;
    for (x, y) in a.iter().zip(b) {
        let d = (*x as f64 - *y as f64).abs() / 255.0;
        sum += d;
        max = max.max(d);
    }
    (sum / a.len() as f64, max)
}

#[test]
fn gpu_matches_cpu_reference_without_jitter() {
    let Some(ctx) = gpu() else { return };
    let mut sc = scene("fair_weather");
    sc.render.tsaa = false;
    let prepared = Prepared::from_scene(&sc, || {}).expect("prepare");
    for (w, h) in [(64, 48), (97, 61), (160, 120)] {
        let r = RenderSettings {
            width: w,
            height: h,
            ..sc.render.clone()
        };
        let q = r.quality();
        let cpu = to_srgb8(&render_linear(w, h, &prepared.frame(&r, q)), q.exposure);
        let mut hl =
            Headless::new(&ctx, &prepared, &prepared.gpu_settings(&r, q), w, h).expect("renderer");
        hl.render(&ctx, &r.camera(), 1).expect("frame");
        let gpu = hl.read_rgb8(&ctx).expect("readback");
        let (mean, max) = diff(&cpu, &gpu);
        eprintln!("{w}x{h}: mean {mean:.5} max {max:.4}");
        image::RgbImage::from_raw(w, h, gpu.clone())
            .unwrap()
            .save(format!("/tmp/gpu_{w}.png"))
            .unwrap();
        image::RgbImage::from_raw(w, h, cpu.clone())
            .unwrap()
            .save(format!("/tmp/cpu_{w}.png"))
            .unwrap();
    }
}
