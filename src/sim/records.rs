//! What each parcel is at one time: the quantities of the paper's Fig. 5,
//! with what it projects into P. `cumulus simulate` writes them as CSV
//! (`report::curves`) and the Python package returns them as columns.

use super::{Band, Simulation};

/// One parcel at the simulation's current time. Positions are the
/// physics' axes: `x_m`, `y_m` horizontal, `z_m` the height (z up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParcelRecord {
    /// Simulated time, s.
    pub t_s: f64,
    /// The parcel's slot.
    pub id: usize,
    /// How many times the slot has been reborn.
    pub generation: u32,
    /// Time since release, s: negative while the parcel waits at the
    /// ground (`physics.release_stagger_s` spreads the releases).
    pub age_s: f64,
    pub x_m: f64,
    pub y_m: f64,
    pub z_m: f64,
    /// Vertical velocity, m/s.
    pub w_mps: f64,
    /// The parcel's and the environment's virtual potential temperature, K.
    pub theta_v_k: f64,
    pub theta_v_env_k: f64,
    /// Temperature, K.
    pub t_k: f64,
    /// Vapour, condensate and total water mixing ratios, kg/kg.
    pub qv: f64,
    pub qc: f64,
    pub qt: f64,
    /// Buoyancy, m/s².
    pub buoyancy_mps2: f64,
    /// `qc / qt` (0 for dry air).
    pub condensed_fraction: f64,
    /// What the parcel projects into P's fill: the condensed fraction over
    /// `physics.fill_full_condensed_fraction`, clamped to 0..=1; 0 when it
    /// does not project.
    pub fill: f64,
    /// Height in the cloud band, 0 at its base and 1 at its top (clamped).
    pub z_norm: f64,
    /// Whether the parcel projects into P: condensed and released.
    pub projects: bool,
}

impl ParcelRecord {
    /// The record's columns, units in the names (mixing ratios in g/kg,
    /// `coverage` 1 where the parcel projects, else 0): the header of
    /// `cumulus simulate`'s CSV and the Python package's column names.
    pub const COLUMNS: [&'static str; 19] = [
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

    /// The values of [`Self::COLUMNS`], in their order and units.
    pub fn values(&self) -> [f64; 19] {
        [
            self.t_s,
            self.id as f64,
            f64::from(self.generation),
            self.age_s,
            self.x_m,
            self.y_m,
            self.z_m,
            self.w_mps,
            self.theta_v_k,
            self.theta_v_env_k,
            self.t_k,
            self.qv * 1e3,
            self.qc * 1e3,
            self.qt * 1e3,
            self.buoyancy_mps2,
            self.condensed_fraction,
            self.fill,
            self.z_norm,
            if self.projects { 1.0 } else { 0.0 },
        ]
    }
}

impl Simulation {
    /// One record per parcel at the current time, in slot order; `band`
    /// normalises the heights as the projection does.
    pub fn records(&self, band: Band) -> impl ExactSizeIterator<Item = ParcelRecord> + '_ {
        let p = self.parcels();
        let full = self.config().fill_full_condensed_fraction;
        let t_s = self.time_s();
        let span = (band.top_m - band.bottom_m).max(1e-6);
        (0..p.len()).map(move |i| {
            let d = &p.diag[i];
            let l = &p.life[i];
            let qt = p.qt[i];
            let condensed_fraction = if qt > 0.0 { d.qc / qt } else { 0.0 };
            let projects = d.qc > 0.0 && l.released();
            let fill = if projects {
                (condensed_fraction / full).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let pos = p.pos[i];
            ParcelRecord {
                t_s,
                id: i,
                generation: l.generation,
                age_s: l.age_s,
                x_m: pos.x,
                y_m: pos.y,
                z_m: pos.z,
                w_mps: p.vel[i].z,
                theta_v_k: d.theta_v,
                theta_v_env_k: d.theta_v_env,
                t_k: d.t_k,
                qv: d.qv,
                qc: d.qc,
                qt,
                buoyancy_mps2: d.buoyancy,
                condensed_fraction,
                fill,
                z_norm: ((pos.z - band.bottom_m) / span).clamp(0.0, 1.0),
                projects,
            }
        })
    }
}
