//! A part the scene switches off does nothing: its effect is absent.

use cumulus::sim::config::PhysicsConfig;
use cumulus::sim::{Atmosphere, ParametricProfile, Simulation};
use glam::DVec3;

fn atm() -> Atmosphere {
    Atmosphere::from_parametric(&ParametricProfile {
        surface_relative_humidity: 0.9,
        ..ParametricProfile::FAIR_WEATHER
    })
}

fn all_off(dt_s: f64) -> PhysicsConfig {
    let mut c = PhysicsConfig {
        dt_s,
        ..PhysicsConfig::default()
    };
    c.entrainment.enabled = false;
    c.detrainment.enabled = false;
    c.recycling.enabled = false;
    c.sph.enabled = false;
    c.wind.enabled = false;
    c
}

#[test]
fn sph_off_lets_overlapping_parcels_pass_through_each_other() {
    let pts = [
        DVec3::new(5000.0, 5000.0, 50.0),
        DVec3::new(5100.0, 5000.0, 50.0),
    ];
    let mut off = Simulation::with_positions(all_off(5.0), atm(), &pts);
    let mut cfg = all_off(5.0);
    cfg.sph.enabled = true;
    let mut on = Simulation::with_positions(cfg, atm(), &pts);
    for _ in 0..60 {
        off.step();
        on.step();
    }
    let dx = |s: &Simulation| s.parcels().pos[1].x - s.parcels().pos[0].x;
    assert_eq!(dx(&off), 100.0, "no SPH: no horizontal force at all");
    assert!(dx(&on) > 150.0, "SPH on: they repel ({})", dx(&on));
}

#[test]
fn wind_off_keeps_horizontal_position() {
    let pts = [DVec3::new(1234.0, 4321.0, 50.0)];
    let mut sim = Simulation::with_positions(all_off(5.0), atm(), &pts);
    for _ in 0..100 {
        sim.step();
    }
    let p = sim.parcels().pos[0];
    assert_eq!((p.x, p.y), (1234.0, 4321.0));
    assert!(p.z > 100.0, "but it rose");
}

#[test]
fn detrainment_off_keeps_all_water_and_on_sheds_it() {
    let pts = [DVec3::new(0.0, 0.0, 50.0)];
    let run = |detrain: bool| {
        let mut cfg = all_off(5.0);
        cfg.detrainment.enabled = detrain;
        let mut sim = Simulation::with_positions(cfg, atm(), &pts);
        for _ in 0..240 {
            sim.step();
        }
        sim.water_budget()
    };
    assert_eq!(run(false).detrained_kg, 0.0);
    assert!(run(true).detrained_kg > 0.0);
}

#[test]
fn recycling_off_never_rebirths_and_entrainment_off_exchanges_nothing() {
    let cfg = PhysicsConfig {
        parcels: 20,
        release_stagger_s: 0.0,
        ..all_off(10.0)
    };
    let mut sim = Simulation::new(cfg, atm());
    for _ in 0..720 {
        sim.step();
    }
    assert_eq!(sim.totals().recycled, 0);
    assert!(sim.parcels().life.iter().all(|l| l.generation == 0));
    assert_eq!(sim.water_budget().entrained_kg, 0.0);
}
