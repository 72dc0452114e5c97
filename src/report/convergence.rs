//! Error against run time for the physics: the same scene stepped with
//! frame steps from 0.1 s to 600 s, compared with a fine reference at
//! common output times.

use std::path::Path;
use std::time::Instant;

use super::ReportError;
use super::plot::{Series, loglog_png};
use crate::io::write_atomically;
use crate::sim::{Atmosphere, PhysicsConfig, Simulation};

/// Frame steps measured by default, s. Each divides [`COMPARE_EVERY_S`].
pub const DEFAULT_DTS_S: [f64; 12] = [
    0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 60.0, 120.0, 300.0, 600.0,
];
/// Step of the reference run, s.
pub const REFERENCE_DT_S: f64 = 0.05;
/// States are compared every this many simulated seconds.
pub const COMPARE_EVERY_S: f64 = 600.0;
/// The error a default step must reach: RMS parcel height within 20 m (a
/// tenth of a typical parcel radius; below a texel of P at 128² over 10 km).
pub const TARGET_Z_M: f64 = 20.0;
/// ... and RMS condensate within 0.05 g/kg (about 5% of a cumulus' q_c).
pub const TARGET_QC_GKG: f64 = 0.05;
/// ... and at most 2 % of parcel samples in another life than the
/// reference's (re-births a frame apart).
pub const TARGET_LIFE_MISMATCH: f64 = 0.02;

/// One measured step size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    pub dt_s: f64,
    pub wall_s: f64,
    pub substeps: u64,
    pub capped_frames: u64,
    pub err_z_m: f64,
    pub err_w_mps: f64,
    pub err_theta_v_k: f64,
    pub err_qc_gkg: f64,
    pub err_cloud_base_m: f64,
    pub err_cloud_top_m: f64,
    /// Fraction of parcel samples in a different life than the reference's.
    pub life_mismatch: f64,
}

/// The whole measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    pub reference_dt_s: f64,
    pub reference_wall_s: f64,
    pub duration_s: f64,
    pub rows: Vec<Row>,
    /// Index into `rows` of the cheapest step meeting both targets.
    pub chosen: Option<usize>,
}

#[derive(Clone)]
struct Snapshot {
    /// Generation (life) of each parcel: states are compared only between
    /// parcels in the same life in both runs.
    generation: Vec<u32>,
    z: Vec<f64>,
    w: Vec<f64>,
    theta_v: Vec<f64>,
    qc: Vec<f64>,
    base_top: Option<(f64, f64)>,
}

fn run(
    cfg: &PhysicsConfig,
    atm: &Atmosphere,
    dt: f64,
    duration_s: f64,
) -> (Vec<Snapshot>, f64, u64, u64) {
    let mut cfg = cfg.clone();
    cfg.dt_s = dt;
    let start = Instant::now();
    let mut sim = Simulation::new(cfg, atm.clone());
    let per_snapshot = (COMPARE_EVERY_S / dt).round() as u64;
    let snapshots = (duration_s / COMPARE_EVERY_S).floor() as u64;
    let mut out = Vec::new();
    for _ in 0..snapshots {
        for _ in 0..per_snapshot {
            sim.step();
        }
        let p = sim.parcels();
        let cloudy: Vec<f64> = (0..p.len())
            .filter(|&i| p.diag[i].qc > 0.0 && p.life[i].released())
            .map(|i| p.pos[i].z)
            .collect();
        out.push(Snapshot {
            generation: p.life.iter().map(|l| l.generation).collect(),
            z: p.pos.iter().map(|x| x.z).collect(),
            w: p.vel.iter().map(|v| v.z).collect(),
            theta_v: p.diag.iter().map(|d| d.theta_v).collect(),
            qc: p.diag.iter().map(|d| d.qc * 1e3).collect(),
            base_top: (!cloudy.is_empty()).then(|| {
                (
                    cloudy.iter().copied().fold(f64::MAX, f64::min),
                    cloudy.iter().copied().fold(f64::MIN, f64::max),
                )
            }),
        });
    }
    let t = sim.totals();
    (
        out,
        start.elapsed().as_secs_f64(),
        t.substeps,
        t.capped_frames,
    )
}

/// RMS difference over the parcels that are in the same life in both runs.
fn rms(a: &[Snapshot], b: &[Snapshot], f: impl Fn(&Snapshot) -> &Vec<f64>) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for (x, y) in a.iter().zip(b) {
        for (k, (u, v)) in f(x).iter().zip(f(y)).enumerate() {
            if x.generation[k] == y.generation[k] {
                s += (u - v) * (u - v);
                n += 1;
            }
        }
    }
    if n == 0 { 0.0 } else { (s / n as f64).sqrt() }
}

/// Fraction of parcel samples whose life (re-birth count) differs from the
/// reference's: re-births are discrete events decided at frame ends, so a
/// parcel re-born one frame apart is counted here, not in the state errors
/// (its ~1 km jump would swamp them).
fn life_mismatch(a: &[Snapshot], b: &[Snapshot]) -> f64 {
    let (mut m, mut n) = (0usize, 0usize);
    for (x, y) in a.iter().zip(b) {
        for (g, h) in x.generation.iter().zip(&y.generation) {
            m += usize::from(g != h);
            n += 1;
        }
    }
    if n == 0 { 0.0 } else { m as f64 / n as f64 }
}

fn mean_abs(a: &[Snapshot], b: &[Snapshot], f: impl Fn((f64, f64)) -> f64) -> f64 {
    let diffs: Vec<f64> = a
        .iter()
        .zip(b)
        .filter_map(|(x, y)| Some((f(x.base_top?) - f(y.base_top?)).abs()))
        .collect();
    if diffs.is_empty() {
        0.0
    } else {
        diffs.iter().sum::<f64>() / diffs.len() as f64
    }
}

/// Measures every step in `dts_s` against the reference; `progress` is
/// called after each run.
pub fn measure(
    cfg: &PhysicsConfig,
    atm: &Atmosphere,
    duration_s: f64,
    dts_s: &[f64],
    mut progress: impl FnMut(),
) -> Report {
    let (reference, reference_wall_s, _, _) = run(cfg, atm, REFERENCE_DT_S, duration_s);
    progress();
    let mut rows = Vec::new();
    for &dt in dts_s {
        let (snap, wall_s, substeps, capped_frames) = run(cfg, atm, dt, duration_s);
        rows.push(Row {
            dt_s: dt,
            wall_s,
            substeps,
            capped_frames,
            err_z_m: rms(&snap, &reference, |s| &s.z),
            err_w_mps: rms(&snap, &reference, |s| &s.w),
            err_theta_v_k: rms(&snap, &reference, |s| &s.theta_v),
            err_qc_gkg: rms(&snap, &reference, |s| &s.qc),
            err_cloud_base_m: mean_abs(&snap, &reference, |bt| bt.0),
            err_cloud_top_m: mean_abs(&snap, &reference, |bt| bt.1),
            life_mismatch: life_mismatch(&snap, &reference),
        });
        progress();
    }
    let chosen = rows
        .iter()
        .enumerate()
        .filter(|(_, r)| {
            r.err_z_m <= TARGET_Z_M
                && r.err_qc_gkg <= TARGET_QC_GKG
                && r.life_mismatch <= TARGET_LIFE_MISMATCH
        })
        .min_by(|a, b| a.1.wall_s.total_cmp(&b.1.wall_s))
        .map(|(i, _)| i);
    Report {
        reference_dt_s: REFERENCE_DT_S,
        reference_wall_s,
        duration_s,
        rows,
        chosen,
    }
}

/// Writes `convergence.csv` and `convergence.png` into `dir`.
pub fn write(report: &Report, dir: &Path) -> Result<(), ReportError> {
    let csv_path = dir.join("convergence.csv");
    write_atomically(&csv_path, |out| {
        writeln!(out, "dt_s,wall_s,substeps,capped_frames,err_z_m,err_w_mps,err_theta_v_K,err_qc_gkg,err_cloud_base_m,err_cloud_top_m,life_mismatch")?;
        for r in &report.rows {
            writeln!(
                out,
                "{},{:.6},{},{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.4}",
                r.dt_s, r.wall_s, r.substeps, r.capped_frames, r.err_z_m, r.err_w_mps, r.err_theta_v_k, r.err_qc_gkg,
                r.err_cloud_base_m, r.err_cloud_top_m, r.life_mismatch
            )?;
        }
        Ok(())
    })
    .map_err(|source| ReportError::Write { path: csv_path.clone(), source })?;
    let floor = 1e-6;
    let series = |name: &str, f: fn(&Row) -> f64| Series {
        joined: true,
        name: name.to_owned(),
        points: report
            .rows
            .iter()
            .map(|r| (r.wall_s.max(1e-6), f(r).max(floor)))
            .collect(),
    };
    let marked: Vec<(f64, f64, String)> = report
        .chosen
        .map(|i| {
            let r = &report.rows[i];
            vec![(
                r.wall_s.max(1e-6),
                r.err_z_m.max(floor),
                format!("least cost meeting the target: dt = {} s", r.dt_s),
            )]
        })
        .unwrap_or_default();
    loglog_png(
        &dir.join("convergence.png"),
        &format!(
            "Physics error against run time ({} s simulated, reference dt {} s)",
            report.duration_s, report.reference_dt_s
        ),
        "wall time of the run, s",
        "RMS error vs reference",
        &[
            series("z, m", |r| r.err_z_m),
            series("w, m/s", |r| r.err_w_mps),
            series("theta_v, K", |r| r.err_theta_v_k),
            series("q_c, g/kg", |r| r.err_qc_gkg),
        ],
        &marked,
    )
}
