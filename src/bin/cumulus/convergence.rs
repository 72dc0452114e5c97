//! `cumulus convergence`: the physics' error against run time.

use std::path::PathBuf;

use anyhow::{Result, bail};

use cumulus::report::convergence;

use crate::{load_scene, progress_bar};

#[derive(clap::Args)]
#[command(
    after_help = "Example:\n  cumulus convergence --scene scenes/bomex.toml --out convergence/"
)]
pub struct ConvergenceArgs {
    /// Scene TOML file, or the name of a built-in shipped scene
    /// (fair_weather, evening, strong_inversion, ...: `--scene fair_weather`).
    #[arg(long)]
    scene: PathBuf,
    /// Simulated time per run, seconds (at least 600: the runs are compared
    /// every 600 s).
    #[arg(long, default_value_t = 1800.0)]
    duration_s: f64,
    /// Output directory (created if missing).
    #[arg(long)]
    out: PathBuf,
}

pub fn run(a: ConvergenceArgs) -> Result<()> {
    let scene = load_scene(&a.scene)?;
    if !(a.duration_s >= convergence::COMPARE_EVERY_S && a.duration_s <= crate::MAX_DURATION_S) {
        bail!(
            "--duration-s is {}, expected {}..={:e} s",
            a.duration_s,
            convergence::COMPARE_EVERY_S,
            crate::MAX_DURATION_S
        );
    }
    let atm = scene.atmosphere(None)?;
    crate::create_output_folder(&a.out)?;
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
