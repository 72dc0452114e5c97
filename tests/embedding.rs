//! What an engine embedding the renderer needs: its own view and
//! projection matrices (roll, off-axis, right-handed), its depth buffer in
//! any of the common conventions (standard or reversed, finite or infinite
//! far plane), and the clouds-only output it composites itself. GPU tests
//! skip without an adapter unless `CUMULUS_REQUIRE_GPU=1` (CI: lavapipe).

mod common;

use common::gpu;
use cumulus::prepare::Prepared;
use cumulus::render::camera::View;
use cumulus::render::cpu::land::flat_ground_albedo;
use cumulus::render::cpu::renderer::{flat_ground_shadow, pixel_dither};
use cumulus::render::cpu::sea::sea_reflection_change;
use cumulus::render::cpu::sea::sea_waves_at;
use cumulus::render::cpu::sky::{background_radiance, sun_direction};
use cumulus::render::cpu::stills::render_clouds_linear;
use cumulus::render::cpu::tone_map::to_srgb8;
use cumulus::render::gpu::renderer::CLOUDS_ONLY_FORMAT;
use cumulus::render::gpu::{CloudRenderer, GpuContext, textures};
use cumulus::scene::Scene;
use glam::{Mat4, Vec3, Vec4};

const W: u32 = 96;
const H: u32 = 64;

fn prepared() -> (Scene, Prepared) {
    prepared_scene("fair_weather")
}

fn prepared_scene(name: &str) -> (Scene, Prepared) {
    let path = format!("scenes/{name}.toml");
    let mut sc = Scene::load(std::path::Path::new(&path)).expect("shipped scene");
    // A quick light volume: the scenes' 1024 photons a column take a
    // minute to build on lavapipe; these tests do not measure the light.
    sc.render.light_photons = 16;
    sc.render.tsaa = false;
    // The composited picture below is the clouds over the background
    // alone: the glare the composite adds around a sun in view is not
    // in an engine's clouds-only layer (the shipped scenes' suns are out
    // of view, where it is a small fraction of a level).
    sc.render.sun_glare = 0.0;
    sc.render.width = W;
    sc.render.height = H;
    let p = Prepared::from_scene(&sc, || {}).expect("prepare");
    (sc, p)
}

fn renderer(ctx: &GpuContext, sc: &Scene, p: &Prepared) -> CloudRenderer {
    let r = &sc.render;
    let mut c = CloudRenderer::new(
        &ctx.device,
        &ctx.queue,
        wgpu::TextureFormat::Rgba8UnormSrgb,
        &p.gpu_settings(r, r.quality()),
        &p.cloud_map,
        None,
    )
    .expect("the renderer");
    c.update_field(&ctx.queue, &p.field);
    c.resize(W, H);
    c
}

/// A depth buffer cleared to `value` everywhere: a plane of constant
/// camera-space depth, in whatever convention `value` was computed in.
fn depth_buffer(ctx: &GpuContext, value: f32) -> wgpu::Texture {
    depth_of(
        ctx,
        wgpu::TextureFormat::Depth32Float,
        1,
        wgpu::TextureUsages::TEXTURE_BINDING,
        value,
    )
}

/// The clouds-only layer for `view` up to `depth`.
fn clouds_only(
    ctx: &GpuContext,
    c: &mut CloudRenderer,
    depth: Option<&wgpu::Texture>,
    view: &View,
) -> Vec<[f32; 4]> {
    let dv = depth.map(|d| d.create_view(&Default::default()));
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    let tex = c
        .render_clouds(&mut enc, dv.as_ref(), view)
        .expect("frame")
        .expect("non-zero size")
        .clone();
    ctx.queue.submit([enc.finish()]);
    assert_eq!(tex.format(), CLOUDS_ONLY_FORMAT);
    ctx.read_rgba16f(&tex).expect("readback")
}

fn mean_abs(a: &[[f32; 4]], b: &[[f32; 4]], lane: usize) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x[lane] - y[lane]).abs() as f64)
        .sum::<f64>()
        / a.len() as f64
}

fn opacity(a: &[[f32; 4]]) -> f64 {
    a.iter().map(|p| p[3] as f64).sum()
}

/// A right-handed view rolled by 25°, with an off-axis reversed-Z
/// infinite projection: the kind of camera a flight simulator's cockpit
/// window has, and nothing like the scene's yaw/pitch camera.
fn engine_view(sc: &Scene) -> View {
    let c = sc.render.camera();
    let (f, _, u) = c.basis();
    let up = glam::Quat::from_axis_angle(f, 25_f32.to_radians()) * u;
    let world_to_view = Mat4::look_to_rh(c.position_m, f, up);
    // perspective_infinite_reverse_rh, its centre shifted by a fifth of the
    // screen right and a tenth down (clip x += 0.2 w, y -= 0.1 w).
    let p = Mat4::perspective_infinite_reverse_rh(55_f32.to_radians(), W as f32 / H as f32, 0.3);
    let shift = Mat4::from_cols(Vec4::X, Vec4::Y, Vec4::Z, Vec4::new(0.2, -0.1, 0.0, 1.0));
    View::new(world_to_view, shift * p).expect("a valid camera")
}

/// The GPU's clouds-only output against its CPU twin, for an engine's
/// rolled, off-axis, right-handed, reversed-Z infinite camera: the same
/// rays on both sides, so the layers agree as closely as the composited
/// pictures do (`tests/render_gpu.rs`, mean under half an 8-bit level).
#[test]
fn an_engines_camera_gives_the_cpu_twins_clouds() {
    let Some(ctx) = gpu() else { return };
    let (sc, p) = prepared();
    let view = engine_view(&sc);
    let mut c = renderer(&ctx, &sc, &p);
    let gpu = clouds_only(&ctx, &mut c, None, &view);
    let mut fr = p.frame(&sc.render, sc.render.quality());
    fr.view = view;
    let cpu: Vec<[f32; 4]> = render_clouds_linear(W, H, &fr, 1)
        .iter()
        .map(|v| v.to_array())
        .collect();
    let alpha = mean_abs(&gpu, &cpu, 3);
    let red = mean_abs(&gpu, &cpu, 0);
    let cover = opacity(&cpu) / cpu.len() as f64;
    eprintln!("opacity: mean {cover:.3}; GPU-CPU mean |Δα| {alpha:.5}, |Δr| {red:.5}");
    assert!(cover > 0.05, "the view sees clouds: mean opacity {cover}");
    assert!(alpha < 0.004, "mean |Δ opacity| {alpha}");
    assert!(red < 0.01, "mean |Δ red| {red}");
    // The roll is real: the scene's own camera sees other clouds where.
    let plain = clouds_only(
        &ctx,
        &mut c,
        None,
        &sc.render.camera().view(W as f32 / H as f32, 4e4),
    );
    assert!(
        mean_abs(&gpu, &plain, 3) > 0.02,
        "rolled view = unrolled view"
    );
}

/// One wall of constant camera depth 3.5 km, written as four engines
/// would write it; each hides the same clouds. Before this test the
/// renderer read every depth buffer as standard-Z with its own near and
/// far planes, so the reversed ones hid nothing (0 reads as the near
/// plane) or everything.
#[test]
fn every_depth_convention_hides_the_same_clouds() {
    let Some(ctx) = gpu() else { return };
    let (sc, p) = prepared();
    let mut c = renderer(&ctx, &sc, &p);
    let cam = sc.render.camera();
    let (f, _, _) = cam.basis();
    let aspect = W as f32 / H as f32;
    let fov = cam.fov_deg.to_radians();
    let wall_m = 3500.0_f32;
    let lh = Mat4::look_to_lh(cam.position_m, f, Vec3::Y);
    let rh = Mat4::look_to_rh(cam.position_m, f, Vec3::Y);
    let views = [
        (
            "lh standard",
            lh,
            Mat4::perspective_lh(fov, aspect, 1.0, 40_000.0),
        ),
        (
            "rh standard",
            rh,
            Mat4::perspective_rh(fov, aspect, 0.5, 60_000.0),
        ),
        (
            "rh reversed infinite",
            rh,
            Mat4::perspective_infinite_reverse_rh(fov, aspect, 0.1),
        ),
        (
            "lh infinite",
            lh,
            Mat4::perspective_infinite_lh(fov, aspect, 0.5),
        ),
    ];
    let mut firsts: Vec<(&str, f64, Vec<[f32; 4]>)> = Vec::new();
    let mut all_shares = Vec::new();
    for (name, m, proj) in views {
        let view = View::new(m, proj).expect("valid");
        // The depth the projection gives a point `wall_m` ahead on the axis.
        let ahead = view.eye() + f * wall_m;
        let clip = view.view_projection() * ahead.extend(1.0);
        let d = clip.z / clip.w;
        let free = clouds_only(&ctx, &mut c, None, &view);
        let far = clouds_only(
            &ctx,
            &mut c,
            Some(&depth_buffer(&ctx, view.far_depth())),
            &view,
        );
        assert!(
            mean_abs(&far, &free, 3) < 1e-3,
            "{name}: a depth buffer cleared to the far value {} hides clouds",
            view.far_depth()
        );
        let walled = clouds_only(&ctx, &mut c, Some(&depth_buffer(&ctx, d)), &view);
        let (o, o_free) = (opacity(&walled), opacity(&free));
        eprintln!("{name}: depth {d:.6}: opacity {o:.1} of {o_free:.1} without the wall");
        assert!(
            o < 0.8 * o_free && o > 0.05 * o_free,
            "{name}: the wall at {wall_m} m should hide part of the clouds: {o} of {o_free}"
        );
        // The same wall hides the same share of the clouds whatever the
        // convention (a right-handed camera with +y up sees the world
        // mirrored, and its pixels' march dithers differ, so across
        // handedness only the share is compared).
        let share = o / o_free;
        let hand = &name[..2];
        match firsts.iter().find(|(h, _, _)| *h == hand) {
            None => firsts.push((hand, share, walled)),
            Some((_, s0, a)) => {
                // Pixel for pixel within one handedness: standard f32 depth
                // with a 0.5 m near plane places a wall 3.5 km away only to
                // ~1.5 m (ulp 6e-8 of 1 - d), which moves the clouds cut at
                // it (with 0.1 m, ~7 m: 2.5e-3 of opacity); reading
                // reversed depth as standard would hide all of them or
                // none.
                let e = mean_abs(a, &walled, 3);
                assert!(
                    e < 2e-3,
                    "{name}: differs from the first {hand} view by {e}"
                );
                assert!((share - s0).abs() < 0.01, "{name}: share {share} vs {s0}");
            }
        }
        all_shares.push(share);
    }
    let (lo, hi) = all_shares
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &s| (lo.min(s), hi.max(s)));
    assert!(hi - lo < 0.02, "shares hidden by the wall: {all_shares:?}");
}

/// The clouds-only layer composited over the scene's sky on the CPU
/// (`rgb + (1 - a) · sky`, the ground in the clouds' shadows below the
/// horizon, tone-mapped) is the renderer's own composite:
/// the output is linear, premultiplied, and leaves the background out.
/// Over land and over the sea (BOMEX), whose mirrored clouds `render`
/// draws in the cloud pass and the clouds-only layer must leave out.
#[test]
fn the_clouds_only_layer_composites_to_the_renderers_picture() {
    let Some(ctx) = gpu() else { return };
    for name in ["fair_weather", "bomex"] {
        clouds_only_layer_composites(&ctx, name);
    }
}

fn clouds_only_layer_composites(ctx: &GpuContext, name: &str) {
    let (sc, p) = prepared_scene(name);
    let mut c = renderer(ctx, &sc, &p);
    let r = &sc.render;
    let view = r
        .camera()
        .view(W as f32 / H as f32, r.quality().max_distance_m);
    let layer = clouds_only(ctx, &mut c, None, &view);
    let target = textures::create_2d(
        &ctx.device,
        "app.target",
        W,
        H,
        wgpu::TextureFormat::Rgba8UnormSrgb,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    c.render(
        &mut enc,
        &target.create_view(&Default::default()),
        None,
        &view,
    )
    .expect("frame");
    ctx.queue.submit([enc.finish()]);
    let picture: Vec<u8> = ctx
        .read_texture(&target, 4)
        .expect("readback")
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    let sun = sun_direction(r.sun_elevation_deg, r.sun_azimuth_deg);
    let q = r.quality();
    let frame = p.frame(r, q);
    let composited: Vec<Vec3> = layer
        .iter()
        .enumerate()
        .map(|(k, px)| {
            let (x, y) = ((k as u32 % W) as f32 + 0.5, (k as u32 / W) as f32 + 0.5);
            let dir = view.camera_ray(x, y, W, H);
            let shadow = flat_ground_shadow(view.eye(), dir, sun, &frame);
            let spread = view.pixel_spread(W, H);
            let dither = pixel_dither(x as u32, y as u32);
            // The sea as march_ray draws it: bare, plus what the mirrored
            // clouds change in it.
            let sky = background_radiance(
                &frame.sky_light(),
                dir,
                sun,
                sea_waves_at(view.eye(), dir, spread, &frame),
                shadow,
                flat_ground_albedo(view.eye(), dir, spread, &frame),
                (Vec3::ZERO, 1.0),
            ) + sea_reflection_change(view.eye(), dir, dither, sun, spread, &frame);
            Vec3::new(px[0], px[1], px[2]) + (1.0 - px[3]) * sky
        })
        .collect();
    let ours = to_srgb8(&composited, r.quality().exposure);
    let worst = ours
        .iter()
        .zip(&picture)
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap_or(0);
    let cloudy = layer.iter().filter(|p| p[3] > 0.5).count();
    assert!(cloudy > 50, "{cloudy} cloudy pixels");
    let off = ours
        .iter()
        .zip(&picture)
        .filter(|(a, b)| a.abs_diff(**b) > 2)
        .count();
    eprintln!(
        "{name}: worst {worst} levels, {off} of {} channels off by > 2",
        ours.len()
    );
    // Half floats (10-bit mantissa) and the GPU's exp: two 8-bit levels,
    // but for a few ground pixels on the edges of the clouds' shadows,
    // whose rays through the detail noise the two twins round
    // differently (measured on lavapipe: 21 of 18,432 channels, at most
    // 5 levels, with the land lit by the sun at its full contrast
    // between sun and shade). Over the sea, for a few more where the 12
    // reflected rays, tilted and turned sideways by the waves, graze the
    // mirrored clouds' edges (measured on lavapipe: 97-98 channels, all
    // below the horizon, of either sign, at most 10 levels). The waves
    // themselves agree: BOMEX with no clouds, 96x64, differs by at most
    // 1 level; with clouds, the sea's rows differ by 0.18 levels on
    // average.
    let share = if name == "bomex" { 0.0065 } else { 0.002 };
    assert!(
        off as f64 <= share * ours.len() as f64,
        "{off} channels differ by more than 2 levels"
    );
    // Over the sea, each pixel's 12 reflected rays take 4 to 16 steps
    // each across kilometres of band; where one of them grazes a cloud's edge
    // the twins can disagree on it, as the parity tests allow on single
    // pixels (measured on lavapipe: one BOMEX pixel, 10 levels; 22
    // with 6 rays of 4 steps).
    let allowed = if name == "bomex" { 64 } else { 8 };
    assert!(
        worst <= allowed,
        "{name}: composite differs by {worst} levels"
    );
    // And it is not the composite itself: no sky in the clear pixels (the
    // sky's radiance is 0.1-1 here; a wisp of opacity under 1e-3 carries
    // at most a few thousandths).
    let clear = layer.iter().filter(|p| p[3] < 1e-3).count();
    let dark = layer
        .iter()
        .filter(|p| p[3] < 1e-3 && p[0].abs() + p[1].abs() + p[2].abs() < 0.01)
        .count();
    assert!(
        clear > 50 && dark == clear,
        "{dark} of {clear} clear pixels are black"
    );
}

/// The far value of [`engine_view`]'s reversed Z: a depth buffer cleared
/// to it is all sky.
const FAR: f32 = 0.0;

/// A depth buffer of `format`, `samples` and `usage` (and
/// `RENDER_ATTACHMENT`), cleared to `value` (a stencil aspect to 0).
fn depth_of(
    ctx: &GpuContext,
    format: wgpu::TextureFormat,
    samples: u32,
    usage: wgpu::TextureUsages,
    value: f32,
) -> wgpu::Texture {
    let t = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("app.depth"),
        size: wgpu::Extent3d {
            width: W,
            height: H,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: usage | wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let view = t.create_view(&Default::default());
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("app.clear"),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(value),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: format.has_stencil_aspect().then_some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(0),
                store: wgpu::StoreOp::Store,
            }),
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    ctx.queue.submit([enc.finish()]);
    t
}

/// An engine's depth buffer as engines make them: a depth-stencil format
/// (its default view has both aspects) gives the same clouds as a depth
/// one, and what the passes cannot bind (a multisampled or unbindable
/// buffer), or a target of another size than the renderer's, is a
/// `RenderError` naming it, not a panic in wgpu's validation or a
/// picture read at the wrong pixels.
#[test]
fn engine_depth_buffers_are_bound_or_refused_by_name() {
    let Some(ctx) = gpu() else { return };
    let (sc, p) = prepared();
    let mut c = renderer(&ctx, &sc, &p);
    let view = engine_view(&sc);
    let bind = wgpu::TextureUsages::TEXTURE_BINDING;
    let plain = depth_of(&ctx, wgpu::TextureFormat::Depth32Float, 1, bind, FAR);
    let stencil = depth_of(&ctx, wgpu::TextureFormat::Depth24PlusStencil8, 1, bind, FAR);
    let a = clouds_only(&ctx, &mut c, Some(&plain), &view);
    let b = clouds_only(&ctx, &mut c, Some(&stencil), &view);
    assert!(opacity(&a) > 1.0, "clouds in view");
    assert!(mean_abs(&a, &b, 3) < 1e-3 && mean_abs(&a, &b, 1) < 1e-3);

    let mut err = |depth: &wgpu::Texture| {
        let dv = depth.create_view(&Default::default());
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let e = c
            .render_clouds(&mut enc, Some(&dv), &view)
            .map(|_| ())
            .expect_err("refused");
        e.to_string()
    };
    let msaa = depth_of(&ctx, wgpu::TextureFormat::Depth32Float, 4, bind, FAR);
    assert!(err(&msaa).contains("4 samples"));
    let unbindable = depth_of(
        &ctx,
        wgpu::TextureFormat::Depth32Float,
        1,
        wgpu::TextureUsages::empty(),
        FAR,
    );
    assert!(err(&unbindable).contains("lacks TEXTURE_BINDING"));

    let target = textures::create_2d(
        &ctx.device,
        "app.target",
        W + 1,
        H,
        wgpu::TextureFormat::Rgba8UnormSrgb,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let tv = target.create_view(&Default::default());
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    let e = c
        .render(&mut enc, &tv, None, &view)
        .expect_err("a wider target");
    assert!(
        e.to_string()
            .contains(&format!("the target is {}x{H}", W + 1)),
        "{e}"
    );
}

/// Over an engine's depth buffer the composite blends the clouds into
/// its colour, which a device blends into an `Rgba32Float` target only
/// with `FLOAT32_BLENDABLE`: without it, a `RenderError` that says so
/// (wgpu's validation panicked), and `Rgba16Float`, always blendable,
/// draws.
#[test]
fn an_unblendable_hdr_target_over_depth_is_refused_by_name() {
    let Some(ctx) = gpu() else { return };
    let (sc, p) = prepared();
    let r = &sc.render;
    let view = engine_view(&sc);
    let depth = depth_buffer(&ctx, FAR);
    let dv = depth.create_view(&Default::default());
    for format in [
        wgpu::TextureFormat::Rgba32Float,
        wgpu::TextureFormat::Rgba16Float,
    ] {
        let mut c = CloudRenderer::new(
            &ctx.device,
            &ctx.queue,
            format,
            &p.gpu_settings(r, r.quality()),
            &p.cloud_map,
            None,
        )
        .expect("the renderer");
        c.update_field(&ctx.queue, &p.field);
        c.resize(W, H);
        let target = textures::create_2d(
            &ctx.device,
            "app.hdr",
            W,
            H,
            format,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let tv = target.create_view(&Default::default());
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        let drawn = c.render(&mut enc, &tv, Some(&dv), &view);
        let blendable = format == wgpu::TextureFormat::Rgba16Float
            || ctx
                .device
                .features()
                .contains(wgpu::Features::FLOAT32_BLENDABLE);
        match drawn {
            Ok(()) => {
                assert!(blendable, "{format:?} drawn without blending support");
                ctx.queue.submit([enc.finish()]);
            }
            Err(e) => {
                assert!(!blendable, "{format:?}: {e}");
                assert!(e.to_string().contains("cannot be blended into"), "{e}");
            }
        }
    }
}

/// `examples/embed.rs` (built with the other examples) runs as written:
/// it builds the light volume progressively, so each frame after an
/// `update_field` traces one batch instead of a whole build, and it says
/// what every frame did and how long it took.
#[test]
fn the_embed_example_reports_each_frame() {
    if gpu().is_none() {
        return;
    }
    let exe = std::env::current_exe().expect("test path");
    let dir = exe.parent().and_then(|d| d.parent()).expect("target dir");
    let embed = dir
        .join("examples")
        .join(format!("embed{}", std::env::consts::EXE_SUFFIX));
    let out = tempfile::tempdir().unwrap();
    let png = out.path().join("embed.png");
    let o = std::process::Command::new(embed)
        .arg(&png)
        .output()
        .expect("the example runs");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let frames: Vec<&str> = text.lines().filter(|l| l.starts_with("frame ")).collect();
    assert_eq!(frames.len(), 16, "{text}");
    assert!(
        frames
            .iter()
            .all(|l| l.contains(" ms (physics, P, light batch")),
        "{text}"
    );
    assert!(png.is_file());
}
