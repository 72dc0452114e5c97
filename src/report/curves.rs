//! Parcel curves as CSV: one row per parcel per output step, the quantities
//! of the paper's Fig. 5.

use std::io::Write;

use crate::sim::{Band, ParcelRecord, Simulation};

/// The CSV header ([`ParcelRecord::COLUMNS`]): positions are the
/// physics' axes, `x_m`, `y_m` horizontal and `z_m` the height (z up, where
/// the renderer and the volume export put y up); `age_s` counts from the
/// parcel's release, negative while it waits at the ground.
pub const HEADER: [&str; 19] = ParcelRecord::COLUMNS;

/// The columns of whole numbers (`id`, `generation`, `coverage`), written
/// without decimals.
const WHOLE_COLUMNS: [usize; 3] = [1, 2, 18];

/// Writes the header.
pub fn write_header(out: &mut csv::Writer<impl Write>) -> csv::Result<()> {
    out.write_record(HEADER)
}

/// Writes one row per parcel at the simulation's current time
/// ([`Simulation::records`]): `coverage` is 1 for a parcel that projects
/// into P (condensed and released), else 0; mixing ratios in g/kg.
pub fn write_rows(
    out: &mut csv::Writer<impl Write>,
    sim: &Simulation,
    band: Band,
) -> csv::Result<()> {
    for r in sim.records(band) {
        let values = r.values();
        let row = values.iter().enumerate().map(|(i, &v)| {
            if WHOLE_COLUMNS.contains(&i) {
                format!("{v:.0}")
            } else {
                fmt(v)
            }
        });
        out.write_record(row)?;
    }
    Ok(())
}

fn fmt(x: f64) -> String {
    format!("{x:.6}")
}
