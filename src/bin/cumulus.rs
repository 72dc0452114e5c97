//! `cumulus`: the physics command line. Units are in every flag's name and
//! help text. Errors leave through `anyhow` with the file, line or field.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use cumulus::io::{write_atomically, write_png_atomically};
use cumulus::report::{convergence, curves};
use cumulus::scene::Scene;
use cumulus::sim::lift::{Adiabat, lift_sounding};
use cumulus::sim::{Simulation, Sounding};

#[derive(Parser)]
#[command(
    name = "cumulus",
    version,
    about = "Physics-driven cumulus clouds (Goswami, STAG 2019): parcel simulator and tools"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a scene and write the parcel curves (paper's Fig. 5) as CSV.
    Simulate(SimulateArgs),
    /// Lift the sounding's lowest air without mixing (like MetPy's
    /// parcel_profile): print its LCL, write one row per level.
    Profile(ProfileArgs),
    /// Error against run time: run a scene at steps from 0.1 s to 600 s
    /// against a fine reference; write convergence.csv and convergence.png.
    Convergence(ConvergenceArgs),
    /// Simulate a scene, then render one sky image (PNG) of its clouds.
    Render(RenderArgs),
    /// GPU frame benchmarks: resolution, coverage, parcel count (cloud map
    /// against a per-parcel baseline), features, the physics' share of the
    /// frame, and render error against GPU time. Writes CSV, JSON and PNGs.
    Bench(BenchArgs),
    /// Scene files.
    Scene {
        #[command(subcommand)]
        command: SceneCommand,
    },
}

#[derive(Subcommand)]
enum SceneCommand {
    /// Validate a scene (and its sounding); report errors with file, line and key.
    Check {
        /// Scene TOML file.
        file: PathBuf,
    },
}

#[derive(clap::Args)]
struct SimulateArgs {
    /// Scene TOML file.
    #[arg(long)]
    scene: PathBuf,
    /// Sounding CSV replacing the scene's atmosphere (header
    /// height_m,pressure_hPa,temperature_C,dewpoint_C).
    #[arg(long)]
    sounding: Option<PathBuf>,
    /// Simulated time, seconds.
    #[arg(long, default_value_t = 3600.0)]
    duration_s: f64,
    /// Frame time step, seconds (overrides the scene's physics.dt_s).
    #[arg(long)]
    dt_s: Option<f64>,
    /// Number of parcels (overrides the scene's physics.parcels).
    #[arg(long)]
    parcels: Option<usize>,
    /// Random seed (overrides the scene's physics.seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Write rows every this many simulated seconds (default: every frame).
    #[arg(long)]
    every_s: Option<f64>,
    /// Output CSV, one row per parcel per output step (written atomically).
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args)]
struct BenchArgs {
    /// Scene every configuration starts from.
    #[arg(long, default_value = "scenes/fair_weather.toml")]
    scene: PathBuf,
    /// Output directory (bench.csv, bench.json, physics_in_frame.csv,
    /// render_error.csv and the plots).
    #[arg(long)]
    out: PathBuf,
    /// Tiny images, 3 frames, 1 warm-up: every configuration runs, fast
    /// enough for CI on software Vulkan.
    #[arg(long)]
    quick: bool,
    /// Timed frames per configuration (default 30; 3 with --quick).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100000))]
    frames: Option<u32>,
    /// Warm-up frames per configuration (default 5; 1 with --quick).
    #[arg(long)]
    warmup: Option<u32>,
    /// Skip a per-parcel configuration predicted to take longer than this
    /// per frame, s (default 20; 2 with --quick).
    #[arg(long)]
    max_frame_s: Option<f64>,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Scene TOML file.
    #[arg(long)]
    scene: PathBuf,
    /// Output PNG (written atomically).
    #[arg(long, required_unless_present = "quality_report")]
    out: Option<PathBuf>,
    /// Also write the error-against-cost report (render_quality.csv/.png)
    /// into this directory: step counts from 8 to 256 against a 2048-step
    /// reference, at up to 320x240.
    #[arg(long)]
    quality_report: Option<PathBuf>,
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
}

/// Which renderer draws the image.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Backend {
    Auto,
    Cpu,
    Gpu,
}

#[derive(clap::Args)]
struct ProfileArgs {
    /// Sounding CSV (height_m,pressure_hPa,temperature_C,dewpoint_C).
    #[arg(long)]
    sounding: PathBuf,
    /// Moist adiabat above the LCL: pseudo (condensate removed) or reversible.
    #[arg(long, value_enum, default_value_t = AdiabatArg::Pseudo)]
    adiabat: AdiabatArg,
    /// Ground pressure in hPa, used when the sounding gives no pressures.
    #[arg(long, default_value_t = 1013.25)]
    surface_pressure_hpa: f64,
    /// Output CSV, one row per sounding level (written atomically).
    #[arg(long)]
    out: Option<PathBuf>,
}

/// `--adiabat` (kept here so the simulator does not depend on clap).
#[derive(Clone, Copy, clap::ValueEnum)]
enum AdiabatArg {
    /// Condensate removed as it forms (meteorologists' default).
    Pseudo,
    /// Condensate carried with the parcel.
    Reversible,
}

#[derive(clap::Args)]
struct ConvergenceArgs {
    /// Scene TOML file.
    #[arg(long)]
    scene: PathBuf,
    /// Simulated time per run, seconds (a multiple of 600).
    #[arg(long, default_value_t = 1800.0)]
    duration_s: f64,
    /// Output directory (created if missing).
    #[arg(long)]
    out: PathBuf,
}

fn main() {
    if let Err(e) = run(Cli::parse()) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Simulate(a) => simulate(a),
        Command::Profile(a) => profile(a),
        Command::Convergence(a) => convergence_cmd(a),
        Command::Render(a) => render_cmd(a),
        Command::Bench(a) => bench_cmd(a),
        Command::Scene {
            command: SceneCommand::Check { file },
        } => {
            let scene = Scene::load(&file)?;
            let atm = scene.atmosphere(None)?;
            let band = scene.band(&atm);
            println!(
                "{}: ok ({}; {} parcels, dt {} s, cloud band {:.0}-{:.0} m)",
                file.display(),
                if scene.name.is_empty() {
                    "unnamed"
                } else {
                    &scene.name
                },
                scene.physics.parcels,
                scene.physics.dt_s,
                band.bottom_m,
                band.top_m
            );
            Ok(())
        }
    }
}

fn progress_bar(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(
        Some(len),
        if std::io::stderr().is_terminal() {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        },
    );
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_message(what.to_owned());
    bar
}

fn finite_positive(name: &str, v: f64) -> Result<()> {
    if !(v.is_finite() && v > 0.0) {
        bail!("{name} is {v}, expected a positive number of seconds");
    }
    Ok(())
}

fn load_scene(path: &Path) -> Result<Scene> {
    Ok(Scene::load(path)?)
}

fn simulate(a: SimulateArgs) -> Result<()> {
    let mut scene = load_scene(&a.scene)?;
    if let Some(dt) = a.dt_s {
        scene.physics.dt_s = dt;
    }
    if let Some(n) = a.parcels {
        scene.physics.parcels = n;
    }
    if let Some(s) = a.seed {
        scene.physics.seed = s;
    }
    scene
        .validate()
        .context("after applying --dt-s/--parcels/--seed")?;
    finite_positive("--duration-s", a.duration_s)?;
    let every = a.every_s.unwrap_or(scene.physics.dt_s);
    finite_positive("--every-s", every)?;
    let atm = scene.atmosphere(a.sounding.as_deref())?;
    let band = scene.band(&atm);
    let frames = (a.duration_s / scene.physics.dt_s).round().max(1.0) as u64;
    let write_every = (every / scene.physics.dt_s).round().max(1.0) as u64;
    let mut sim = Simulation::new(scene.physics.clone(), atm);
    let bar = progress_bar(frames, "simulating");
    write_atomically(&a.out, |out| {
        let mut w = csv::Writer::from_writer(out);
        curves::write_header(&mut w)?;
        curves::write_rows(&mut w, &sim, band)?;
        for f in 1..=frames {
            sim.step();
            if f % write_every == 0 || f == frames {
                curves::write_rows(&mut w, &sim, band)?;
            }
            bar.inc(1);
        }
        w.flush()
    })
    .with_context(|| format!("{}: cannot write curves", a.out.display()))?;
    bar.finish_and_clear();
    let t = sim.totals();
    let b = sim.water_budget();
    eprintln!(
        "simulated {:.0} s in {} frames ({} sub-steps, {} frames hit the sub-step cap), {} re-births; water budget residual {:.2e} (relative); wrote {}",
        sim.time_s(),
        t.frames,
        t.substeps,
        t.capped_frames,
        t.recycled,
        b.relative_residual(),
        a.out.display()
    );
    Ok(())
}

fn profile(a: ProfileArgs) -> Result<()> {
    if !(300.0..=1100.0).contains(&a.surface_pressure_hpa) {
        bail!(
            "--surface-pressure-hpa is {}, expected 300..=1100",
            a.surface_pressure_hpa
        );
    }
    let s = Sounding::load(&a.sounding, a.surface_pressure_hpa * 100.0)?;
    let adiabat = match a.adiabat {
        AdiabatArg::Pseudo => Adiabat::Pseudo,
        AdiabatArg::Reversible => Adiabat::Reversible,
    };
    let prof = lift_sounding(&s, adiabat);
    println!("lcl_pressure_hPa={:.3}", prof.lcl.pressure_pa / 100.0);
    println!("lcl_temperature_K={:.3}", prof.lcl.temperature_k);
    match prof.lcl_height_m {
        Some(z) => println!("lcl_height_m={z:.1}"),
        None => println!("lcl_height_m=none (the parcel does not saturate within the sounding)"),
    }
    if let Some(out) = &a.out {
        write_atomically(out, |w| {
            writeln!(
                w,
                "height_m,pressure_hPa,env_T_K,parcel_T_K,parcel_qv_gkg,parcel_qc_gkg,buoyancy_mps2"
            )?;
            for r in &prof.rows {
                writeln!(
                    w,
                    "{:.3},{:.4},{:.4},{:.4},{:.5},{:.5},{:.6}",
                    r.height_m,
                    r.pressure_pa / 100.0,
                    r.env_t_k,
                    r.parcel_t_k,
                    r.parcel_qv * 1e3,
                    r.parcel_qc * 1e3,
                    r.buoyancy
                )?;
            }
            Ok(())
        })
        .with_context(|| format!("{}: cannot write profile", out.display()))?;
    }
    Ok(())
}

fn convergence_cmd(a: ConvergenceArgs) -> Result<()> {
    let scene = load_scene(&a.scene)?;
    if !(a.duration_s >= convergence::COMPARE_EVERY_S && a.duration_s.is_finite()) {
        bail!(
            "--duration-s is {}, expected at least {} s",
            a.duration_s,
            convergence::COMPARE_EVERY_S
        );
    }
    let atm = scene.atmosphere(None)?;
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("{}: cannot create directory", a.out.display()))?;
    let dts = convergence::DEFAULT_DTS_S;
    let bar = progress_bar(dts.len() as u64 + 1, "convergence");
    let report = convergence::measure(&scene.physics, &atm, a.duration_s, &dts, || bar.inc(1));
    bar.finish_and_clear();
    convergence::write(&report, &a.out)?;
    println!(
        "reference dt {} s took {:.2} s",
        report.reference_dt_s, report.reference_wall_s
    );
    println!(
        "{:>8} {:>9} {:>9} {:>9} {:>10} {:>10} {:>9} {:>9} {:>9}",
        "dt_s",
        "wall_s",
        "err_z_m",
        "err_w",
        "err_thv_K",
        "err_qc_gkg",
        "base_m",
        "top_m",
        "other_life"
    );
    for r in &report.rows {
        println!(
            "{:>8} {:>9.4} {:>9.3} {:>9.4} {:>10.4} {:>10.5} {:>9.2} {:>9.2} {:>9.3}",
            r.dt_s,
            r.wall_s,
            r.err_z_m,
            r.err_w_mps,
            r.err_theta_v_k,
            r.err_qc_gkg,
            r.err_cloud_base_m,
            r.err_cloud_top_m,
            r.life_mismatch
        );
    }
    match report.chosen {
        Some(i) => println!(
            "least-cost step reaching RMS z error <= {} m, q_c error <= {} g/kg and other-life fraction <= {}: dt = {} s",
            convergence::TARGET_Z_M,
            convergence::TARGET_QC_GKG,
            convergence::TARGET_LIFE_MISMATCH,
            report.rows[i].dt_s
        ),
        None => println!(
            "no step reached the stated error (z <= {} m, q_c <= {} g/kg)",
            convergence::TARGET_Z_M,
            convergence::TARGET_QC_GKG
        ),
    }
    println!(
        "wrote {0}/convergence.csv and {0}/convergence.png",
        a.out.display()
    );
    Ok(())
}

/// The GPU, from `WGPU_BACKEND` when set (the binary's edge reads the
/// environment, the library does not).
fn gpu_context() -> Result<cumulus::render::gpu::GpuContext, cumulus::render::gpu::GpuError> {
    let backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::all());
    cumulus::render::gpu::GpuContext::new(backends)
}

/// `render` on the GPU: `--frames` frames (TSAA converges), the last one
/// saved; `--time-frames` times more.
fn render_gpu(
    ctx: &cumulus::render::gpu::GpuContext,
    a: &RenderArgs,
    scene: &cumulus::scene::Scene,
    prepared: &cumulus::render::prepare::Prepared,
) -> Result<()> {
    use cumulus::render::gpu::Headless;
    let r = &scene.render;
    eprintln!("backend: gpu ({})", ctx.describe());
    let settings = prepared.gpu_settings(r, r.quality());
    let mut hl = Headless::new(ctx, prepared, &settings, r.width, r.height)?;
    let frames = a.frames.unwrap_or(if r.tsaa { 32 } else { 1 });
    let start = std::time::Instant::now();
    hl.render(ctx, &r.camera(), frames)?;
    let elapsed = start.elapsed();
    if let Some(out) = &a.out {
        let bytes = hl.read_rgb8(ctx)?;
        let img =
            image::RgbImage::from_raw(r.width, r.height, bytes).context("image buffer size")?;
        write_png_atomically(out, &img)
            .with_context(|| format!("{}: cannot write image", out.display()))?;
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
    }
    Ok(())
}

fn bench_cmd(a: BenchArgs) -> Result<()> {
    use cumulus::report::gpu_bench::{self, BenchOptions};
    let mut scene = load_scene(&a.scene)?;
    if a.quick {
        scene.render.time_s = scene.render.time_s.min(600.0);
    }
    let ctx = gpu_context().context("cumulus bench needs a GPU adapter")?;
    eprintln!("device: {}", ctx.describe());
    let o = BenchOptions {
        quick: a.quick,
        frames: a.frames.unwrap_or(if a.quick { 3 } else { 30 }),
        warmup: a.warmup.unwrap_or(if a.quick { 1 } else { 5 }),
        max_frame_s: a.max_frame_s.unwrap_or(if a.quick { 2.0 } else { 20.0 }),
    };
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("{}: cannot create directory", a.out.display()))?;
    let report = gpu_bench::run(&ctx, &scene, &o, |line| eprintln!("{line}"))?;
    gpu_bench::write(&report, &a.out)?;
    println!(
        "{:<11} {:<10} {:>9} {:>8} {:>7} {:>9} {:>9} {:>10} {:>10} {:>6}",
        "group",
        "renderer",
        "size",
        "coverage",
        "parcels",
        "features",
        "P_covered",
        "median_ms",
        "p95_ms",
        "timing"
    );
    for r in &report.rows {
        let features = format!(
            "{}{}s{}o{}{}",
            if r.tsaa { "T" } else { "-" },
            if r.terrain { "G" } else { "-" },
            r.shadow_steps,
            r.octaves,
            if r.detail { "D" } else { "-" }
        );
        println!(
            "{:<11} {:<10} {:>9} {:>8} {:>7} {:>9} {:>9.2} {:>10.3} {:>10.3} {:>6}",
            r.group,
            r.renderer,
            format!("{}x{}", r.width, r.height),
            r.coverage,
            r.parcels,
            features,
            r.p_covered,
            r.median_ms,
            r.p95_ms,
            r.timing
        );
    }
    for n in [12, 85] {
        if let Some(x) = report.ratio_at(n) {
            println!("per-parcel / cloud-map frame time at {n} parcels: {x:.1}x");
        }
    }
    println!("physics + projection + upload against the frame:");
    for p in &report.physics {
        println!(
            "  {:>6} parcels: {:.3} + {:.3} + {:.3} ms = {:.2} % of a {:.2} ms frame",
            p.parcels, p.physics_ms, p.projection_ms, p.upload_ms, p.share_pct, p.frame_ms
        );
    }
    println!("wrote {}", a.out.display());
    Ok(())
}

fn render_cmd(a: RenderArgs) -> Result<()> {
    use cumulus::render::cpu::renderer::{render_linear, to_srgb8};
    use cumulus::render::prepare::Prepared;
    use cumulus::report::render_quality;

    let mut scene = load_scene(&a.scene)?;
    if let Some(w) = a.width {
        scene.render.width = w;
    }
    if let Some(h) = a.height {
        scene.render.height = h;
    }
    if let Some(t) = a.time_s {
        scene.render.time_s = t;
    }
    if let Some(s) = a.steps {
        scene.render.steps = s;
    }
    scene
        .validate()
        .context("after applying --width/--height/--time-s/--steps")?;
    let gpu = match a.backend {
        Backend::Cpu => None,
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
                eprintln!("backend: cpu ({e})");
                None
            }
        },
    };
    if gpu.is_none() && a.time_frames.is_some() {
        bail!("--time-frames needs the GPU backend (--backend gpu)");
    }
    let bar = progress_bar(Prepared::frames(&scene), "simulating");
    let prepared = Prepared::from_scene(&scene, || bar.inc(1))?;
    bar.finish_and_clear();
    let r = &scene.render;
    let frame = prepared.frame(r, r.quality());
    if let Some(dir) = &a.quality_report {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create directory", dir.display()))?;
        let (w, h) = (r.width.min(320), r.height.min(240));
        let bar = progress_bar(render_quality::STEPS.len() as u64 + 1, "rendering");
        let report = render_quality::measure(&frame, w, h, &render_quality::STEPS, || bar.inc(1));
        bar.finish_and_clear();
        render_quality::write(&report, dir)?;
        println!(
            "reference ({} steps) took {:.2} s at {w}x{h}",
            render_quality::REFERENCE_STEPS,
            report.reference_wall_s
        );
        println!(
            "{:>6} {:>9} {:>11} {:>10}",
            "steps", "wall_s", "mean_error", "max_error"
        );
        for row in &report.rows {
            println!(
                "{:>6} {:>9.4} {:>11.5} {:>10.4}",
                row.steps, row.wall_s, row.mean_error, row.max_error
            );
        }
        match report.chosen {
            Some(i) => println!(
                "least-cost step count with mean error <= {}: {}",
                render_quality::TARGET_MEAN_ERROR,
                report.rows[i].steps
            ),
            None => println!(
                "no step count reached mean error <= {}",
                render_quality::TARGET_MEAN_ERROR
            ),
        }
        println!(
            "wrote {0}/render_quality.csv and {0}/render_quality.png",
            dir.display()
        );
    }
    if let Some(ctx) = &gpu {
        return render_gpu(ctx, &a, &scene, &prepared);
    }
    eprintln!("backend: cpu (the CPU reference renderer)");
    let Some(out) = &a.out else { return Ok(()) };
    let start = std::time::Instant::now();
    let linear = render_linear(r.width, r.height, &frame);
    let elapsed = start.elapsed();
    let bytes = to_srgb8(&linear, r.exposure);
    let img = image::RgbImage::from_raw(r.width, r.height, bytes).context("image buffer size")?;
    write_png_atomically(out, &img)
        .with_context(|| format!("{}: cannot write image", out.display()))?;
    eprintln!(
        "rendered {}x{} in {:.2} s ({} steps, {} shadow steps, {} octaves; P {:.0} % covered, cloud band {:.0}-{:.0} m); wrote {}",
        r.width,
        r.height,
        elapsed.as_secs_f64(),
        r.steps,
        r.shadow_steps,
        r.octaves,
        100.0 * prepared.field.covered_fraction(),
        prepared.band.bottom_m,
        prepared.band.top_m,
        out.display()
    );
    Ok(())
}
