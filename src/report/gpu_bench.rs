//! `cumulus bench`: GPU frame times across resolution, coverage, parcel
//! count and features, for the cloud-map renderer and the per-parcel
//! baseline; the physics' share of the frame; and rendering error against
//! run time. Results as CSV, JSON and plots.

use std::path::Path;
use std::time::Instant;

use serde::Serialize;

use super::ReportError;
use super::plot::{Series, bars_png, loglog_png};
use crate::io::write_atomically;
use crate::render::cpu::renderer::{RenderSettings, render_linear, to_srgb8};
use crate::render::gpu::baseline::{BaselineRenderer, spheres};
use crate::render::gpu::headless::TARGET_FORMAT;
use crate::render::gpu::timer::{FrameTimes, time_frames};
use crate::render::gpu::{GpuContext, GpuError, Headless, textures};
use crate::render::prepare::Prepared;
use crate::scene::{Scene, SceneError};
use crate::sim::{ProjectedField, Simulation};

/// Errors of the benchmark.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Report(#[from] ReportError),
}

/// What to run.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// Tiny images and few frames (for CI): every configuration still runs.
    pub quick: bool,
    /// Timed frames per configuration.
    pub frames: u32,
    /// Untimed frames first.
    pub warmup: u32,
    /// A configuration whose single frame is predicted to take longer than
    /// this (from the previous parcel count, the cost being linear) is
    /// skipped and reported as skipped, s.
    pub max_frame_s: f64,
}

/// Coverages of the cloud-map paper's Table 1.
pub const COVERAGES: [f32; 4] = [0.91, 0.71, 0.51, 0.10];
/// Parcel counts (12: the paper; 85: Goswami & Neyret 2017).
pub const PARCELS: [usize; 4] = [12, 85, 1_000, 10_000];
/// Resolutions of the full run.
pub const RESOLUTIONS: [(u32, u32); 3] = [(640, 480), (1280, 720), (1920, 1080)];

/// One timed configuration.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    pub group: &'static str,
    pub renderer: &'static str,
    pub width: u32,
    pub height: u32,
    pub coverage: f32,
    pub parcels: usize,
    pub tsaa: bool,
    pub terrain: bool,
    pub shadow_steps: u32,
    pub octaves: u32,
    pub detail: bool,
    pub frames: u32,
    /// Fraction of P's texels with coverage.
    pub p_covered: f64,
    pub median_ms: f64,
    pub p95_ms: f64,
    /// "gpu" (timestamp queries) or "wall" (CPU wall time, submit to idle);
    /// "skipped" when the frame was predicted too slow to run.
    pub timing: &'static str,
}

/// Physics, projection and upload against the frame, per parcel count.
#[derive(Debug, Clone, Serialize)]
pub struct PhysicsRow {
    pub parcels: usize,
    pub physics_ms: f64,
    pub projection_ms: f64,
    pub upload_ms: f64,
    pub frame_ms: f64,
    /// (physics + projection + upload) / frame, %.
    pub share_pct: f64,
}

/// Rendering error against run time: one knob varied, the others at the
/// scene's defaults.
#[derive(Debug, Clone, Serialize)]
pub struct QualityRow {
    pub knob: &'static str,
    pub value: u32,
    /// GPU time per frame (times `value` for TSAA frames), ms.
    pub ms: f64,
    /// Mean absolute error of the image (0..1) against the CPU reference.
    pub mean_error: f64,
    pub is_default: bool,
}

/// The whole benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub adapter: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    pub driver_info: String,
    pub timing: &'static str,
    pub quick: bool,
    pub rows: Vec<Row>,
    pub physics: Vec<PhysicsRow>,
    pub quality: Vec<QualityRow>,
    /// Quality images' size.
    pub quality_size: [u32; 2],
}

impl Report {
    /// The cloud-map against baseline speed ratio at `parcels` (baseline
    /// ms / cloud-map ms), when both ran.
    pub fn ratio_at(&self, parcels: usize) -> Option<f64> {
        let find = |r: &str| {
            self.rows
                .iter()
                .find(|x| {
                    x.group == "parcels"
                        && x.renderer == r
                        && x.parcels == parcels
                        && x.timing != "skipped"
                })
                .map(|x| x.median_ms)
        };
        Some(find("per_parcel")? / find("cloud_map")?)
    }
}

fn median(v: &mut [f64]) -> f64 {
    FrameTimes::quantile(v, 0.5)
}

/// The base scene with `parcels` parcels at the base scene's parcel
/// density: the domain, and the cloud map's cells with it, grow as
/// `sqrt(parcels)`, so the sky looks alike (the same cloud cover and cell
/// size) and only the number of parcels behind it changes. Held at one
/// density, the frame cost compares like with like; packing 10,000
/// parcels into the base domain would cover the whole sky instead.
pub fn scaled_scene(base: &Scene, parcels: usize) -> Scene {
    let mut sc = base.clone();
    let f = (parcels as f64 / base.physics.parcels.max(1) as f64).sqrt();
    sc.physics.parcels = parcels;
    sc.physics.domain_size_m = base.physics.domain_size_m * f;
    let cm = &mut sc.render.cloud_map;
    cm.cells = (cm.cells * f).clamp(1.0, 64.0);
    cm.detail = (cm.detail * f).clamp(1.0, 256.0);
    cm.size = ((cm.size as f64 * f) as usize).clamp(64, 2048);
    sc
}

/// A change of a scene's `[render]` settings.
type Tweak = fn(&mut RenderSettings);

/// A quality knob: name, values, default, reference value, setter.
type Knob = (
    &'static str,
    Vec<u32>,
    u32,
    u32,
    fn(&mut RenderSettings, u32),
);

/// A scene prepared with `parcels` parcels ([`scaled_scene`]).
fn prepare(base: &Scene, parcels: usize) -> Result<(Scene, Prepared), SceneError> {
    let sc = scaled_scene(base, parcels);
    let p = Prepared::from_scene(&sc, || {})?;
    Ok((sc, p))
}

struct Features {
    tsaa: bool,
    terrain: bool,
    shadow_steps: u32,
    octaves: u32,
    detail: bool,
}

fn features_of(r: &RenderSettings) -> Features {
    Features {
        tsaa: r.tsaa,
        terrain: r.terrain.enabled,
        shadow_steps: r.shadow_steps,
        octaves: r.octaves,
        detail: r.detail_strength > 0.0,
    }
}

/// Times the cloud-map renderer on `p` with `r`.
fn time_cloud_map(
    ctx: &GpuContext,
    p: &Prepared,
    r: &RenderSettings,
    o: &BenchOptions,
) -> Result<FrameTimes, GpuError> {
    let mut hl = Headless::new(ctx, p, &p.gpu_settings(r, r.quality()), r.width, r.height)?;
    hl.time_frames(ctx, &r.camera(), o.warmup, o.frames)
}

/// Times the per-parcel baseline on `p`'s parcels with `r`.
fn time_baseline(
    ctx: &GpuContext,
    sc: &Scene,
    p: &Prepared,
    r: &RenderSettings,
    o: &BenchOptions,
) -> Result<FrameTimes, GpuError> {
    let settings = p.gpu_settings(r, r.quality());
    let mut b = BaselineRenderer::new(&ctx.device, &ctx.queue, TARGET_FORMAT, &settings);
    b.update_spheres(&spheres(
        &p.parcels,
        sc.physics.fill_full_condensed_fraction,
    ));
    b.resize(r.width, r.height);
    let target = textures::create_2d(
        &ctx.device,
        "bench.target",
        r.width,
        r.height,
        TARGET_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let view = target.create_view(&Default::default());
    let camera = r.camera();
    time_frames(ctx, o.warmup, o.frames, |enc, q| {
        b.render(enc, &view, &camera, q);
        Ok(1)
    })
}

fn row(
    group: &'static str,
    renderer: &'static str,
    r: &RenderSettings,
    p: &Prepared,
    t: Option<&FrameTimes>,
    frames: u32,
) -> Row {
    let f = features_of(r);
    Row {
        group,
        renderer,
        width: r.width,
        height: r.height,
        coverage: r.coverage,
        parcels: p.parcels.len(),
        tsaa: f.tsaa,
        terrain: f.terrain,
        shadow_steps: f.shadow_steps,
        octaves: f.octaves,
        detail: f.detail,
        frames: if t.is_some() { frames } else { 0 },
        p_covered: p.field.covered_fraction(),
        median_ms: t.map_or(f64::NAN, FrameTimes::median),
        p95_ms: t.map_or(f64::NAN, FrameTimes::p95),
        timing: t.map_or("skipped", FrameTimes::source),
    }
}

/// Runs the benchmark on `base` (the scene whose defaults every
/// configuration starts from); `progress` gets a line per configuration.
pub fn run(
    ctx: &GpuContext,
    base: &Scene,
    o: &BenchOptions,
    mut progress: impl FnMut(&str),
) -> Result<Report, BenchError> {
    let mut base = base.clone();
    let (w0, h0) = if o.quick { (64, 48) } else { (640, 480) };
    base.render.width = w0;
    base.render.height = h0;
    let resolutions: Vec<(u32, u32)> = if o.quick {
        vec![(64, 48), (96, 72)]
    } else {
        RESOLUTIONS.to_vec()
    };
    let mut rows = Vec::new();
    let sc = base.clone();
    let p = Prepared::from_scene(&sc, || {})?;

    for &(w, h) in &resolutions {
        let r = RenderSettings {
            width: w,
            height: h,
            ..sc.render.clone()
        };
        progress(&format!("resolution {w}x{h}"));
        let t = time_cloud_map(ctx, &p, &r, o)?;
        rows.push(row("resolution", "cloud_map", &r, &p, Some(&t), o.frames));
    }
    for c in COVERAGES {
        let r = RenderSettings {
            coverage: c,
            ..sc.render.clone()
        };
        progress(&format!("coverage {c}"));
        let t = time_cloud_map(ctx, &p, &r, o)?;
        rows.push(row("coverage", "cloud_map", &r, &p, Some(&t), o.frames));
    }
    let variants: [(&str, Tweak); 6] = [
        ("defaults", |_| {}),
        ("tsaa off", |r| r.tsaa = false),
        ("terrain on", |r| r.terrain.enabled = true),
        ("shadows off", |r| r.shadow_steps = 0),
        ("octaves 0", |r| r.octaves = 0),
        ("detail off", |r| r.detail_strength = 0.0),
    ];
    for (name, f) in variants {
        let mut s2 = sc.clone();
        f(&mut s2.render);
        progress(&format!("features: {name}"));
        let p2 = if s2.render.terrain.enabled {
            Prepared::from_scene(&s2, || {})?
        } else {
            Prepared::from_scene(&sc, || {})?
        };
        let t = time_cloud_map(ctx, &p2, &s2.render, o)?;
        rows.push(row(
            "features",
            "cloud_map",
            &s2.render,
            &p2,
            Some(&t),
            o.frames,
        ));
    }

    let mut physics = Vec::new();
    let mut last_baseline: Option<(usize, f64)> = None;
    for n in PARCELS {
        let (scn, pn) = prepare(&base, n)?;
        let r = &scn.render;
        progress(&format!("parcels {n}: cloud map"));
        let t = time_cloud_map(ctx, &pn, r, o)?;
        let frame_ms = t.median();
        rows.push(row("parcels", "cloud_map", r, &pn, Some(&t), o.frames));
        let predicted_s = last_baseline.map(|(m, ms)| ms * n as f64 / m as f64 * 1e-3);
        if predicted_s.is_some_and(|s| s > o.max_frame_s) {
            progress(&format!(
                "parcels {n}: per-parcel baseline skipped (predicted {:.0} s a frame)",
                predicted_s.unwrap_or(0.0)
            ));
            rows.push(row("parcels", "per_parcel", r, &pn, None, 0));
        } else {
            progress(&format!("parcels {n}: per-parcel baseline"));
            let tb = time_baseline(ctx, &scn, &pn, r, o)?;
            last_baseline = Some((n, tb.median()));
            rows.push(row("parcels", "per_parcel", r, &pn, Some(&tb), o.frames));
        }
        physics.push(physics_in_frame(
            ctx,
            &scn,
            n,
            frame_ms,
            if o.quick { 3 } else { 20 },
        )?);
    }
    progress("render error against run time");
    let (quality, quality_size) = quality_sweep(ctx, &sc, &p, o)?;
    let timing = rows
        .iter()
        .find(|r| r.timing != "skipped")
        .map_or("wall", |r| r.timing);
    let i = &ctx.adapter_info;
    Ok(Report {
        adapter: i.name.clone(),
        backend: format!("{:?}", i.backend),
        device_type: format!("{:?}", i.device_type),
        driver: i.driver.clone(),
        driver_info: i.driver_info.clone(),
        timing,
        quick: o.quick,
        rows,
        physics,
        quality,
        quality_size,
    })
}

/// Physics step, projection and upload, each the median of `samples`
/// frames of a simulation spun up for the scene's `time_s` (CPU wall time).
fn physics_in_frame(
    ctx: &GpuContext,
    sc: &Scene,
    parcels: usize,
    frame_ms: f64,
    samples: usize,
) -> Result<PhysicsRow, BenchError> {
    let atm = sc.atmosphere(None)?;
    let band = sc.band(&atm);
    let mut sim = Simulation::new(sc.physics.clone(), atm);
    for _ in 0..Prepared::frames(sc).min(240) {
        sim.step();
    }
    let mut quick = sc.clone();
    quick.render.time_s = 0.0;
    let p = Prepared::from_scene(&quick, || {})?;
    let mut hl = Headless::new(
        ctx,
        &p,
        &p.gpu_settings(&sc.render, sc.render.quality()),
        8,
        8,
    )?;
    let mut field = ProjectedField::new(sc.projection.width, sc.projection.height);
    let (mut step, mut project, mut upload) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..samples {
        let t = Instant::now();
        sim.step();
        step.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        field.project(
            sim.parcels(),
            sc.physics.domain_size_m,
            band,
            sc.physics.fill_full_condensed_fraction,
        );
        project.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        hl.renderer.update_field(&ctx.queue, &field);
        ctx.queue.submit([]);
        ctx.wait()?;
        upload.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let (s, pr, u) = (median(&mut step), median(&mut project), median(&mut upload));
    Ok(PhysicsRow {
        parcels,
        physics_ms: s,
        projection_ms: pr,
        upload_ms: u,
        frame_ms,
        share_pct: 100.0 * (s + pr + u) / frame_ms,
    })
}

/// Mean absolute difference of two 8-bit images, 0..1.
pub fn mean_abs_diff(a: &[u8], b: &[u8]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| x.abs_diff(*y) as f64)
        .sum::<f64>()
        / (255.0 * a.len().max(1) as f64)
}

/// A CPU reference image: `steps` steps, 2x2 samples per pixel (box
/// filter, what TSAA converges to), tone-mapped to sRGB8.
fn reference(p: &Prepared, r: &RenderSettings, steps: u32) -> Vec<u8> {
    let mut q = r.quality();
    q.steps = steps;
    let (w, h, s) = (r.width, r.height, 2);
    let fine = render_linear(w * s, h * s, &p.frame(r, q));
    let mut out = vec![glam::Vec3::ZERO; (w * h) as usize];
    for y in 0..h * s {
        for x in 0..w * s {
            out[((y / s) * w + x / s) as usize] += fine[(y * w * s + x) as usize] / (s * s) as f32;
        }
    }
    to_srgb8(&out, q.exposure)
}

fn quality_sweep(
    ctx: &GpuContext,
    sc: &Scene,
    p: &Prepared,
    o: &BenchOptions,
) -> Result<(Vec<QualityRow>, [u32; 2]), BenchError> {
    let (w, h) = if o.quick { (32, 24) } else { (160, 120) };
    let d = RenderSettings {
        width: w,
        height: h,
        tsaa: false,
        ..sc.render.clone()
    };
    let ref_steps = if o.quick { 128 } else { 512 };
    let mut out = Vec::new();
    let gpu_image = |r: &RenderSettings, frames: u32| -> Result<(Vec<u8>, f64), GpuError> {
        let mut hl = Headless::new(ctx, p, &p.gpu_settings(r, r.quality()), w, h)?;
        hl.render(ctx, &r.camera(), frames)?;
        let img = hl.read_rgb8(ctx)?;
        let t = hl.time_frames(ctx, &r.camera(), 1, o.frames.min(5))?;
        Ok((img, t.median()))
    };
    // Steps, shadow steps and octaves: each against a reference with that
    // knob high and the rest at the defaults.
    let knobs: [Knob; 3] = [
        (
            "steps",
            vec![8, 16, 32, 48, 64, 128],
            d.steps,
            ref_steps,
            |r, v| r.steps = v,
        ),
        (
            "shadow_steps",
            vec![0, 2, 4, 6, 8, 12],
            d.shadow_steps,
            32,
            |r, v| r.shadow_steps = v,
        ),
        ("octaves", vec![0, 1, 2, 3], d.octaves, 3, |r, v| {
            r.octaves = v
        }),
    ];
    for (knob, values, default, ref_value, set) in knobs {
        let mut rr = d.clone();
        set(&mut rr, ref_value);
        let reference = reference(
            p,
            &rr,
            if knob == "steps" {
                ref_steps
            } else {
                rr.steps.max(256)
            },
        );
        for v in values {
            let mut r = d.clone();
            set(&mut r, v);
            let (img, ms) = gpu_image(&r, 1)?;
            out.push(QualityRow {
                knob,
                value: v,
                ms,
                mean_error: mean_abs_diff(&img, &reference),
                is_default: v == default,
            });
        }
    }
    // TSAA: frames accumulated at the default steps, against the
    // high-step reference; the cost is the frames' total time.
    let reference = reference(p, &d, ref_steps);
    let t = RenderSettings {
        tsaa: true,
        ..d.clone()
    };
    for frames in [1, 2, 4, 8, 16, 32] {
        let (img, ms) = gpu_image(&t, frames)?;
        out.push(QualityRow {
            knob: "tsaa_frames",
            value: frames,
            ms: ms * frames as f64,
            mean_error: mean_abs_diff(&img, &reference),
            is_default: frames == 32,
        });
    }
    Ok((out, [w, h]))
}

/// Writes `bench.csv`, `physics_in_frame.csv`, `render_error.csv`,
/// `bench.json` and the plots into `dir`.
pub fn write(report: &Report, dir: &Path) -> Result<(), ReportError> {
    let werr = |path: &Path| {
        let path = path.to_owned();
        move |source| ReportError::Write { path, source }
    };
    let path = dir.join("bench.csv");
    write_atomically(&path, |out| {
        writeln!(out, "group,renderer,width,height,coverage,parcels,tsaa,terrain,shadow_steps,octaves,detail,frames,p_covered,median_ms,p95_ms,timing")?;
        for r in &report.rows {
            writeln!(
                out,
                "{},{},{},{},{},{},{},{},{},{},{},{},{:.4},{:.4},{:.4},{}",
                r.group, r.renderer, r.width, r.height, r.coverage, r.parcels, r.tsaa, r.terrain, r.shadow_steps, r.octaves, r.detail, r.frames, r.p_covered, r.median_ms, r.p95_ms, r.timing
            )?;
        }
        Ok(())
    })
    .map_err(werr(&path))?;
    let path = dir.join("physics_in_frame.csv");
    write_atomically(&path, |out| {
        writeln!(
            out,
            "parcels,physics_ms,projection_ms,upload_ms,frame_ms,share_pct"
        )?;
        for r in &report.physics {
            writeln!(
                out,
                "{},{:.4},{:.4},{:.4},{:.4},{:.3}",
                r.parcels, r.physics_ms, r.projection_ms, r.upload_ms, r.frame_ms, r.share_pct
            )?;
        }
        Ok(())
    })
    .map_err(werr(&path))?;
    let path = dir.join("render_error.csv");
    write_atomically(&path, |out| {
        writeln!(out, "knob,value,ms,mean_abs_error,is_default")?;
        for r in &report.quality {
            writeln!(
                out,
                "{},{},{:.4},{:.6},{}",
                r.knob, r.value, r.ms, r.mean_error, r.is_default
            )?;
        }
        Ok(())
    })
    .map_err(werr(&path))?;
    let path = dir.join("bench.json");
    write_atomically(&path, |out| {
        serde_json::to_writer_pretty(&mut *out, report).map_err(std::io::Error::other)?;
        writeln!(out)
    })
    .map_err(werr(&path))?;

    let device = format!("{} ({} timing)", report.adapter, report.timing);
    let series_of = |group: &str, renderer: &str, x: fn(&Row) -> f64| Series {
        name: renderer.replace('_', "-"),
        points: report
            .rows
            .iter()
            .filter(|r| r.group == group && r.renderer == renderer && r.timing != "skipped")
            .map(|r| (x(r), r.median_ms))
            .collect(),
    };
    loglog_png(
        &dir.join("ms_vs_coverage.png"),
        &format!("Frame time against coverage, {device}"),
        "coverage",
        "frame, ms",
        &[series_of("coverage", "cloud_map", |r| r.coverage as f64)],
        &[],
    )?;
    loglog_png(
        &dir.join("ms_vs_parcels.png"),
        &format!("Frame time against parcels, {device}"),
        "parcels",
        "frame, ms",
        &[
            series_of("parcels", "cloud_map", |r| r.parcels as f64),
            series_of("parcels", "per_parcel", |r| r.parcels as f64),
        ],
        &[],
    )?;
    let bars: Vec<(String, f64)> = report
        .rows
        .iter()
        .filter(|r| r.group == "features")
        .enumerate()
        .map(|(k, r)| {
            (
                [
                    "defaults",
                    "tsaa off",
                    "terrain on",
                    "shadows off",
                    "octaves 0",
                    "detail off",
                ]
                .get(k)
                .copied()
                .unwrap_or("?")
                .to_owned(),
                r.median_ms,
            )
        })
        .collect();
    bars_png(
        &dir.join("ms_per_feature.png"),
        &format!("Frame time per feature, {device}"),
        "frame, ms",
        &bars,
    )?;
    let knobs = ["steps", "shadow_steps", "octaves", "tsaa_frames"];
    let series: Vec<Series> = knobs
        .iter()
        .map(|k| Series {
            name: k.to_string(),
            points: report
                .quality
                .iter()
                .filter(|q| q.knob == *k)
                .map(|q| (q.ms.max(1e-6), q.mean_error.max(1e-6)))
                .collect(),
        })
        .collect();
    let marked: Vec<(f64, f64, String)> = report
        .quality
        .iter()
        .filter(|q| q.is_default)
        .map(|q| {
            (
                q.ms.max(1e-6),
                q.mean_error.max(1e-6),
                format!("  {} {}", q.knob, q.value),
            )
        })
        .collect();
    loglog_png(
        &dir.join("render_error.png"),
        &format!(
            "Render error against GPU time, {}x{}, {device}",
            report.quality_size[0], report.quality_size[1]
        ),
        "ms",
        "mean abs. error",
        &series,
        &marked,
    )
}
