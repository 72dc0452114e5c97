//! The parcel physics on its own, as a library: build an atmosphere, run
//! a simulation, read the parcels and the projected field P.
//!
//! `cargo run --release --example parcels -- [PARCELS]`

use cumulus::sim::{
    Atmosphere, Band, ParametricProfile, PhysicsConfig, ProjectedField, Simulation,
};

fn main() {
    let parcels: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1000);
    let cfg = PhysicsConfig {
        parcels,
        // One parcel per km².
        domain_size_m: 1000.0 * (parcels as f64).sqrt(),
        ..PhysicsConfig::default()
    };
    let atm = Atmosphere::from_parametric(&ParametricProfile::FAIR_WEATHER);
    let mut sim = Simulation::new(cfg, atm);
    let mut field = ProjectedField::new(128, 128);
    let band = Band {
        bottom_m: 600.0,
        top_m: 1600.0,
    };
    let frames_per_minute = (60.0 / sim.config().dt_s).round().max(1.0) as usize;
    let start = std::time::Instant::now();
    for minute in 1..=60 {
        let mut substeps = 0;
        for _ in 0..frames_per_minute {
            substeps += sim.step().substeps;
        }
        sim.project_into(&mut field, band);
        if minute % 10 == 0 {
            let p = sim.parcels();
            let cloudy = p.diag.iter().filter(|d| d.qc > 0.0).count();
            let top = p
                .pos
                .iter()
                .zip(&p.diag)
                .filter(|(_, d)| d.qc > 0.0)
                .map(|(x, _)| x.z)
                .fold(0.0, f64::max);
            println!(
                "t = {:4.0} s: {cloudy:5} of {} parcels cloudy, highest cloud {top:5.0} m, P covered {:4.1} %, {:.1} sub-steps/frame",
                sim.time_s(),
                p.len(),
                100.0 * field.covered_fraction(),
                substeps as f64 / frames_per_minute as f64
            );
        }
    }
    let b = sim.water_budget();
    println!(
        "1 h simulated in {:.2} s; {:?}; water budget residual {:.1e}",
        start.elapsed().as_secs_f64(),
        sim.totals(),
        b.relative_residual()
    );
}
