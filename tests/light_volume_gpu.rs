//! The light volume built on the GPU (`LightVolumePass`,
//! `shaders/light_volume_build.wgsl`) against its CPU twin
//! (`render::cpu::light_volume`), and when it is built. Runs on whatever
//! adapter exists (lavapipe in CI). Without one each test prints
//! `SKIPPED: no GPU adapter` and passes, unless `CUMULUS_REQUIRE_GPU=1`.

mod common;

use common::gpu;
use cumulus::prepare::Prepared;
use cumulus::render::gpu::renderer::PASS_LIGHT_VOLUME;
use cumulus::scene::{RenderSettings, Scene};

fn scene(name: &str) -> Scene {
    Scene::load(std::path::Path::new(&format!("scenes/{name}.toml"))).expect("shipped scene")
}

/// The GPU's fluence against the CPU's, over the cells that hold light
/// (above a hundredth of the largest): the mean relative difference
/// (measured on lavapipe: see the test's output) and the largest. The
/// extinction of a cell is the mean of eight `density_at` reads, whose
/// GPU twin reads P and the cloud map as half floats through hardware
/// filtering: a few cells at cloud edges differ by a few per cent, and
/// the sweeps spread that over their neighbours.
const FLUENCE_MEAN_REL: f64 = 0.01;
const FLUENCE_HIGH_REL: f64 = 0.1;
const FLUENCE_MAX_REL: f64 = 0.6;
/// The net flux's difference over the cell's fluence: the mean and the
/// 99.9th percentile.
const FLUX_MEAN_REL: f64 = 0.01;
const FLUX_HIGH_REL: f64 = 0.1;

#[test]
fn the_gpu_light_volume_is_its_cpu_twin() {
    let Some(ctx) = gpu() else { return };
    for name in ["fair_weather", "bomex"] {
        let sc = scene(name);
        let p = Prepared::from_scene(&sc, || {}).expect("prepare");
        let r = RenderSettings {
            width: 32,
            height: 24,
            ..sc.render.clone()
        };
        let q = r.quality();
        let frame = p.frame(&r, q);
        let cpu = frame.light.expect("the CPU light volume");
        let mut hl = p
            .headless(&ctx, &p.gpu_settings(&r, q), r.width, r.height)
            .expect("renderer");
        hl.render(&ctx, &r.camera(), 1).expect("frame");
        let pass = hl.renderer.light_volume().expect("the GPU light volume");
        assert_eq!(pass.grid, cpu.grid);
        let gpu = pass.read_fluence(&ctx).expect("readback");
        assert_eq!(gpu.len(), cpu.fluence.len());
        let peak = cpu.fluence.iter().cloned().fold(0.0f32, f32::max);
        assert!(peak > 0.0, "{name}: no light in the CPU volume");
        let mut rel: Vec<f64> = Vec::new();
        for (g, c) in gpu.iter().zip(&cpu.fluence) {
            assert!(g.is_finite(), "{name}: GPU fluence {g}");
            if *c > 0.01 * peak {
                rel.push(((g - c).abs() / c) as f64);
            }
        }
        rel.sort_by(f64::total_cmp);
        let mean = rel.iter().sum::<f64>() / rel.len() as f64;
        let high = rel[rel.len() * 999 / 1000];
        let worst = rel[rel.len() - 1];
        eprintln!(
            "{name}: {} lit cells of {}, peak fluence {peak:.3}: relative difference mean {mean:.2e}, 99.9th percentile {high:.2e}, largest {worst:.2e}",
            rel.len(),
            cpu.fluence.len()
        );
        assert!(mean < FLUENCE_MEAN_REL, "{name}: mean {mean}");
        assert!(high < FLUENCE_HIGH_REL, "{name}: 99.9th percentile {high}");
        assert!(worst < FLUENCE_MAX_REL, "{name}: largest {worst}");

        // What the cloud pass samples: the fluence again (as half floats)
        // and the net flux, against the CPU's over the same cells, the
        // flux's difference relative to the cell's fluence (the flux is
        // at most FLUX_LIMIT of it, and crosses zero).
        let texels = pass.read_light(&ctx).expect("texture readback");
        assert_eq!(texels.len(), cpu.fluence.len());
        let (mut fluence_rel, mut flux_rel, mut flux_size) = (Vec::new(), Vec::new(), 0.0f64);
        for ((t, c), f) in texels.iter().zip(&cpu.fluence).zip(&cpu.flux) {
            if *c > 0.01 * peak {
                fluence_rel.push(((t[0] - c).abs() / c) as f64);
                let g = glam::Vec3::new(t[1], t[2], t[3]);
                flux_rel.push(((g - *f).length() / c) as f64);
                flux_size += (f.length() / c) as f64;
            }
        }
        for v in [&mut fluence_rel, &mut flux_rel] {
            v.sort_by(f64::total_cmp);
        }
        let n = flux_rel.len();
        let texture_mean = fluence_rel.iter().sum::<f64>() / n as f64;
        let flux_mean = flux_rel.iter().sum::<f64>() / n as f64;
        let flux_high = flux_rel[n * 999 / 1000];
        eprintln!(
            "{name}: texture fluence mean {texture_mean:.2e}; flux over fluence: CPU's mean size {:.3}, difference mean {flux_mean:.2e}, 99.9th percentile {flux_high:.2e}",
            flux_size / n as f64
        );
        assert!(
            texture_mean < FLUENCE_MEAN_REL,
            "{name}: texture {texture_mean}"
        );
        // The flux is there (a cloud's light flows outward), and the GPU's
        // is the CPU's.
        assert!(
            flux_size / n as f64 > 0.05,
            "{name}: flux {}",
            flux_size / n as f64
        );
        assert!(flux_mean < FLUX_MEAN_REL, "{name}: flux mean {flux_mean}");
        assert!(
            flux_high < FLUX_HIGH_REL,
            "{name}: flux 99.9th percentile {flux_high}"
        );
    }
}

/// The volume is built when P, the sun or the density change, not per
/// frame; without multiple scattering there is none, and no pipeline.
#[test]
fn the_light_volume_is_built_only_when_its_inputs_change() {
    let Some(ctx) = gpu() else { return };
    let sc = scene("fair_weather");
    let p = Prepared::from_scene(&sc, || {}).expect("prepare");
    let r = RenderSettings {
        width: 16,
        height: 12,
        ..sc.render.clone()
    };
    let q = r.quality();
    let settings = p.gpu_settings(&r, q);
    let mut hl = p
        .headless(&ctx, &settings, r.width, r.height)
        .expect("renderer");
    // Wall times, printed for the record (not asserted: machines here are
    // noisy): the first frame builds the volume, the next ones do not.
    let clock = std::time::Instant::now();
    hl.render(&ctx, &r.camera(), 1).expect("frame");
    let first = clock.elapsed().as_secs_f64();
    let clock = std::time::Instant::now();
    hl.render(&ctx, &r.camera(), 2).expect("frames");
    let next = clock.elapsed().as_secs_f64() / 2.0;
    eprintln!(
        "first frame (with the light volume's build) {:.0} ms, next frames {:.0} ms",
        first * 1e3,
        next * 1e3
    );
    assert_eq!(hl.renderer.light_volume_builds(), Some(1));
    assert!(hl.renderer.pipelines().contains(&PASS_LIGHT_VOLUME));
    hl.renderer.update_field(&ctx.queue, &p.field);
    hl.render(&ctx, &r.camera(), 2).expect("frames");
    assert_eq!(hl.renderer.light_volume_builds(), Some(2));
    let mut lower = settings;
    lower.sun_elevation_deg -= 5.0;
    hl.renderer.set_settings(&lower);
    hl.render(&ctx, &r.camera(), 1).expect("frame");
    assert_eq!(hl.renderer.light_volume_builds(), Some(3));
    let mut off = lower;
    off.quality.octaves = 0;
    hl.renderer.set_settings(&off);
    hl.render(&ctx, &r.camera(), 1).expect("frame");
    assert_eq!(hl.renderer.light_volume_builds(), None);
    assert!(!hl.renderer.pipelines().contains(&PASS_LIGHT_VOLUME));
    let cpu = p.frame(&r, off.quality);
    assert!(cpu.light.is_none(), "no CPU light volume without octaves");
}
