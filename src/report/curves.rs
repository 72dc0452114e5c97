//! Parcel curves as CSV: one row per parcel per output step, the quantities
//! of the paper's Fig. 5.

use std::io::Write;

use crate::sim::{Band, Simulation};

/// The CSV header (units in the names). Positions are the physics'
/// axes: `x_m`, `y_m` horizontal, `z_m` the height (z up, where the
/// renderer and the volume export put y up). `age_s` counts from the
/// parcel's release: negative while it waits at the ground
/// (`physics.release_stagger_s` spreads the releases).
pub const HEADER: [&str; 19] = [
    "t_s",
    "id",
    "generation",
    "age_s",
    "x_m",
    "y_m",
    "z_m",
    "w_mps",
    "theta_v_K",
    "theta_v_env_K",
    "T_K",
    "qv_gkg",
    "qc_gkg",
    "qt_gkg",
    "buoyancy_mps2",
    "condensed_fraction",
    "fill",
    "z_norm",
    "coverage",
];

/// Writes the header.
pub fn write_header(out: &mut csv::Writer<impl Write>) -> csv::Result<()> {
    out.write_record(HEADER)
}

/// Writes one row per parcel at the simulation's current time. `fill` is the
/// value the parcel projects into P; `coverage` is 1 for a condensed,
/// released parcel (it projects), else 0.
pub fn write_rows(
    out: &mut csv::Writer<impl Write>,
    sim: &Simulation,
    band: Band,
) -> csv::Result<()> {
    let p = sim.parcels();
    let full = sim.config().fill_full_condensed_fraction;
    let t = sim.time_s();
    let span = (band.top_m - band.bottom_m).max(1e-6);
    for i in 0..p.len() {
        let d = &p.diag[i];
        let l = &p.life[i];
        let qt = p.qt[i];
        let cf = if qt > 0.0 { d.qc / qt } else { 0.0 };
        let projects = d.qc > 0.0 && l.released();
        let fill = if projects {
            (cf / full).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let pos = p.pos[i];
        out.write_record(&[
            fmt(t),
            i.to_string(),
            l.generation.to_string(),
            fmt(l.age_s),
            fmt(pos.x),
            fmt(pos.y),
            fmt(pos.z),
            fmt(p.vel[i].z),
            fmt(d.theta_v),
            fmt(d.theta_v_env),
            fmt(d.t_k),
            fmt(d.qv * 1e3),
            fmt(d.qc * 1e3),
            fmt(qt * 1e3),
            fmt(d.buoyancy),
            fmt(cf),
            fmt(fill),
            fmt(((pos.z - band.bottom_m) / span).clamp(0.0, 1.0)),
            if projects { "1" } else { "0" }.to_owned(),
        ])?;
    }
    Ok(())
}

fn fmt(x: f64) -> String {
    format!("{x:.6}")
}
