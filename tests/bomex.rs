//! BOMEX (Siebesma et al. 2003): parcels released from the surface must form
//! a cloud layer with its base between 500 and 700 m and tops under the
//! inversion (~2000 m), as large-eddy simulations of the case do.

use std::path::PathBuf;

use cumulus::scene::Scene;
use cumulus::sim::Simulation;

#[test]
fn bomex_parcels_form_a_cloud_layer_between_500_and_2000_m() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/bomex.toml");
    let scene = Scene::load(&path).expect("shipped scene is valid");
    let atm = scene.atmosphere(None).expect("sounding loads");
    let mut cfg = scene.physics.clone();
    cfg.parcels = 64;
    let mut sim = Simulation::new(cfg, atm);
    // Two hours; sample every minute after the first hour (spin-up).
    let (mut bases, mut tops) = (Vec::new(), Vec::new());
    let frames_per_minute = (60.0 / sim.config().dt_s).round() as usize;
    for minute in 0..120 {
        for _ in 0..frames_per_minute {
            sim.step();
        }
        if minute < 60 {
            continue;
        }
        let p = sim.parcels();
        // Cloud base: the lowest height at which any parcel holds condensate.
        // A parcel's centre is where its state is defined, so that is its z.
        let cloudy: Vec<f64> = (0..p.len())
            .filter(|&i| p.diag[i].qc > 1e-5)
            .map(|i| p.pos[i].z)
            .collect();
        if let (Some(lo), Some(hi)) = (
            cloudy.iter().copied().reduce(f64::min),
            cloudy.iter().copied().reduce(f64::max),
        ) {
            bases.push(lo);
            tops.push(hi);
        }
    }
    assert!(
        bases.len() > 50,
        "clouds present most of the second hour ({} of 60 samples)",
        bases.len()
    );
    bases.sort_by(f64::total_cmp);
    tops.sort_by(f64::total_cmp);
    let base = bases[bases.len() / 2];
    let top = tops[tops.len() / 2];
    let highest = tops[tops.len() - 1];
    assert!(
        (500.0..=700.0).contains(&base),
        "median cloud base {base:.0} m"
    );
    assert!(
        top > base + 500.0,
        "a cloud layer, not a film: median top {top:.0} m"
    );
    assert!(
        highest < 2000.0,
        "tops stay under the inversion: highest {highest:.0} m"
    );
    let b = sim.water_budget();
    assert!(b.relative_residual() < 1e-9, "water budget {b:?}");
}
