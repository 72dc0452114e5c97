//! The landscape sky demo: hills under living cumulus, driven by the
//! parcel simulator and drawn by the wgpu cloud renderer, with egui
//! controls, debug views and a frame-timing overlay.
//!
//! ```sh
//! cargo run --release --example sky [-- --scene scenes/bomex.toml]
//! cargo run --release --example sky -- --screenshot shot.png --frames 60
//! ```
//!
//! `--screenshot FILE --frames N` renders N frames in a real window
//! (the simulation advancing a fixed 1/30 s of wall time per frame, so the
//! picture does not depend on the machine's speed), saves the last one
//! and exits. Without a GPU adapter it says how to install software Vulkan.

mod camera;
mod gfx;
mod screenshot;
mod ui;
mod world;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Parser;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::PhysicalKey;
use winit::window::{Window, WindowId};

use crate::camera::Controller;
use crate::gfx::{Gfx, settings_of};
use crate::world::World;

#[derive(Parser, Debug, Clone)]
#[command(about = "Living cumulus over a landscape (cumulus sky demo)")]
struct Args {
    /// Scene to start with.
    /// (A TOML file, or the name of a built-in shipped scene.)
    #[arg(long, default_value = "evening")]
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
    /// Start with the control panel hidden (F1 or its button toggles it;
    /// a window under 640 pixels wide starts with it hidden anyway).
    #[arg(long)]
    hide_panel: bool,
}

/// The control panel's width where the window has room, logical pixels.
const PANEL_WIDTH: f32 = 300.0;
/// The most of the window's width the panel takes.
const PANEL_SHARE: f32 = 0.4;
/// Windows narrower than this (logical pixels) start with the panel
/// hidden.
const PANEL_MIN_WINDOW: u32 = 640;

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
    /// The sea's clock, s: the viewer's time since the start (the waves
    /// move at their own pace whatever the physics' speed or pause).
    sea_clock_s: f64,
    frames_done: u32,
    dragging: bool,
    cursor: Option<(f64, f64)>,
    /// `World::field_version` of the P last uploaded (P and its coverage
    /// mask are uploaded only when they changed, not while paused).
    uploaded: Option<u64>,
    error: Option<anyhow::Error>,
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
            sea_clock_s: 0.0,
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
        let gfx = Gfx::new(window.clone(), &self.world)?;
        self.egui_state = Some(egui_winit::State::new(
            self.egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(gfx.ctx.device.limits().max_texture_dimension_2d as usize),
        ));
        self.gfx = Some(gfx);
        self.window = Some(window);
        Ok(())
    }

    fn resize(&mut self, width: u32, height: u32) {
        let Some(g) = &mut self.gfx else { return };
        g.clouds.resize(width, height);
        if width > 0 && height > 0 {
            g.config.width = width;
            g.config.height = height;
            g.surface.configure(&g.ctx.device, &g.config);
        }
    }

    fn load_scene(&mut self, path: &Path) {
        match World::load(path) {
            Ok(w) => {
                self.world = w;
                self.camera = Controller::new(self.world.scene.render.camera());
                self.views = ui::Views::default();
                // A new renderer holds the new P; if the device refused it,
                // the old renderer stays and gets the new P next frame.
                self.message = Some(
                    match self.gfx.as_mut().map(|g| g.rebuild_clouds(&self.world)) {
                        Some(Err(e)) => {
                            format!("loaded {}, but the renderer failed: {e}", path.display())
                        }
                        rebuilt => {
                            if rebuilt.is_some() {
                                self.uploaded = Some(self.world.field_version);
                            }
                            format!("loaded {}", path.display())
                        }
                    },
                );
            }
            // The old scene stays.
            Err(e) => self.message = Some(format!("could not load: {e}")),
        }
    }

    /// One frame: the clock, the UI and what it asked for, then the
    /// picture.
    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        self.advance();
        let Some(window) = self.window.clone() else {
            return Ok(());
        };
        let Some((actions, out)) = self.run_ui(&window) else {
            return Ok(());
        };
        self.apply(actions);
        self.draw(event_loop, &window, out)
    }

    /// Steps the clocks, the world and the camera by one frame: the wall
    /// time since the last (at most 0.25 s), or a fixed 1/30 s while
    /// taking a screenshot.
    fn advance(&mut self) {
        let now = Instant::now();
        let wall_dt = (now - self.last_frame).as_secs_f64();
        self.last_frame = now;
        let dt = if self.args.screenshot.is_some() {
            1.0 / 30.0
        } else {
            wall_dt.min(0.25)
        };
        self.timings.frame_ms = wall_dt * 1e3;
        self.sea_clock_s += dt;
        self.world.update(dt);
        self.camera.update(dt as f32);
        self.timings.physics_ms = self.world.physics_ms;
        self.timings.projection_ms = self.world.projection_ms;
    }

    /// The panel, the debug views and the overlay; what the user asked
    /// for, and what egui drew. `None` before egui is set up.
    fn run_ui(&mut self, window: &Window) -> Option<(ui::Actions, egui::FullOutput)> {
        let state = self.egui_state.as_mut()?;
        let raw = state.take_egui_input(window);
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
        let mut toggle_panel = false;
        let mut out = self.egui_ctx.run_ui(raw, |ui| {
            // The panel takes at most PANEL_SHARE of the window's width, so
            // a small window keeps most of its sky; hidden, a button (or
            // F1) brings it back.
            let width = ui.ctx().content_rect().width();
            let widest = (PANEL_SHARE * width).max(120.0);
            if show_panel {
                egui::Panel::left("controls")
                    .default_size(PANEL_WIDTH.min(widest))
                    .max_size(widest)
                    .show(ui, |ui| {
                        if ui.small_button("hide controls (F1)").clicked() {
                            toggle_panel = true;
                        }
                        // Scrolls when the window is shorter than the panel.
                        egui::ScrollArea::vertical().show(ui, |ui| {
                            actions =
                                ui::panel(ui, world, camera, views, scenes, message, save_path);
                        });
                    });
            }
            if !show_panel {
                egui::Area::new(egui::Id::unique("show controls"))
                    .fixed_pos(egui::pos2(6.0, 6.0))
                    .show(ui.ctx(), |ui| {
                        if ui.small_button("controls (F1)").clicked() {
                            toggle_panel = true;
                        }
                    });
            }
            ui::debug_views(ui.ctx(), world, views);
            ui::overlay(ui.ctx(), timings, &description);
        });
        state.handle_platform_output(window, std::mem::take(&mut out.platform_output));
        if toggle_panel {
            self.args.hide_panel = !self.args.hide_panel;
        }
        Some((actions, out))
    }

    /// Carries out what the panel asked for (load, save, one step) and
    /// hands the renderer what changed: its settings, the terrain, P.
    fn apply(&mut self, actions: ui::Actions) {
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
            return;
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
            g.clouds.update_field(&g.ctx.queue, &self.world.field);
            self.uploaded = Some(self.world.field_version);
        }
    }

    /// Draws the clouds and the UI into the window's surface and presents
    /// it; on a screenshot's last frame, saves it and ends the loop.
    fn draw(
        &mut self,
        event_loop: &ActiveEventLoop,
        window: &Window,
        out: egui::FullOutput,
    ) -> Result<()> {
        let screenshot = self.args.screenshot.is_some();
        let Some(g) = &mut self.gfx else {
            return Ok(());
        };
        // Nothing to draw into while minimised.
        let (width, height) = g.clouds.size();
        if width == 0 || height == 0 {
            return Ok(());
        }
        let frame = match g.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                g.surface.configure(&g.ctx.device, &g.config);
                return Ok(());
            }
            _ => return Ok(()),
        };
        // The renderer refuses a target of another size than its own; a
        // surface may hand one out before the resize event arrives.
        let size = (frame.texture.width(), frame.texture.height());
        if g.clouds.size() != size {
            g.clouds.resize(size.0, size.1);
        }
        let view = frame
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = g
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("sky.frame"),
            });
        g.clouds
            .set_timestamp_queries(g.timestamps.as_ref().map(|t| t.0.clone()));
        g.clouds.set_sea_time(self.sea_clock_s as f32);
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
        let extra = draw_egui(g, &self.egui_ctx, &mut encoder, &view, window, out);
        let last = screenshot && self.frames_done + 1 >= self.args.frames;
        g.ctx
            .queue
            .submit(extra.into_iter().chain([encoder.finish()]));
        if read_timestamps && let Some((_, _, read)) = &g.timestamps {
            let ticks = g.ctx.map_read(read)?;
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
        if last {
            // The frame is submitted and not yet presented: read it back.
            let path = self.args.screenshot.clone().unwrap_or_default();
            let (w, h) = screenshot::save(&g.ctx, &frame.texture, &path)?;
            println!(
                "wrote {} ({w}x{h}, {} frames, {})",
                path.display(),
                self.args.frames,
                g.description
            );
        }
        window.pre_present_notify();
        g.ctx.queue.present(frame);
        self.frames_done += 1;
        if screenshot {
            eprintln!("frame {} of {}", self.frames_done, self.args.frames);
        }
        if last {
            event_loop.exit();
        }
        Ok(())
    }
}

/// Records egui's `out` over the picture in `view`: its textures, its
/// buffers (the command buffers egui needs submitted first, returned) and
/// its render pass.
fn draw_egui(
    g: &mut Gfx,
    egui_ctx: &egui::Context,
    encoder: &mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
    window: &Window,
    out: egui::FullOutput,
) -> Vec<wgpu::CommandBuffer> {
    let screen = egui_wgpu::ScreenDescriptor {
        size_in_pixels: [g.config.width, g.config.height],
        pixels_per_point: window.scale_factor() as f32,
    };
    let jobs = egui_ctx.tessellate(out.shapes, screen.pixels_per_point);
    for (id, deltas) in &out.textures_delta.set {
        for delta in deltas {
            g.egui
                .update_texture(&g.ctx.device, &g.ctx.queue, *id, delta);
        }
    }
    let extra = g
        .egui
        .update_buffers(&g.ctx.device, &g.ctx.queue, encoder, &jobs, &screen);
    {
        let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("egui"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view,
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
    extra
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
    let mut args = Args::parse();
    // A small window keeps its sky: the panel starts hidden.
    args.hide_panel |= args.width < PANEL_MIN_WINDOW;
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
