//! The wgpu cloud renderer embedded in an application that owns its
//! device, its frame and its target (the way vello or wgpu's examples are
//! embedded): the app steps the physics, hands the projected field P to
//! `CloudRenderer::update_field`, and records `CloudRenderer::render` into
//! its own command encoder each frame. Here the "app" renders offscreen
//! and saves the last frame.
//!
//! `cargo run --release --example embed -- [OUT.png]`

use anyhow::{Context, Result};
use cumulus::prepare::spawn_sites;
use cumulus::render::cloud_map::{CloudMap, CloudMapConfig};
use cumulus::render::cpu::camera::Camera;
use cumulus::render::gpu::{CloudRenderer, GpuContext};
use cumulus::scene::RenderSettings;
use cumulus::sim::{
    Atmosphere, Band, ParametricProfile, PhysicsConfig, ProjectedField, Simulation,
};
use glam::Vec3;

fn main() -> Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "embed.png".into());
    // The application's device (any wgpu device works; this one is headless).
    let ctx = GpuContext::new(wgpu::Backends::all()).context("a GPU adapter")?;
    let (device, queue) = (&ctx.device, &ctx.queue);
    let (width, height) = (320, 200);
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("app.target"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let target_view = target.create_view(&Default::default());

    // The physics, with parcels born on the cloud map's cells.
    let physics = PhysicsConfig {
        parcels: 85,
        ..PhysicsConfig::default()
    };
    let extent = physics.domain_size_m;
    let cloud_map = CloudMap::generate(&CloudMapConfig::default());
    let mut sim = Simulation::new(
        physics,
        Atmosphere::from_parametric(&ParametricProfile::FAIR_WEATHER),
    );
    sim.set_spawn_sites(spawn_sites(&cloud_map, extent));
    let band = Band {
        bottom_m: 600.0,
        top_m: 1600.0,
    };
    let mut field = ProjectedField::new(128, 128);

    // The renderer: settings from a scene's [render] table (its defaults,
    // with the sun moved), the band and the map's extent.
    let look = RenderSettings {
        sun_elevation_deg: 35.0,
        sun_azimuth_deg: 140.0,
        ..RenderSettings::default()
    };
    let settings = look.gpu_settings(band, extent);
    let mut clouds = CloudRenderer::new(device, queue, format, &settings, &cloud_map, None);
    clouds.resize(width, height);

    // Spin the sky up for 40 minutes, then animate 16 frames of 5 s each,
    // the camera turning slowly.
    for _ in 0..480 {
        sim.step();
    }
    for frame in 0..16 {
        sim.step();
        sim.project_into(&mut field, band);
        clouds.update_field(queue, &field);
        let camera = Camera {
            position_m: Vec3::new(0.0, 100.0, 0.0),
            yaw_deg: 20.0 + 0.2 * frame as f32,
            pitch_deg: 12.0,
            fov_deg: 60.0,
        };
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("app.frame"),
        });
        // ... the app's own passes would go here ...
        clouds.render(&mut encoder, &target_view, None, &camera)?;
        queue.submit([encoder.finish()]);
    }
    let rgba = ctx.read_texture(&target, 4)?;
    let rgb: Vec<u8> = rgba
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    let img = image::RgbImage::from_raw(width, height, rgb).context("image size")?;
    cumulus::io::write_png_atomically(std::path::Path::new(&out), &img)?;
    println!(
        "wrote {out} ({}; passes {})",
        ctx.describe(),
        clouds.last_passes().join(", ")
    );
    Ok(())
}
