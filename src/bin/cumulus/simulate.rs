//! `cumulus simulate`: the parcel curves (the paper's Fig. 5) as CSV.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};

use cumulus::io::write_atomically;
use cumulus::report::curves;
use cumulus::sim::{FramePlan, Simulation};

use crate::{finite_positive, guard_output_file, load_scene, progress_bar, with_overrides};

#[derive(clap::Args)]
#[command(
    after_help = "Example:\n  cumulus simulate --scene scenes/bomex.toml --duration-s 3600 --out curves.csv"
)]
pub struct SimulateArgs {
    /// Scene TOML file, or the name of a built-in shipped scene
    /// (fair_weather, evening, strong_inversion, ...: `--scene fair_weather`).
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
    /// Output CSV, one row per parcel per output step (written atomically):
    /// the physics' axes, x and y horizontal and z_m the height (z up;
    /// `render` and `export` put y up); age_s is negative while a parcel
    /// waits at the ground for its release (-600: released in 600 s).
    /// Columns: docs/physics.md, "Parcel curves".
    #[arg(long)]
    out: PathBuf,
}

pub fn run(a: SimulateArgs) -> Result<()> {
    let flags = [
        ("--dt-s", "physics.dt_s"),
        ("--parcels", "physics.parcels"),
        ("--seed", "physics.seed"),
    ];
    let scene = with_overrides(load_scene(&a.scene)?, &flags, |s| {
        if let Some(dt) = a.dt_s {
            s.physics.dt_s = dt;
        }
        if let Some(n) = a.parcels {
            s.physics.parcels = n;
        }
        if let Some(seed) = a.seed {
            s.physics.seed = seed;
        }
    })?;
    if scene.simulation.method == cumulus::scene::Method::Automaton {
        bail!(
            "{}: simulation.method = \"automaton\" has no parcels; `cumulus simulate` writes parcel curves (render the automaton with `cumulus render`)",
            a.scene.display()
        );
    }
    finite_positive("--duration-s", a.duration_s)?;
    let every = a.every_s.unwrap_or(scene.physics.dt_s);
    finite_positive("--every-s", every)?;
    crate::refuse_overwriting_inputs(&a.out, &crate::scene_inputs(&scene, a.sounding.as_deref()))?;
    let atm = scene.atmosphere(a.sounding.as_deref())?;
    guard_output_file(&a.out);
    let band = scene.band(&atm);
    // Exactly the duration asked: a short last frame when dt does not
    // divide it.
    let plan = FramePlan::new(a.duration_s, scene.physics.dt_s);
    let frames = plan.frames();
    let mut sim = Simulation::new(scene.physics.clone(), atm);
    let bar = progress_bar(frames, "simulating");
    write_atomically(&a.out, |out| {
        let mut w = csv::Writer::from_writer(out);
        curves::write_header(&mut w)?;
        curves::write_rows(&mut w, &sim, band)?;
        for f in 1..=frames {
            sim.advance(plan.frame_s(f - 1));
            if plan.records_after(f, every) {
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
    // Seconds to the microsecond, without trailing zeros.
    let secs = |x: f64| (x * 1e6).round() / 1e6;
    let frames_said = if plan.last_s > 0.0 {
        format!(
            "{} frames ({} of {} s, the last of {} s)",
            t.frames,
            plan.full,
            secs(plan.dt_s),
            secs(plan.last_s)
        )
    } else {
        format!("{} frames of {} s", t.frames, secs(plan.dt_s))
    };
    eprintln!(
        "simulated {} s in {frames_said} ({} sub-steps, {} frames hit the sub-step cap), {} re-births; water budget residual {:.2e} (relative); wrote {}",
        secs(sim.time_s()),
        t.substeps,
        t.capped_frames,
        t.recycled,
        b.relative_residual(),
        a.out.display()
    );
    Ok(())
}
