//! The wgpu cloud renderer embedded in an application that owns its
//! device, its camera, its depth buffer and its target (the way vello or
//! wgpu's examples are embedded): the app steps the physics, hands the
//! projected field P to `CloudRenderer::update_field`, draws its own
//! geometry, and records `CloudRenderer::render` into its own command
//! encoder each frame, with its own view and projection matrices and its
//! depth buffer.
//!
//! The app here uses the conventions of many wgpu and Bevy programs: a
//! right-handed view matrix, a reversed-Z projection with an infinite far
//! plane (depth cleared to 0, compared with `Greater`). Its geometry is a
//! mountain 8 km away that rises through the cloud band: clouds behind it
//! are hidden, clouds in front of it are drawn over it. It renders
//! offscreen and saves the last frame.
//!
//! `cargo run --release --example embed -- [OUT.png]`

use anyhow::{Context, Result};
use cumulus::prepare::spawn_sites;
use cumulus::render::camera::View;
use cumulus::render::cloud_map::{CloudMap, CloudMapConfig};
use cumulus::render::gpu::{CloudRenderer, FrameUse, GpuContext};
use cumulus::scene::RenderSettings;
use cumulus::sim::{
    Atmosphere, Band, ParametricProfile, PhysicsConfig, ProjectedField, Simulation,
};
use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

const WIDTH: u32 = 320;
const HEIGHT: u32 = 200;
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

fn main() -> Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "embed.png".into());
    // The application's device (any adapter that can draw the clouds,
    // `requirements::check_adapter`; this one is headless; WGPU_BACKEND
    // narrows the search).
    let backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::all());
    let ctx = GpuContext::new(backends).context("a GPU adapter")?;
    let (device, queue) = (&ctx.device, &ctx.queue);
    let texture = |label, format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: WIDTH,
                height: HEIGHT,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let target = texture(
        "app.target",
        FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    // The renderer reads the app's depth buffer: it needs TEXTURE_BINDING.
    let depth = texture(
        "app.depth",
        DEPTH,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let (target_view, depth_view) = (
        target.create_view(&Default::default()),
        depth.create_view(&Default::default()),
    );
    let mountain = Mountain::new(device);

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
    let mut clouds = CloudRenderer::new(device, queue, FORMAT, &settings, &cloud_map, None)
        .context("the cloud renderer on this device")?;
    clouds.resize(WIDTH, HEIGHT);
    // Each `update_field` makes the light volume stale. Built whole, it
    // would cost the next frame a whole build (seconds on a software
    // adapter); built progressively, each frame traces one batch, a
    // quarter of the photons, and the light follows the clouds over a
    // few frames.
    clouds.set_progressive_light(true);
    // Compile the pipelines the frames below use (over the app's depth
    // buffer) now, not in the first frame.
    clouds.warm_up(&[FrameUse::Render { depth: true }]);

    // Spin the sky up for 40 minutes, then animate 16 frames of 5 s each,
    // the camera turning slowly.
    for _ in 0..480 {
        sim.step();
    }
    let aspect = WIDTH as f32 / HEIGHT as f32;
    let projection = Mat4::perspective_infinite_reverse_rh(60_f32.to_radians(), aspect, 0.5);
    let eye = Vec3::new(0.0, 100.0, 0.0);
    println!(
        "{}: 16 frames of {WIDTH}x{HEIGHT}, each a physics step, P and a light batch",
        ctx.describe()
    );
    for frame in 0..16 {
        let start = std::time::Instant::now();
        sim.step();
        sim.project_into(&mut field, band);
        clouds.update_field(queue, &field);
        // The app's camera: yaw from north (+z) toward east (+x), pitched up.
        let yaw = (20.0 + 0.2 * frame as f32).to_radians();
        let pitch = 6_f32.to_radians();
        let forward = Vec3::new(
            pitch.cos() * yaw.sin(),
            pitch.sin(),
            pitch.cos() * yaw.cos(),
        );
        let view_matrix = Mat4::look_to_rh(eye, forward, Vec3::Y);
        let view = View::new(view_matrix, projection).context("the app's camera")?;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("app.frame"),
        });
        // The app's own pass: its geometry into its colour and depth.
        mountain.draw(
            &mut encoder,
            queue,
            &target_view,
            &depth_view,
            projection * view_matrix,
        );
        // The clouds: over the sky where the depth is the far value (0
        // here), in front of the geometry elsewhere.
        clouds.render(&mut encoder, &target_view, Some(&depth_view), &view)?;
        queue.submit([encoder.finish()]);
        // Waits for the GPU, so the time below is the frame's (an
        // application would not wait).
        device.poll(wgpu::PollType::wait_indefinitely())?;
        println!(
            "frame {frame:>2}: {:>7.1} ms (physics, P, light batch, clouds; light volume builds so far: {})",
            start.elapsed().as_secs_f64() * 1e3,
            clouds.light_volume_builds().unwrap_or(0)
        );
    }
    let rgba = ctx.read_texture(&target, 4)?;
    let rgb: Vec<u8> = rgba
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    let img = image::RgbImage::from_raw(WIDTH, HEIGHT, rgb).context("image size")?;
    cumulus::io::write_png_atomically(std::path::Path::new(&out), &img)?;
    println!(
        "wrote {out} ({}; passes {})",
        ctx.describe(),
        clouds.last_passes().join(", ")
    );
    Ok(())
}

/// The app's geometry: a dark triangle of a mountain, 5 km wide at its
/// foot 8 km north-north-east of the camera and 1.9 km high, drawn
/// with reversed Z. Its corners are transformed on the CPU each frame
/// (clip-space vertices; the GPU clips them).
struct Mountain {
    pipeline: wgpu::RenderPipeline,
    vertices: wgpu::Buffer,
}

impl Mountain {
    fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("app.mountain"),
            source: wgpu::ShaderSource::Wgsl(
                "@vertex fn vs(@location(0) clip: vec4f) -> @builtin(position) vec4f { return clip; }
                 @fragment fn fs() -> @location(0) vec4f { return vec4f(0.035, 0.045, 0.03, 1.0); }"
                    .into(),
            ),
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("app.mountain"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 16,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x4],
                })],
            },
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH,
                depth_write_enabled: Some(true),
                // Reversed Z: nearer is larger.
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("app.mountain.vertices"),
            contents: &[0u8; 48],
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        });
        Self { pipeline, vertices }
    }

    fn draw(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        queue: &wgpu::Queue,
        target: &wgpu::TextureView,
        depth: &wgpu::TextureView,
        view_projection: Mat4,
    ) {
        let (east, north) = (2600.0, 7500.0);
        let corners = [
            Vec3::new(east - 2500.0, 0.0, north),
            Vec3::new(east + 2500.0, 0.0, north),
            Vec3::new(east, 1900.0, north),
        ];
        let clip: Vec<f32> = corners
            .iter()
            .flat_map(|p| (view_projection * p.extend(1.0)).to_array())
            .collect();
        queue.write_buffer(&self.vertices, 0, bytemuck::cast_slice(&clip));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("app.geometry"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    // Reversed Z: the far plane (here at infinity) is 0.
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.draw(0..3, 0..1);
    }
}
