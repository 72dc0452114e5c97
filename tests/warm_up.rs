//! `CloudRenderer::warm_up`: the pipelines an application's frames need
//! are compiled ahead of the first frame, so that frame does not stall
//! on the driver's compiler. GPU tests skip without an adapter unless
//! `CUMULUS_REQUIRE_GPU=1` (CI: lavapipe).

mod common;

use common::gpu;
use cumulus::prepare::Prepared;
use cumulus::render::gpu::renderer::{PASS_CLOUDS, PASS_COMPOSITE, PASS_LIGHT_VOLUME};
use cumulus::render::gpu::{CloudRenderer, FrameUse, GpuContext, textures};
use cumulus::scene::Scene;

const W: u32 = 32;
const H: u32 = 24;
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

fn renderer(ctx: &GpuContext, name: &str, tsaa: bool) -> (Scene, CloudRenderer) {
    let path = format!("scenes/{name}.toml");
    let mut sc = Scene::load(std::path::Path::new(&path)).expect("shipped scene");
    // A quick light volume: the scenes' 1024 photons a column take a
    // minute to build on lavapipe; these tests do not measure the light.
    sc.render.light_photons = 16;
    sc.render.tsaa = tsaa;
    sc.render.terrain.size = sc.render.terrain.size.min(32);
    let p = Prepared::from_scene(&sc, || {}).expect("prepare");
    let r = &sc.render;
    let mut c = CloudRenderer::new(
        &ctx.device,
        &ctx.queue,
        FORMAT,
        &p.gpu_settings(r, r.quality()),
        &p.cloud_map,
        p.terrain.as_ref(),
    )
    .expect("the renderer");
    c.update_field(&ctx.queue, &p.field);
    c.resize(W, H);
    (sc, c)
}

fn texture(ctx: &GpuContext, format: wgpu::TextureFormat) -> wgpu::TextureView {
    let usage = if format.is_depth_stencil_format() {
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING
    } else {
        wgpu::TextureUsages::RENDER_ATTACHMENT
    };
    textures::create_2d(&ctx.device, "app.target", W, H, format, usage)
        .create_view(&Default::default())
}

/// Draws one frame of each way in `uses`.
fn draw(ctx: &GpuContext, sc: &Scene, c: &mut CloudRenderer, uses: &[FrameUse]) {
    let target = texture(ctx, FORMAT);
    let depth = texture(ctx, wgpu::TextureFormat::Depth32Float);
    let camera = sc.render.camera();
    for u in uses {
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        match *u {
            FrameUse::Render { depth: d } => c
                .render(&mut enc, &target, d.then_some(&depth), &camera)
                .expect("frame"),
            FrameUse::CloudsOnly { depth: d } => {
                c.render_clouds(&mut enc, d.then_some(&depth), &camera)
                    .expect("frame");
            }
        }
        ctx.queue.submit([enc.finish()]);
    }
}

#[test]
fn warm_up_builds_every_pipeline_the_frames_then_use() {
    let Some(ctx) = gpu() else { return };
    let all = [
        FrameUse::Render { depth: false },
        FrameUse::Render { depth: true },
        FrameUse::CloudsOnly { depth: false },
        FrameUse::CloudsOnly { depth: true },
    ];
    // With TSAA and without, over the sky and over the scene's terrain:
    // the cloud pass's variants (depth or none) and the composite's
    // (sky, terrain, the application's depth).
    for (name, tsaa) in [("fair_weather", true), ("evening", false)] {
        for uses in [&all[..1], &all[1..2], &all[2..3], &all[..]] {
            let (sc, mut c) = renderer(&ctx, name, tsaa);
            let before = c.pipelines();
            assert!(!before.contains(&PASS_CLOUDS), "{name}: {before:?}");
            c.warm_up(uses);
            let warm = c.pipelines();
            assert!(warm.contains(&PASS_LIGHT_VOLUME), "{name}: {warm:?}");
            assert!(warm.contains(&PASS_CLOUDS), "{name}: {warm:?}");
            let composites = uses.iter().any(|u| matches!(u, FrameUse::Render { .. }));
            assert_eq!(warm.contains(&PASS_COMPOSITE), composites, "{name}");
            draw(&ctx, &sc, &mut c, uses);
            // The frames found every pipeline they use built.
            assert_eq!(c.pipelines(), warm, "{name} {uses:?}");
        }
    }
}

#[test]
fn a_settings_change_that_drops_the_pipelines_is_warmed_up_again() {
    let Some(ctx) = gpu() else { return };
    let (sc, mut c) = renderer(&ctx, "fair_weather", true);
    let uses = [FrameUse::Render { depth: false }];
    // Wall times, printed (`--nocapture`) for the README, not asserted.
    let (cold_sc, mut cold) = renderer(&ctx, "fair_weather", true);
    let timed = |f: &mut dyn FnMut()| {
        let t = std::time::Instant::now();
        f();
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("poll");
        t.elapsed().as_secs_f64() * 1e3
    };
    let cold_frame = timed(&mut || draw(&ctx, &cold_sc, &mut cold, &uses));
    let warm_up = timed(&mut || c.warm_up(&uses));
    let first = timed(&mut || draw(&ctx, &sc, &mut c, &uses));
    eprintln!(
        "first frame without warm_up {cold_frame:.0} ms; warm_up {warm_up:.0} ms, then the first frame {first:.0} ms"
    );
    let warm = c.pipelines();
    let mut s = *c.settings();
    s.quality.shadow_steps += 4;
    c.set_settings(&s);
    assert!(!c.pipelines().contains(&PASS_CLOUDS), "dropped");
    c.warm_up(&uses);
    assert_eq!(c.pipelines(), warm);
    draw(&ctx, &sc, &mut c, &uses);
    assert_eq!(c.pipelines(), warm);
}
