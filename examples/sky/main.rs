//! The landscape sky demo: hills under living cumulus, driven by the
//! parcel simulator and drawn by the wgpu cloud renderer, with egui
//! controls, debug views and a frame-timing overlay.
//!
//! ```sh
//! cargo run --release --example sky [-- --scene scenes/evening.toml]
//! cargo run --release --example sky -- --screenshot shot.png --frames 60
//! ```
//!
//! `--screenshot FILE --frames N` renders N frames in a real window
//! (the simulation advancing a fixed 1/30 s of wall time per frame, so the
//! picture does not depend on the machine's speed), saves the last one
//! and exits. Without a GPU adapter it says how to install software Vulkan.

mod camera;
mod ui;
mod world;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result, anyhow};
use clap::Parser;
use cumulus::render::gpu::{CloudRenderer, GpuSettings};
use cumulus::render::prepare::gpu_settings;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::PhysicalKey;
use winit::window::{Window, WindowId};

use crate::camera::Controller;
use crate::world::World;

#[derive(Parser, Debug, Clone)]
#[command(about = "Living cumulus over a landscape (cumulus sky demo)")]
struct Args {
    /// Scene to start with.
    #[arg(long, default_value = "scenes/evening.toml")]
    scene: PathBuf,
    /// Render --frames frames, save the last one to this PNG, and exit.
    #[arg(long)]
    screenshot: Option<PathBuf>,
    /// Frames to render before the screenshot.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..=100000))]
    frames: u32,
    /// Window width, pixels.
    #[arg(long, default_value_t = 1280)]
    width: u32,
    /// Window height, pixels.
    #[arg(long, default_value_t = 720)]
    height: u32,
    /// Start with the control panel hidden (F1 toggles it).
    #[arg(long)]
    hide_panel: bool,
}

/// The GPU side: surface, device, the cloud renderer and egui's renderer.
struct Gfx {
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    clouds: CloudRenderer,
    egui: egui_wgpu::Renderer,
    /// Timestamp queries of the renderer's passes, when supported.
    timestamps: Option<(wgpu::QuerySet, wgpu::Buffer, wgpu::Buffer)>,
    period_ns: f64,
    description: String,
}

struct App {
    args: Args,
    window: Option<Arc<Window>>,
    gfx: Option<Gfx>,
    egui_ctx: egui::Context,
    egui_state: Option<egui_winit::State>,
    world: World,
    camera: Controller,
    views: ui::Views,
    timings: ui::Timings,
    message: Option<String>,
    scenes: Vec<PathBuf>,
    save_path: String,
    last_frame: Instant,
    frames_done: u32,
    dragging: bool,
    cursor: Option<(f64, f64)>,
    /// `World::field_version` of the P last uploaded (P and its coverage
    /// mask are uploaded only when they changed, not while paused).
    uploaded: Option<u64>,
    error: Option<anyhow::Error>,
}

fn settings_of(world: &World) -> GpuSettings {
    let r = &world.scene.render;
    gpu_settings(
        r,
        world.band,
        world.scene.physics.domain_size_m,
        r.quality(),
    )
}

impl App {
    fn new(args: Args) -> Result<Self> {
        let world = World::load(&args.scene)?;
        let camera = Controller::new(world.scene.render.camera());
        let dir = args.scene.parent().unwrap_or(Path::new(".")).to_owned();
        Ok(Self {
            scenes: world::scene_files(&dir),
            save_path: dir.join("my_sky.toml").display().to_string(),
            args,
            window: None,
            gfx: None,
            egui_ctx: egui::Context::default(),
            egui_state: None,
            world,
            camera,
            views: ui::Views::default(),
            timings: ui::Timings::default(),
            message: None,
            last_frame: Instant::now(),
            frames_done: 0,
            dragging: false,
            cursor: None,
            uploaded: None,
            error: None,
        })
    }

    fn init(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let window = Arc::new(
            event_loop.create_window(
                Window::default_attributes()
                    .with_title("cumulus: living clouds")
                    .with_inner_size(winit::dpi::PhysicalSize::new(
                        self.args.width,
                        self.args.height,
                    )),
            )?,
        );
        let backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::all());
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = backends;
        let instance = wgpu::Instance::new(desc);
        let surface = instance.create_surface(window.clone()).map_err(|e| {
            anyhow!(
                "no GPU adapter can draw to this window ({e}). Install a Vulkan driver (on Debian/Ubuntu, software Vulkan: `sudo apt-get install mesa-vulkan-drivers`), or use `cumulus render --backend cpu` for still pictures"
            )
        })?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: Some(&surface),
            apply_limit_buckets: false,
        }))
        .map_err(|_| {
            anyhow!(
                "no GPU adapter can draw to this window. Install a Vulkan driver (on Debian/Ubuntu, software Vulkan: `sudo apt-get install mesa-vulkan-drivers`), or use `cumulus render --backend cpu` for still pictures"
            )
        })?;
        let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("sky"),
            required_features: if timestamps {
                wgpu::Features::TIMESTAMP_QUERY
            } else {
                wgpu::Features::empty()
            },
            required_limits: wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits()),
            ..Default::default()
        }))
        .context("requesting a device")?;
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, size.width.max(1), size.height.max(1))
            .ok_or_else(|| anyhow!("the adapter cannot present to this window"))?;
        let caps = surface.get_capabilities(&adapter);
        if let Some(f) = caps.formats.iter().find(|f| f.is_srgb()) {
            config.format = *f;
        }
        if caps.usages.contains(wgpu::TextureUsages::COPY_SRC) {
            config.usage |= wgpu::TextureUsages::COPY_SRC;
        }
        if size.width > 0 && size.height > 0 {
            surface.configure(&device, &config);
        }
        let mut clouds = CloudRenderer::new(
            &device,
            &queue,
            config.format,
            &settings_of(&self.world),
            &self.world.cloud_map,
            self.world.terrain.as_ref(),
        );
        clouds.update_field(&queue, &self.world.field);
        clouds.resize(size.width, size.height);
        let ts = timestamps.then(|| {
            let q = device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("sky.timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 8,
            });
            let buf = |label, usage| {
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: 64,
                    usage,
                    mapped_at_creation: false,
                })
            };
            (
                q,
                buf(
                    "sky.timestamps.resolve",
                    wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                ),
                buf(
                    "sky.timestamps.read",
                    wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                ),
            )
        });
        let egui = egui_wgpu::Renderer::new(
            &device,
            config.format,
            egui_wgpu::RendererOptions::default(),
        );
        self.egui_state = Some(egui_winit::State::new(
            self.egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(device.limits().max_texture_dimension_2d as usize),
        ));
        let info = adapter.get_info();
        self.gfx = Some(Gfx {
            period_ns: queue.get_timestamp_period() as f64,
            surface,
            device,
            queue,
            config,
            clouds,
            egui,
            timestamps: ts,
            description: format!("{} ({:?})", info.name, info.backend),
        });
        self.window = Some(window);
        Ok(())
    }

    fn resize(&mut self, width: u32, height: u32) {
        let Some(g) = &mut self.gfx else { return };
        g.clouds.resize(width, height);
        if width > 0 && height > 0 {
            g.config.width = width;
            g.config.height = height;
            g.surface.configure(&g.device, &g.config);
        }
    }

    fn load_scene(&mut self, path: &Path) {
        match World::load(path) {
            Ok(w) => {
                self.world = w;
                self.camera = Controller::new(self.world.scene.render.camera());
                self.views = ui::Views::default();
                if let Some(g) = &mut self.gfx {
                    let (width, height) = g.clouds.size();
                    g.clouds = CloudRenderer::new(
                        &g.device,
                        &g.queue,
                        g.config.format,
                        &settings_of(&self.world),
                        &self.world.cloud_map,
                        self.world.terrain.as_ref(),
                    );
                    g.clouds.update_field(&g.queue, &self.world.field);
                    self.uploaded = Some(self.world.field_version);
                    g.clouds.resize(width, height);
                }
                self.message = Some(format!("loaded {}", path.display()));
            }
            // The old scene stays.
            Err(e) => self.message = Some(format!("could not load: {e}")),
        }
    }

    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let now = Instant::now();
        let wall_dt = (now - self.last_frame).as_secs_f64();
        self.last_frame = now;
        let screenshot = self.args.screenshot.is_some();
        let dt = if screenshot {
            1.0 / 30.0
        } else {
            wall_dt.min(0.25)
        };
        self.timings.frame_ms = wall_dt * 1e3;
        self.world.update(dt);
        self.camera.update(dt as f32);
        self.timings.physics_ms = self.world.physics_ms;
        self.timings.projection_ms = self.world.projection_ms;
        let (Some(window), Some(state)) = (self.window.clone(), self.egui_state.as_mut()) else {
            return Ok(());
        };

        // The UI.
        let raw = state.take_egui_input(&window);
        let mut actions = ui::Actions::default();
        let description = self
            .gfx
            .as_ref()
            .map_or(String::new(), |g| g.description.clone());
        let (world, camera, views, scenes, message, save_path, timings) = (
            &mut self.world,
            &mut self.camera,
            &mut self.views,
            &self.scenes,
            &self.message,
            &mut self.save_path,
            &self.timings,
        );
        let show_panel = !self.args.hide_panel;
        let out = self.egui_ctx.run_ui(raw, |ui| {
            if show_panel {
                egui::Panel::left("controls")
                    .default_size(300.0)
                    .show(ui, |ui| {
                        actions = ui::panel(ui, world, camera, views, scenes, message, save_path);
                    });
            }
            ui::debug_views(ui.ctx(), world, views);
            ui::overlay(ui.ctx(), timings, &description);
        });
        state.handle_platform_output(&window, out.platform_output);
        if let Some(p) = actions.load {
            self.load_scene(&p);
        }
        if let Some(p) = actions.save {
            self.message = Some(match self.world.scene.save(&p) {
                Ok(()) => format!("saved {}", p.display()),
                Err(e) => format!("could not save: {e}"),
            });
        }
        if actions.step {
            self.world.advance(self.world.scene.physics.dt_s);
        }
        let Some(g) = &mut self.gfx else {
            return Ok(());
        };
        if actions.panel_changed {
            let changes = self.world.apply_panel();
            if changes.terrain {
                g.clouds.set_terrain(self.world.terrain.as_ref());
            }
            if changes.settings {
                g.clouds.set_settings(&settings_of(&self.world));
            }
        }
        if self.uploaded != Some(self.world.field_version) {
            g.clouds.update_field(&g.queue, &self.world.field);
            self.uploaded = Some(self.world.field_version);
        }

        // Nothing to draw into while minimised.
        let (width, height) = g.clouds.size();
        if width == 0 || height == 0 {
            return Ok(());
        }
        let frame = match g.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                g.surface.configure(&g.device, &g.config);
                return Ok(());
            }
            _ => return Ok(()),
        };
        let view = frame
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = g
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("sky.frame"),
            });
        g.clouds
            .set_timestamp_queries(g.timestamps.as_ref().map(|t| t.0.clone()));
        g.clouds
            .render(&mut encoder, &view, None, &self.camera.camera)?;
        let read_timestamps = g.timestamps.is_some() && self.frames_done.is_multiple_of(30);
        if let Some((q, resolve, read)) = &g.timestamps {
            let n = 2 * g.clouds.last_passes().len() as u32;
            if n > 0 {
                encoder.resolve_query_set(q, 0..n, resolve, 0);
                if read_timestamps {
                    encoder.copy_buffer_to_buffer(resolve, 0, read, 0, 64);
                }
            }
        }

        // egui on top.
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [g.config.width, g.config.height],
            pixels_per_point: window.scale_factor() as f32,
        };
        let jobs = self
            .egui_ctx
            .tessellate(out.shapes, screen.pixels_per_point);
        for (id, deltas) in &out.textures_delta.set {
            for delta in deltas {
                g.egui.update_texture(&g.device, &g.queue, *id, delta);
            }
        }
        let extra = g
            .egui
            .update_buffers(&g.device, &g.queue, &mut encoder, &jobs, &screen);
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("egui"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            g.egui.render(&mut pass.forget_lifetime(), &jobs, &screen);
        }
        for id in &out.textures_delta.free {
            g.egui.free_texture(id);
        }
        let last = screenshot && self.frames_done + 1 >= self.args.frames;
        let readback = last.then(|| {
            let w = frame.texture.width();
            let h = frame.texture.height();
            let row = (4 * w).div_ceil(256) * 256;
            let buf = g.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("sky.screenshot"),
                size: row as u64 * h as u64,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            encoder.copy_texture_to_buffer(
                frame.texture.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer: &buf,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(row),
                        rows_per_image: Some(h),
                    },
                },
                frame.texture.size(),
            );
            (buf, row, w, h)
        });
        g.queue.submit(extra.into_iter().chain([encoder.finish()]));
        if read_timestamps && let Some((_, _, read)) = &g.timestamps {
            let ticks = map_read(&g.device, read)?;
            let t: &[u64] = bytemuck::cast_slice(&ticks);
            // The cloud pass is the first pass, or the second after terrain.
            let k = g
                .clouds
                .last_passes()
                .iter()
                .position(|p| *p == "clouds")
                .unwrap_or(0);
            self.timings.cloud_pass_ms =
                Some(t[2 * k + 1].saturating_sub(t[2 * k]) as f64 * g.period_ns * 1e-6);
        }
        if let Some((buf, row, w, h)) = readback {
            let data = map_read(&g.device, &buf)?;
            let bgra = matches!(
                g.config.format,
                wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
            );
            let mut rgb = Vec::with_capacity((w * h * 3) as usize);
            for y in 0..h as usize {
                for px in data[y * row as usize..][..4 * w as usize].chunks_exact(4) {
                    if bgra {
                        rgb.extend([px[2], px[1], px[0]]);
                    } else {
                        rgb.extend([px[0], px[1], px[2]]);
                    }
                }
            }
            let img = image::RgbImage::from_raw(w, h, rgb).context("screenshot size")?;
            let path = self.args.screenshot.clone().unwrap_or_default();
            cumulus::io::write_png_atomically(&path, &img)
                .with_context(|| format!("{}: cannot write", path.display()))?;
            println!(
                "wrote {} ({w}x{h}, {} frames, {})",
                path.display(),
                self.args.frames,
                g.description
            );
        }
        window.pre_present_notify();
        g.queue.present(frame);
        self.frames_done += 1;
        if last {
            event_loop.exit();
        }
        Ok(())
    }
}

/// Maps `buffer` for reading and waits.
fn map_read(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    let slice = buffer.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device.poll(wgpu::PollType::wait_indefinitely())?;
    rx.recv()??;
    let v = slice.get_mapped_range()?.to_vec();
    buffer.unmap();
    Ok(v)
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_none()
            && let Err(e) = self.init(event_loop)
        {
            self.error = Some(e);
            event_loop.exit();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(window) = self.window.clone() else {
            return;
        };
        let consumed = self
            .egui_state
            .as_mut()
            .is_some_and(|s| s.on_window_event(&window, &event).consumed);
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => self.resize(size.width, size.height),
            WindowEvent::KeyboardInput { event, .. }
                if !self.egui_ctx.egui_wants_keyboard_input() =>
            {
                if let PhysicalKey::Code(code) = event.physical_key {
                    let down = event.state == ElementState::Pressed;
                    if code == winit::keyboard::KeyCode::F1 && down {
                        self.args.hide_panel = !self.args.hide_panel;
                    }
                    self.camera.key(code, down);
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.dragging = state == ElementState::Pressed
                    && !consumed
                    && !self.egui_ctx.egui_wants_pointer_input();
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let Some((x, y)) = self.cursor
                    && self.dragging
                {
                    self.camera
                        .drag((position.x - x) as f32, (position.y - y) as f32);
                }
                self.cursor = Some((position.x, position.y));
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.camera.scroll(lines);
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.frame(event_loop) {
                    self.error = Some(e);
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(w) = &self.window {
            w.request_redraw();
        }
    }
}

fn main() -> Result<()> {
    let args = Args::parse();
    let mut app = App::new(args).context("loading the scene")?;
    let event_loop = EventLoop::new().context(
        "no display to open a window on (set DISPLAY, or run under `xvfb-run`); for still pictures use `cumulus render`",
    )?;
    event_loop.run_app(&mut app)?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
