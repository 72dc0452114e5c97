//! The egui side of the demo: the control panel, the debug views (P, the
//! cloud map, the parcels, the picked parcel's curves) and the timing
//! overlay.

use std::path::PathBuf;

use egui::{Color32, ColorImage, TextureHandle, TextureOptions};
use egui_plot::{Legend, Line, Plot, PlotPoints};

use crate::camera::{Bookmark, Controller, Mode};
use crate::world::World;

/// What the panel asks the app to do.
#[derive(Default)]
pub struct Actions {
    pub load: Option<PathBuf>,
    pub save: Option<PathBuf>,
    pub step: bool,
    pub panel_changed: bool,
}

/// Debug views shown, and their textures.
#[derive(Default)]
pub struct Views {
    pub show_p: bool,
    pub show_cloud_map: bool,
    pub show_parcels: bool,
    pub show_plot: bool,
    p_texture: Option<(TextureHandle, u64)>,
    cm_texture: Option<TextureHandle>,
}

/// Frame timings shown in the overlay, ms.
#[derive(Default, Clone, Copy)]
pub struct Timings {
    pub frame_ms: f64,
    pub physics_ms: f64,
    pub projection_ms: f64,
    /// GPU time of the cloud pass from timestamp queries (None: not supported).
    pub cloud_pass_ms: Option<f64>,
}

fn unit_slider<N: egui::emath::Numeric>(
    ui: &mut egui::Ui,
    value: &mut N,
    range: std::ops::RangeInclusive<N>,
    label: &str,
) -> bool {
    ui.add(egui::Slider::new(value, range).text(label))
        .changed()
}

/// The control panel.
#[allow(clippy::too_many_arguments)]
pub fn panel(
    ui: &mut egui::Ui,
    world: &mut World,
    camera: &mut Controller,
    views: &mut Views,
    scenes: &[PathBuf],
    message: &Option<String>,
    save_path: &mut String,
) -> Actions {
    let mut a = Actions::default();
    egui::ScrollArea::vertical().show(ui, |ui| {
        ui.heading("cumulus");
        ui.label(format!("scene: {}", world.path.display()));
        egui::ComboBox::from_label("scene file")
            .selected_text(
                world
                    .path
                    .file_name()
                    .map_or("?".into(), |n| n.to_string_lossy().into_owned()),
            )
            .show_ui(ui, |ui| {
                for s in scenes {
                    let name = s
                        .file_name()
                        .map_or("?".into(), |n| n.to_string_lossy().into_owned());
                    if ui.selectable_label(*s == world.path, name).clicked() {
                        a.load = Some(s.clone());
                    }
                }
            });
        ui.horizontal(|ui| {
            ui.text_edit_singleline(save_path);
            if ui.button("save scene").clicked() {
                a.save = Some(PathBuf::from(save_path.as_str()));
            }
        });
        if let Some(m) = message {
            ui.colored_label(Color32::from_rgb(255, 140, 90), m);
        }
        ui.separator();
        ui.label("Simulation");
        let t_min = world.time_s() / 60.0;
        let p = &mut world.panel;
        let mut ch = false;
        ch |= unit_slider(ui, &mut p.parcels, 0..=10_000, "parcels (restarts)");
        ch |= unit_slider(ui, &mut p.wind_speed_mps, 0.0..=30.0, "wind speed, m/s");
        ch |= unit_slider(
            ui,
            &mut p.wind_direction_deg,
            0.0..=360.0,
            "wind toward, ° from north",
        );
        ui.add(
            egui::Slider::new(&mut world.speed, 1.0..=600.0)
                .logarithmic(true)
                .text("speed, simulated s per s"),
        );
        ui.horizontal(|ui| {
            ui.checkbox(&mut world.paused, "pause");
            if ui.button("step (one dt)").clicked() {
                a.step = true;
            }
            ui.label(format!("t = {t_min:.1} min"));
        });
        ui.separator();
        ui.label("Clouds and light");
        ch |= unit_slider(ui, &mut p.coverage, 0.0..=1.0, "coverage, fraction");
        ch |= unit_slider(ui, &mut p.band_bottom_m, 0.0..=4000.0, "band bottom, m");
        ch |= unit_slider(ui, &mut p.band_top_m, 100.0..=8000.0, "band top, m");
        if p.band_top_m < p.band_bottom_m + 100.0 {
            p.band_top_m = p.band_bottom_m + 100.0;
        }
        ch |= unit_slider(
            ui,
            &mut p.sun_elevation_deg,
            -10.0..=90.0,
            "sun elevation, °",
        );
        ch |= unit_slider(
            ui,
            &mut p.sun_azimuth_deg,
            0.0..=360.0,
            "sun azimuth, ° from north",
        );
        ch |= ui
            .checkbox(&mut p.physical_sky, "physical sky (off: analytic)")
            .changed();
        ch |= unit_slider(
            ui,
            &mut p.aerosol_optical_depth,
            0.0..=1.5,
            "aerosol optical depth (haze)",
        );
        ch |= ui
            .add(
                egui::Slider::new(&mut p.exposure, 0.05..=20.0)
                    .logarithmic(true)
                    .text("exposure"),
            )
            .changed();
        ch |= ui
            .checkbox(&mut p.auto_exposure, "open the exposure below a 5° sun")
            .changed();
        ch |= unit_slider(ui, &mut p.sun_glare, 0.0..=3.0, "sun glare (0: off)");
        ui.separator();
        ui.label("Quality (off = the pass or code is not built)");
        ch |= ui
            .checkbox(&mut p.tsaa, "TSAA (temporal anti-aliasing)")
            .changed();
        ch |= unit_slider(ui, &mut p.steps, 1..=256, "ray steps");
        ch |= unit_slider(ui, &mut p.shadow_steps, 0..=32, "shadow steps (0: off)");
        ch |= unit_slider(ui, &mut p.octaves, 0..=3, "scattering octaves");
        ch |= ui.checkbox(&mut p.terrain, "terrain").changed();
        ch |= ui
            .checkbox(&mut p.fields, "fields and woods (off: plain land)")
            .changed();
        ch |= ui
            .checkbox(&mut p.fine_detail, "fine billows near the camera")
            .changed();
        a.panel_changed = ch;
        ui.separator();
        ui.label("Camera (drag: look/orbit, WASD/QE: fly, Shift: fast, wheel: speed/zoom)");
        ui.horizontal(|ui| {
            let mut mode = camera.mode;
            ui.radio_value(&mut mode, Mode::Fly, "fly");
            ui.radio_value(&mut mode, Mode::Orbit, "orbit");
            camera.set_mode(mode);
            if ui.button("reset").clicked() {
                camera.reset();
            }
        });
        for b in Bookmark::ALL {
            if ui.button(b.label()).clicked() {
                camera.go_to(b, world.band.bottom_m as f32, world.band.top_m as f32);
            }
        }
        ui.separator();
        ui.label("Debug views");
        ui.checkbox(&mut views.show_p, "P texture (coverage, height, fill)");
        ui.checkbox(&mut views.show_cloud_map, "cloud map");
        ui.checkbox(
            &mut views.show_parcels,
            "parcels (red: rising, blue: sinking; click picks)",
        );
        ui.checkbox(&mut views.show_plot, "picked parcel's curves");
    });
    a
}

/// The debug windows.
pub fn debug_views(ctx: &egui::Context, world: &mut World, views: &mut Views) {
    if views.show_p {
        let version = world.field_version;
        if views.p_texture.as_ref().is_none_or(|(_, v)| *v != version) {
            let f = &world.field;
            let px: Vec<Color32> = f
                .texels()
                .iter()
                .map(|t| {
                    Color32::from_rgb(
                        (t[0] * 255.0) as u8,
                        (t[1] * 255.0) as u8,
                        (t[2] * 255.0) as u8,
                    )
                })
                .collect();
            let img = ColorImage::new([f.width(), f.height()], px);
            match &mut views.p_texture {
                Some((h, v)) => {
                    h.set(img, TextureOptions::NEAREST);
                    *v = version;
                }
                None => {
                    views.p_texture =
                        Some((ctx.load_texture("P", img, TextureOptions::NEAREST), version))
                }
            }
        }
        if let Some((h, _)) = &views.p_texture {
            let id = h.id();
            egui::Window::new("P: coverage (R), height (G), fill (B)")
                .open(&mut views.show_p)
                .show(ctx, |ui| ui.image((id, egui::vec2(256.0, 256.0))));
        }
    }
    if views.show_cloud_map {
        let cm = &world.cloud_map;
        let h = views.cm_texture.get_or_insert_with(|| {
            let n = cm.size();
            let px: Vec<Color32> = cm
                .texels()
                .iter()
                .map(|t| Color32::from_rgb((t[0] * 255.0) as u8, (t[1] * 255.0) as u8, 0))
                .collect();
            ctx.load_texture(
                "cloud map",
                ColorImage::new([n, n], px),
                TextureOptions::LINEAR,
            )
        });
        let id = h.id();
        egui::Window::new("cloud map: shape (R), coarse (G)")
            .open(&mut views.show_cloud_map)
            .show(ctx, |ui| ui.image((id, egui::vec2(256.0, 256.0))));
    }
    if views.show_parcels {
        let mut open = true;
        egui::Window::new("parcels (top view)")
            .open(&mut open)
            .show(ctx, |ui| {
                let size = egui::vec2(256.0, 256.0);
                let (rect, response) = ui.allocate_exact_size(size, egui::Sense::click());
                let painter = ui.painter_at(rect);
                painter.rect_filled(rect, 0.0, Color32::from_gray(20));
                let l = world.scene.physics.domain_size_m;
                let p = world.sim.parcels();
                for i in 0..p.len() {
                    if !p.life[i].released() {
                        continue;
                    }
                    let b = p.diag[i].buoyancy;
                    let k = (b.abs() / 0.05).min(1.0) as f32;
                    let c = if b >= 0.0 {
                        Color32::from_rgb(255, (255.0 * (1.0 - k)) as u8, (255.0 * (1.0 - k)) as u8)
                    } else {
                        Color32::from_rgb((255.0 * (1.0 - k)) as u8, (255.0 * (1.0 - k)) as u8, 255)
                    };
                    let pos = rect.min
                        + egui::vec2(
                            (p.pos[i].x / l) as f32 * size.x,
                            (p.pos[i].y / l) as f32 * size.y,
                        );
                    let r = if p.diag[i].qc > 0.0 { 3.0 } else { 1.5 };
                    painter.circle_filled(pos, r, c);
                }
                if let Some((i, _)) = world.picked
                    && i < p.len()
                {
                    let pos = rect.min
                        + egui::vec2(
                            (p.pos[i].x / l) as f32 * size.x,
                            (p.pos[i].y / l) as f32 * size.y,
                        );
                    painter.circle_stroke(pos, 6.0, egui::Stroke::new(2.0, Color32::YELLOW));
                }
                if let Some(at) = response.interact_pointer_pos()
                    && response.clicked()
                {
                    let uv = (at - rect.min) / size;
                    world.pick(uv.x as f64, uv.y as f64);
                    views.show_plot = true;
                }
            });
        views.show_parcels = open;
    }
    if views.show_plot {
        let mut open = true;
        egui::Window::new("picked parcel (Fig. 5)")
            .open(&mut open)
            .show(ctx, |ui| {
                if world.picked.is_none() {
                    ui.label("Click a parcel in the parcels view.");
                    return;
                }
                let h = &world.history;
                let line = |name: &str, f: fn(&crate::world::Sample) -> f64| {
                    Line::new(
                        name.to_owned(),
                        PlotPoints::from_iter(h.iter().map(|s| [s.t_min, f(s)])),
                    )
                };
                ui.label("height, m");
                Plot::new("z")
                    .height(110.0)
                    .show(ui, |p| p.line(line("z, m", |s| s.z_m)));
                ui.label("vertical velocity w, m/s");
                Plot::new("w")
                    .height(110.0)
                    .show(ui, |p| p.line(line("w, m/s", |s| s.w_mps)));
                ui.label("θv of the parcel and of the environment, K");
                Plot::new("thv")
                    .height(110.0)
                    .legend(Legend::default())
                    .show(ui, |p| {
                        p.line(line("θv parcel", |s| s.theta_v_k));
                        p.line(line("θv environment", |s| s.theta_v_env_k));
                    });
                ui.label("cloud water qc, g/kg (x: simulated minutes)");
                Plot::new("qc")
                    .height(110.0)
                    .show(ui, |p| p.line(line("qc, g/kg", |s| s.qc_gkg)));
            });
        views.show_plot = open;
    }
}

/// The timing overlay in the top-right corner.
pub fn overlay(ctx: &egui::Context, t: &Timings, device: &str) {
    egui::Area::new(egui::Id::unique("timings"))
        .anchor(egui::Align2::RIGHT_TOP, egui::vec2(-10.0, 10.0))
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.label(format!(
                    "{:.0} fps ({:.1} ms)",
                    1000.0 / t.frame_ms.max(1e-3),
                    t.frame_ms
                ));
                ui.label(format!(
                    "physics {:.2} ms, projection {:.2} ms",
                    t.physics_ms, t.projection_ms
                ));
                ui.label(match t.cloud_pass_ms {
                    Some(ms) => format!("GPU cloud pass {ms:.2} ms"),
                    None => "GPU cloud pass: no timestamp queries".into(),
                });
                ui.small(device);
            });
        });
}
