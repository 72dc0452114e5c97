//! `cumulus render`: simulate a scene, then render one picture on the GPU
//! or with the CPU reference; the other methods' pictures are in
//! `methods`, the error-against-cost reports in `reports`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use cumulus::io::write_png_atomically;
use cumulus::prepare::Prepared;
use cumulus::render::cpu::frame::{Frame, Quality};
use cumulus::render::gpu::GpuContext;
use cumulus::render::gpu::headless::{HDR_FORMAT, TARGET_FORMAT};
use cumulus::scene::{Method, RenderMethod, RenderSettings, Scene};

mod methods;
mod reports;

use methods::{render_endless, render_spheroids};
use reports::{quality_report, stills_report};

use crate::{
    check_output_file, gpu_context, guard_output_file, load_scene, progress_bar, with_overrides,
    write_exr,
};

#[derive(clap::Args)]
#[command(
    after_help = "Example:\n  cumulus render --scene scenes/fair_weather.toml --out sky.png\n  cumulus render --scene scenes/evening.toml --backend gpu --time-frames 100 --out evening.png"
)]
pub struct RenderArgs {
    /// Scene TOML file, or the name of a built-in shipped scene
    /// (fair_weather, evening, strong_inversion, ...: `--scene fair_weather`).
    #[arg(long)]
    scene: PathBuf,
    /// Output picture, written atomically: .png (tone-mapped with ACES
    /// filmic at render.exposure, opened below a 5° sun by
    /// render.auto_exposure; sRGB) or .exr (OpenEXR, linear radiance, no
    /// tone map). Needed unless --quality-report or --stills-report is
    /// given.
    #[arg(long, required_unless_present_any = ["quality_report", "stills_report"])]
    out: Option<PathBuf>,
    /// Also write the error-against-cost report (render_quality.csv/.png)
    /// into this directory: step counts from 8 to 256 against a 2048-step
    /// reference, at up to 320x240.
    #[arg(long)]
    quality_report: Option<PathBuf>,
    /// Also write the CPU stills' error against cost (stills.csv) into
    /// this directory: one march a pixel up to eight, averaged everywhere
    /// (render.cpu_sampling = "uniform") or at edges ("adaptive"),
    /// against 32 a pixel, at up to 320x240.
    #[arg(long)]
    stills_report: Option<PathBuf>,
    /// Image width in pixels (overrides render.width).
    #[arg(long)]
    width: Option<u32>,
    /// Image height in pixels (overrides render.height).
    #[arg(long)]
    height: Option<u32>,
    /// Simulated seconds before the picture (overrides render.time_s).
    #[arg(long)]
    time_s: Option<f64>,
    /// Primary ray-march steps (overrides render.steps).
    #[arg(long)]
    steps: Option<u32>,
    /// Photons the light volume traces per column of its cells (overrides
    /// render.light_photons, default 64): more for a light closer to the
    /// path tracer's (1024, the count it was fitted with, takes 18 times
    /// as long), fewer for a quicker, noisier one, 0 for none.
    #[arg(long)]
    light_photons: Option<u32>,
    /// auto: a hardware GPU when wgpu finds one, else the CPU reference;
    /// cpu; gpu (any adapter wgpu finds, software Vulkan included).
    /// WGPU_BACKEND (vulkan, gl, metal, dx12) narrows the search.
    #[arg(long, value_enum, default_value_t = Backend::Auto)]
    backend: Backend,
    /// GPU frames rendered from the still camera before the picture is
    /// taken, so TSAA has converged (default: 32 with render.tsaa, else 1).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    frames: Option<u32>,
    /// GPU: also time this many frames (after 10 warm-up frames) and print
    /// the median and 95th percentile, from timestamp queries when the
    /// adapter has them, else CPU wall time (labelled).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100000))]
    time_frames: Option<u32>,
    /// CPU, cloud map only: render the sun's light scattered once and
    /// nothing else (no multiple-scattering octaves, no sky or ground
    /// light in the clouds, black behind them, no haze): the part of the
    /// light a path tracer limited to one scattering checks exactly
    /// (docs/ground_truth/compare.py --single-scattering).
    #[arg(long)]
    single_scattering: bool,
}

/// What `--out` holds, from its extension.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Picture {
    /// Tone-mapped sRGB, 8 bits.
    Png,
    /// Linear radiance, 32-bit floats.
    Exr,
}

impl Picture {
    fn of(path: &Path) -> Result<Self> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("png") => Ok(Self::Png),
            Some("exr") => Ok(Self::Exr),
            _ => bail!(
                "{}: --out must end in .png (tone-mapped picture) or .exr (linear radiance)",
                path.display()
            ),
        }
    }
}

/// Which renderer draws the image.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Backend {
    Auto,
    Cpu,
    Gpu,
}

pub fn run(a: RenderArgs) -> Result<()> {
    let scene = scene_with_flags(&a)?;
    for w in cumulus::prepare::view_warnings(&scene)? {
        eprintln!("warning: {}: {w}", a.scene.display());
    }
    let r = &scene.render;
    let factor = r.exposure_factor();
    if factor != 1.0 && picture_is_png(a.out.as_deref()) {
        eprintln!(
            "auto_exposure: the sun {}° high, exposure {} x {:.4} ({:.1} stops)",
            r.sun_elevation_deg,
            r.exposure,
            factor,
            factor.log2()
        );
    }
    let mut picture = None;
    if let Some(out) = &a.out {
        check_output_file(out)?;
        crate::refuse_overwriting_inputs(out, &crate::scene_inputs(&scene, None))?;
        picture = Some(Picture::of(out)?);
        guard_output_file(out);
    }
    let gpu = choose_backend(a.backend)?;
    check_backend_flags(&a, &scene, gpu.is_some())?;
    if scene.simulation.method == Method::Endless {
        return render_endless(gpu.as_ref(), &a, &scene, picture);
    }
    let simulated = std::time::Instant::now();
    let bar = progress_bar(Prepared::frames(&scene), "simulating");
    let prepared = Prepared::from_scene(&scene, || bar.inc(1))?;
    bar.finish_and_clear();
    let simulate_s = simulated.elapsed().as_secs_f64();
    let quality = Quality {
        single_scattering: a.single_scattering,
        ..r.quality()
    };
    if a.quality_report.is_some() || a.stills_report.is_some() {
        // The CPU's frame, its light volume built once here (the GPU
        // builds its own: a GPU picture does not wait for the CPU's).
        let frame = lit_frame(&prepared, r, quality);
        if let Some(dir) = &a.quality_report {
            quality_report(&frame, r, dir)?;
        }
        if let Some(dir) = &a.stills_report {
            stills_report(&frame, r, dir)?;
        }
    }
    if r.renderer == RenderMethod::Spheroids {
        return render_spheroids(gpu.as_ref(), &a, &scene, &prepared, picture);
    }
    if let Some(ctx) = &gpu {
        return render_gpu(ctx, &a, &scene, &prepared, picture);
    }
    match &a.out {
        Some(out) => render_cpu(&a, &scene, &prepared, quality, out, picture, simulate_s),
        None => Ok(()),
    }
}

/// The scene of `--scene` with the flags that override its keys.
fn scene_with_flags(a: &RenderArgs) -> Result<Scene> {
    let flags = [
        ("--width", "render.width"),
        ("--height", "render.height"),
        ("--time-s", "render.time_s"),
        ("--steps", "render.steps"),
        ("--light-photons", "render.light_photons"),
    ];
    with_overrides(load_scene(&a.scene)?, &flags, |s| {
        let r = &mut s.render;
        if let Some(w) = a.width {
            r.width = w;
        }
        if let Some(h) = a.height {
            r.height = h;
        }
        if let Some(t) = a.time_s {
            r.time_s = t;
        }
        if let Some(steps) = a.steps {
            r.steps = steps;
        }
        if let Some(n) = a.light_photons {
            r.light_photons = n;
        }
    })
}

/// The GPU to render on (`None`: the CPU reference), saying which.
fn choose_backend(backend: Backend) -> Result<Option<GpuContext>> {
    Ok(match backend {
        Backend::Cpu => {
            eprintln!("backend: cpu (the CPU reference renderer)");
            None
        }
        Backend::Gpu => Some(gpu_context().context("--backend gpu")?),
        Backend::Auto => match gpu_context() {
            Ok(c) if c.adapter_info.device_type != wgpu::DeviceType::Cpu => Some(c),
            Ok(c) => {
                eprintln!(
                    "backend: cpu (the only GPU adapter is software, {}; --backend gpu uses it)",
                    c.adapter_info.name
                );
                None
            }
            Err(e) => {
                eprintln!("backend: cpu ({e}; the CPU reference renderer)");
                None
            }
        },
    })
}

/// The flags that only one backend or renderer reads: refused where they
/// cannot be honoured, warned about where another machine would use them.
fn check_backend_flags(a: &RenderArgs, scene: &Scene, gpu: bool) -> Result<()> {
    if !gpu && a.time_frames.is_some() {
        bail!("--time-frames needs the GPU backend (--backend gpu)");
    }
    if !gpu && a.frames.is_some() {
        // Not an error: with --backend auto the same command runs on a
        // machine with a GPU, where --frames counts.
        eprintln!(
            "warning: --frames is for the GPU backend; the CPU renderer averages \
             render.cpu_offsets jittered frames instead"
        );
    }
    if a.single_scattering
        && (gpu
            || scene.simulation.method == Method::Endless
            || scene.render.renderer == RenderMethod::Spheroids)
    {
        bail!(
            "--single-scattering is a check of the CPU reference's cloud-map renderer: \
             use --backend cpu with render.renderer = \"cloud_map\" and a simulated (not endless) scene"
        );
    }
    Ok(())
}

/// The CPU's frame of `prepared` with its light volume, built with a
/// progress bar (nothing shown when there is none to build).
fn lit_frame<'a>(prepared: &'a Prepared, r: &RenderSettings, quality: Quality) -> Frame<'a> {
    let bar = std::cell::OnceCell::new();
    let frame = prepared.frame_reporting(r, quality, &|share| {
        bar.get_or_init(|| progress_bar(100, "light volume"))
            .to_share(share)
    });
    if let Some(b) = bar.get() {
        b.finish_and_clear();
    }
    frame
}

/// The CPU reference's still of the cloud map's clouds, written to `out`.
#[allow(clippy::too_many_arguments)]
fn render_cpu(
    a: &RenderArgs,
    scene: &Scene,
    prepared: &Prepared,
    quality: Quality,
    out: &Path,
    picture: Option<Picture>,
    simulate_s: f64,
) -> Result<()> {
    use cumulus::render::cpu::still_reconstruction::render_still_adaptive;
    use cumulus::render::cpu::stills::{add_sun_glare, render_still_reporting};
    use cumulus::scene::CpuSampling;
    let r = &scene.render;
    let built = std::time::Instant::now();
    let frame = lit_frame(prepared, r, quality);
    let light_s = built.elapsed().as_secs_f64();
    let start = std::time::Instant::now();
    let bar = progress_bar(100, "rendering");
    let report = &|share: f32| bar.to_share(share);
    let (mut linear, cost) = match r.cpu_sampling {
        CpuSampling::Adaptive => {
            let still = render_still_adaptive(r.width, r.height, &frame, r.cpu_offsets, report);
            let cost = format!(
                "{:.2} marches, {:.0} density reads a pixel",
                still.marches_per_pixel(),
                still.reads_per_pixel()
            );
            (still.linear, cost)
        }
        CpuSampling::Uniform => (
            render_still_reporting(r.width, r.height, &frame, r.cpu_offsets, report),
            format!("{} marches a pixel", r.cpu_offsets),
        ),
    };
    bar.finish_and_clear();
    if picture != Some(Picture::Exr) {
        // The tone-mapped picture gets the sun's glare (`still_srgb8`; the
        // GPU's composite adds it the same way); the linear OpenEXR does
        // not.
        add_sun_glare(&mut linear, r.width, r.height, &frame, r.cpu_offsets);
    }
    let elapsed = start.elapsed();

    write_linear(out, picture, r, &linear)?;
    eprintln!(
        "rendered {}x{} in {:.2} s ({cost}) after {simulate_s:.2} s simulating and {light_s:.2} s for the light volume ({} steps, {} shadow steps, {}; P {:.0} % covered, cloud band {:.0}-{:.0} m); wrote {}",
        r.width,
        r.height,
        elapsed.as_secs_f64(),
        r.steps,
        r.shadow_steps,
        if a.single_scattering {
            "single scattering only".to_string()
        } else {
            format!("{} octaves", r.octaves)
        },
        100.0 * prepared.field.covered_fraction(),
        prepared.band.bottom_m,
        prepared.band.top_m,
        out.display()
    );
    Ok(())
}

/// The most primary steps times shadow steps with which lavapipe stays
/// with the CPU twin (likely its loop limit,
/// [`cumulus::render::gpu::context::LLVMPIPE_LOOP_ITERATIONS`]):
/// measured on fair weather at 64x48, 512 x 20 and 1024 x 10 are 0.10
/// levels from the CPU, 768 x 20 0.28, 1024 x 20 1.3, 512 x 64 2.1
/// (docs/gpu.md, "Lavapipe at 1024 steps or more"). The default is 48 x 20.
const LAVAPIPE_MARCH_LOAD_MAX: u32 = 10_240;

/// `render` on the GPU: `--frames` frames (TSAA converges), the last one
/// saved; `--time-frames` times more.
fn render_gpu(
    ctx: &GpuContext,
    a: &RenderArgs,
    scene: &Scene,
    prepared: &Prepared,
    picture: Option<Picture>,
) -> Result<()> {
    let r = &scene.render;
    eprintln!("backend: gpu ({})", ctx.describe());
    let load = r.steps * r.shadow_steps.max(1);
    if ctx.is_llvmpipe() && load > LAVAPIPE_MARCH_LOAD_MAX {
        eprintln!(
            "warning: {}: render.steps x render.shadow_steps = {} x {} = {load} on lavapipe, \
             which ends a shader's loops after {} iterations: above {LAVAPIPE_MARCH_LOAD_MAX} \
             its distant cloud bases come out brighter than the CPU's (--backend cpu); use \
             fewer steps or shadow steps",
            a.scene.display(),
            r.steps,
            r.shadow_steps,
            cumulus::render::gpu::context::LLVMPIPE_LOOP_ITERATIONS
        );
    }
    let settings = prepared.gpu_settings(r, r.quality());
    let format = match picture {
        Some(Picture::Exr) => HDR_FORMAT,
        _ => TARGET_FORMAT,
    };
    let mut hl = prepared.headless_with_format(ctx, &settings, r.width, r.height, format)?;
    let frames = a.frames.unwrap_or(if r.tsaa { 32 } else { 1 });
    let start = std::time::Instant::now();
    hl.render(ctx, &r.camera(), frames)?;
    let elapsed = start.elapsed();
    if let Some(out) = &a.out {
        if let Some(rgb) = hl.read_linear(ctx)? {
            write_exr(out, r.width, r.height, rgb)?;
        } else {
            write_rgb8(out, r.width, r.height, hl.read_rgb8(ctx)?)?;
        }
        eprintln!(
            "rendered {}x{}, {frames} frame(s) in {:.2} s ({} steps, {} shadow steps, {} octaves, TSAA {}; passes {}); wrote {}",
            r.width,
            r.height,
            elapsed.as_secs_f64(),
            r.steps,
            r.shadow_steps,
            r.octaves,
            if r.tsaa { "on" } else { "off" },
            hl.renderer.last_passes().join(", "),
            out.display()
        );
    }
    if let Some(n) = a.time_frames {
        let t = hl.time_frames(ctx, &r.camera(), 10, n)?;
        let source = if t.gpu {
            "GPU timestamps"
        } else {
            "CPU wall time, submit to idle (no timestamp queries)"
        };
        println!(
            "frame {}x{}: median {:.3} ms, p95 {:.3} ms over {n} frames ({source}; {})",
            r.width,
            r.height,
            t.median(),
            t.p95(),
            ctx.describe()
        );
        if t.gpu {
            for (k, pass) in hl.renderer.last_passes().iter().enumerate() {
                let v: Vec<f64> = t.per_pass.iter().map(|f| f[k]).collect();
                println!(
                    "  {pass}: median {:.3} ms",
                    cumulus::render::gpu::timer::FrameTimes::quantile(&v, 0.5)
                );
            }
        }
        let reads = hl.density_reads(ctx, &r.camera())?;
        println!(
            "density reads a pixel a frame: mean {:.1}, max {:.0}",
            reads.mean, reads.max
        );
    }
    Ok(())
}

/// Whether `out` (if any) is a PNG, which the exposure applies to.
fn picture_is_png(out: Option<&Path>) -> bool {
    out.and_then(|o| Picture::of(o).ok()) == Some(Picture::Png)
}

/// Writes a CPU picture: OpenEXR of the linear radiance, or the PNG of its
/// tone map at the quality's exposure (`r.exposure`, metered at a low sun
/// by `RenderSettings::exposure_factor`).
fn write_linear(
    out: &Path,
    picture: Option<Picture>,
    r: &cumulus::scene::RenderSettings,
    linear: &[glam::Vec3],
) -> Result<()> {
    if picture == Some(Picture::Exr) {
        let rgb = linear.iter().flat_map(|c| c.to_array()).collect();
        return write_exr(out, r.width, r.height, rgb);
    }
    let exposure = r.quality().exposure;
    let bytes = cumulus::render::cpu::tone_map::to_srgb8(linear, exposure);
    write_rgb8(out, r.width, r.height, bytes)
}

/// Writes 8-bit RGB rows as a PNG, atomically.
fn write_rgb8(out: &Path, width: u32, height: u32, bytes: Vec<u8>) -> Result<()> {
    let img = image::RgbImage::from_raw(width, height, bytes).context("image buffer size")?;
    write_png_atomically(out, &img)
        .with_context(|| format!("{}: cannot write image", out.display()))
}
