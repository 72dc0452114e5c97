//! `cumulus bench`: GPU frame times across resolution, coverage, parcel
//! count and features, for the cloud-map renderer and the per-parcel
//! pseudo-spheroid renderer; the physics' share of the frame; the methods
//! side by side; and rendering error against run time. Results as CSV,
//! JSON and plots. `timing.rs` times one configuration,
//! `physics_share.rs` the physics against the frame, `methods.rs` the
//! methods, `quality.rs` the error against GPU time, `write.rs` the files.

mod methods;
mod physics_share;
mod quality;
mod timing;
mod write;

use serde::Serialize;

pub use quality::mean_abs_diff;
pub use write::write;

use super::ReportError;
use crate::prepare::Prepared;
use crate::render::cpu::sky::SkyModel;
use crate::render::gpu::{GpuContext, GpuError};
use crate::scene::{RenderSettings, Scene, SceneError};
use methods::compare_methods;
use physics_share::physics_in_frame;
use quality::quality_sweep;
use timing::{row, spheroid_renderer, time_cloud_map, time_pass};

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
    /// Only the methods side by side (`methods.csv`), nothing else.
    pub methods_only: bool,
}

/// Coverages of the cloud-map paper's Table 1.
pub const COVERAGES: [f32; 4] = [0.91, 0.71, 0.51, 0.10];
/// Parcel counts (12: the paper; 85: Goswami & Neyret 2017).
pub const PARCELS: [usize; 4] = [12, 85, 1_000, 10_000];
/// The feature rows, in order: the defaults, then one change each.
pub const FEATURES: [&str; 8] = [
    "defaults",
    "tsaa off",
    "terrain on",
    "shadows off",
    "octaves 0",
    "detail off",
    "analytic sky",
    "aerial off",
];
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
    /// The sky model: "physical" or "analytic".
    pub sky: &'static str,
    /// Aerial perspective on.
    pub aerial: bool,
    pub frames: u32,
    /// Fraction of P's texels with coverage.
    pub p_covered: f64,
    pub median_ms: f64,
    pub p95_ms: f64,
    /// "gpu" (timestamp queries) or "wall" (CPU wall time, submit to idle);
    /// "skipped" when the frame was predicted too slow to run.
    pub timing: &'static str,
    /// Density reads per output pixel of one frame, mean and max (the
    /// cloud map's renderer; NaN for the spheroids): a cost that does not
    /// depend on the machine.
    pub reads_mean: f64,
    pub reads_max: f64,
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

/// One method on the base scene: its frame, its simulation step and
/// (spheroids) its light grid's build.
#[derive(Debug, Clone, Serialize)]
pub struct MethodRow {
    /// The animation: "parcels", "automaton" or "endless".
    pub method: &'static str,
    /// The renderer: "cloud_map", "spheroids" or "volume".
    pub renderer: &'static str,
    pub width: u32,
    pub height: u32,
    /// Fraction of P's texels with coverage.
    pub p_covered: f64,
    pub median_ms: f64,
    pub p95_ms: f64,
    pub timing: &'static str,
    /// One simulation step (CPU wall time, median), ms.
    pub step_ms: f64,
    /// Seconds of sky one step advances.
    pub step_s: f64,
    /// The light grid's CPU build (spheroids only), ms.
    pub light_grid_ms: f64,
    /// What the frame keeps on the GPU of the animation's state, bytes:
    /// P (half floats), the spheroids and their light grid, or every
    /// volume of the database.
    pub state_bytes: usize,
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
    /// The methods side by side ([`MethodRow`]).
    pub methods: Vec<MethodRow>,
    /// The endless playback's jumps against its similarity temperature.
    pub endless: Vec<crate::endless::ThresholdRow>,
    pub quality: Vec<QualityRow>,
    /// Quality images' size.
    pub quality_size: [u32; 2],
}

impl Report {
    /// The cloud-map against per-parcel speed ratio at `parcels` (per-parcel
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
    cm.size = ((cm.size as f64 * f) as usize).clamp(64, 2048);
    sc
}

/// A change of a scene's `[render]` settings.
type Tweak = fn(&mut RenderSettings);

/// A quality knob: name, values, default, reference value, setter.
pub(super) type Knob = (
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
    if o.methods_only {
        let methods = compare_methods(ctx, &base, o, &mut progress)?;
        let timing = methods.0.first().map_or("wall", |m| m.timing);
        return Ok(report(
            ctx,
            o,
            timing,
            Vec::new(),
            Vec::new(),
            methods,
            (Vec::new(), [0, 0]),
        ));
    }
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
        let (t, reads) = time_cloud_map(ctx, &p, &r, o)?;
        rows.push(row(
            "resolution",
            "cloud_map",
            &r,
            &p,
            (Some(&t), Some(reads)),
            o.frames,
        ));
    }
    for c in COVERAGES {
        let r = RenderSettings {
            coverage: c,
            ..sc.render.clone()
        };
        progress(&format!("coverage {c}"));
        let (t, reads) = time_cloud_map(ctx, &p, &r, o)?;
        rows.push(row(
            "coverage",
            "cloud_map",
            &r,
            &p,
            (Some(&t), Some(reads)),
            o.frames,
        ));
    }
    let tweaks: [Tweak; 8] = [
        |_| {},
        |r| r.tsaa = false,
        // Hills under the camera: raised by their relief, so it stands
        // above them whatever the ground under it.
        |r| {
            r.terrain.enabled = true;
            r.camera_position_m[1] += r.terrain.relief_m;
        },
        |r| r.shadow_steps = 0,
        |r| r.octaves = 0,
        |r| r.detail_strength = 0.0,
        |r| r.atmosphere.model = SkyModel::Analytic,
        |r| r.atmosphere.aerial_perspective = false,
    ];
    for (name, f) in FEATURES.into_iter().zip(tweaks) {
        let mut s2 = sc.clone();
        f(&mut s2.render);
        progress(&format!("features: {name}"));
        let p2 = if s2.render.terrain.enabled {
            Prepared::from_scene(&s2, || {})?
        } else {
            Prepared::from_scene(&sc, || {})?
        };
        let (t, reads) = time_cloud_map(ctx, &p2, &s2.render, o)?;
        rows.push(row(
            "features",
            "cloud_map",
            &s2.render,
            &p2,
            (Some(&t), Some(reads)),
            o.frames,
        ));
    }

    let mut physics = Vec::new();
    let mut last_per_parcel: Option<(usize, f64)> = None;
    for n in PARCELS {
        let (scn, pn) = prepare(&base, n)?;
        let r = &scn.render;
        progress(&format!("parcels {n}: cloud map"));
        let (t, reads) = time_cloud_map(ctx, &pn, r, o)?;
        let frame_ms = t.median();
        rows.push(row(
            "parcels",
            "cloud_map",
            r,
            &pn,
            (Some(&t), Some(reads)),
            o.frames,
        ));
        let predicted_s = last_per_parcel.map(|(m, ms)| ms * n as f64 / m as f64 * 1e-3);
        if predicted_s.is_some_and(|s| s > o.max_frame_s) {
            progress(&format!(
                "parcels {n}: spheroids skipped (predicted {:.0} s a frame)",
                predicted_s.unwrap_or(0.0)
            ));
            rows.push(row("parcels", "per_parcel", r, &pn, (None, None), 0));
        } else {
            progress(&format!("parcels {n}: spheroids"));
            let mut sp = spheroid_renderer(ctx, &pn, r);
            sp.resize(r.width, r.height);
            let tb = time_pass(ctx, r, o, |e, v, c, q| sp.render(e, v, c, q))?;
            last_per_parcel = Some((n, tb.median()));
            rows.push(row(
                "parcels",
                "per_parcel",
                r,
                &pn,
                (Some(&tb), None),
                o.frames,
            ));
        }
        physics.push(physics_in_frame(
            ctx,
            &scn,
            n,
            frame_ms,
            if o.quick { 3 } else { 20 },
        )?);
    }
    let methods = compare_methods(ctx, &base, o, &mut progress)?;
    progress("render error against run time");
    let (quality, quality_size) = quality_sweep(ctx, &sc, &p, o)?;
    let timing = rows
        .iter()
        .find(|r| r.timing != "skipped")
        .map_or("wall", |r| r.timing);
    Ok(report(
        ctx,
        o,
        timing,
        rows,
        physics,
        methods,
        (quality, quality_size),
    ))
}

fn report(
    ctx: &GpuContext,
    o: &BenchOptions,
    timing: &'static str,
    rows: Vec<Row>,
    physics: Vec<PhysicsRow>,
    (methods, endless): (Vec<MethodRow>, Vec<crate::endless::ThresholdRow>),
    (quality, quality_size): (Vec<QualityRow>, [u32; 2]),
) -> Report {
    let i = &ctx.adapter_info;
    Report {
        adapter: i.name.clone(),
        backend: format!("{:?}", i.backend),
        device_type: format!("{:?}", i.device_type),
        driver: i.driver.clone(),
        driver_info: i.driver_info.clone(),
        timing,
        quick: o.quick,
        rows,
        physics,
        methods,
        endless,
        quality,
        quality_size,
    }
}
