//! `cumulus bench`: the GPU frame benchmarks.

use std::path::PathBuf;

use anyhow::{Context, Result};

use crate::{gpu_context, load_scene};

#[derive(clap::Args)]
#[command(after_help = "Example:\n  cumulus bench --quick --out bench/")]
pub struct BenchArgs {
    /// Scene every configuration starts from: a TOML file, or the name
    /// of a built-in shipped scene.
    #[arg(long, default_value = "fair_weather")]
    scene: PathBuf,
    /// Output directory (bench.csv, bench.json, physics_in_frame.csv,
    /// render_error.csv and the plots).
    #[arg(long)]
    out: PathBuf,
    /// Tiny images, 3 frames, 1 warm-up: every configuration runs, fast
    /// enough for CI on software Vulkan.
    #[arg(long)]
    quick: bool,
    /// Only the methods side by side (methods.csv and bench.json): the
    /// cloud map fed by the parcels and by the automaton, and the
    /// pseudo-spheroids, at the scene's 640x480.
    #[arg(long)]
    methods: bool,
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
    /// Photons the light volume traces per column of its cells (overrides
    /// render.light_photons; 16 with --quick, where software Vulkan would
    /// spend a minute on each configuration's first build). The build runs
    /// before the timed frames, which it does not change.
    #[arg(long)]
    light_photons: Option<u32>,
}

pub fn run(a: BenchArgs) -> Result<()> {
    use cumulus::report::gpu_bench::{self, BenchOptions};
    let mut scene = load_scene(&a.scene)?;
    if a.quick {
        scene.render.time_s = scene.render.time_s.min(600.0);
        scene.render.light_photons = scene.render.light_photons.min(16);
    }
    if let Some(n) = a.light_photons {
        scene.render.light_photons = n;
        scene
            .validate()
            .with_context(|| format!("--light-photons {n}"))?;
    }
    let ctx = gpu_context().context("cumulus bench needs a GPU adapter")?;
    eprintln!("device: {}", ctx.describe());
    let o = BenchOptions {
        quick: a.quick,
        frames: a.frames.unwrap_or(if a.quick { 3 } else { 30 }),
        warmup: a.warmup.unwrap_or(if a.quick { 1 } else { 5 }),
        max_frame_s: a.max_frame_s.unwrap_or(if a.quick { 2.0 } else { 20.0 }),
        methods_only: a.methods,
    };
    crate::create_output_folder(&a.out)?;
    let report = gpu_bench::run(&ctx, &scene, &o, |line| eprintln!("{line}"))?;
    gpu_bench::write(&report, &a.out)?;
    if !report.rows.is_empty() {
        print_sweeps(&report);
    }
    println!("methods side by side (frame on the GPU; step and light grid on the CPU):");
    for m in &report.methods {
        println!(
            "  {:<9} + {:<9} {}x{}: frame median {:.2} ms, p95 {:.2} ms ({}); step {:.3} ms per {} s; light grid {:.1} ms",
            m.method,
            m.renderer,
            m.width,
            m.height,
            m.median_ms,
            m.p95_ms,
            m.timing,
            m.step_ms,
            m.step_s,
            m.light_grid_ms
        );
    }
    println!("endless playback against its similarity temperature (sigma / mean step):");
    for t in &report.endless {
        println!(
            "  {:>5}: {:.1} jumps per 100 steps, a jump {:.2}x (largest {:.2}x) a plain step's change; {} volumes shown, {} in the second half",
            t.similarity, t.jumps_per_100, t.mean_jump, t.max_jump, t.distinct, t.distinct_late
        );
    }
    println!("wrote {}", a.out.display());
    Ok(())
}

/// The sweeps' table, the speed ratios and the physics' share.
fn print_sweeps(report: &cumulus::report::gpu_bench::Report) {
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
}
