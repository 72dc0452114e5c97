//! Cold air: the default moisture excess (1 g/kg) is more than the whole
//! saturation mixing ratio at -20 °C (about 0.8 g/kg), so an absolute excess
//! would make every parcel a fog droplet at its release height. Capped at the
//! saturation of the parcel at the cloud base, no parcel may hold cloud
//! below the surface air's LCL, while convection still makes cloud above.

use cumulus::sim::lift::surface_lcl_height;
use cumulus::sim::{Atmosphere, PhysicsConfig, Simulation, Sounding};

/// A cold-air outbreak over open water: -18 °C at the surface, a
/// near-dry-adiabatic layer to 1.5 km capped by an inversion, humid below.
const COLD_OUTBREAK: &str = "height_m,pressure_hPa,temperature_C,dewpoint_C
0,1012,-18.0,-20.5
500,,-22.6,-24.6
1000,,-27.2,-28.8
1500,,-31.5,-33.0
1700,,-29.5,-40.0
3000,,-36.5,-47.0
6000,,-55.0,-65.0
";

/// Cloud below the LCL by less than this is the LCL's own interpolation
/// between the atmosphere table's rows (1 m), m. Measured: the lowest
/// cloudy parcel is 20.7 m above the LCL (`cargo test --release --test
/// cold_air -- --nocapture`, this 2-core machine): no cloud forms below it.
const BELOW_LCL_TOLERANCE_M: f64 = 1.0;

#[test]
fn cold_air_forms_no_cloud_below_the_lcl() {
    let s = Sounding::parse(COLD_OUTBREAK, std::path::Path::new("cold.csv"), 101_200.0)
        .expect("valid sounding");
    let atm = Atmosphere::from_sounding(&s);
    let lcl = surface_lcl_height(&atm).expect("the surface air saturates");
    assert!(lcl > 150.0, "LCL {lcl} m");
    let cfg = PhysicsConfig {
        parcels: 60,
        domain_size_m: 6000.0,
        release_stagger_s: 300.0,
        ..PhysicsConfig::default()
    };
    let mut sim = Simulation::new(cfg, atm);
    let mut cloudy_above = 0;
    let mut lowest_cloud = f64::INFINITY;
    for frame in 0..360 {
        let p = sim.parcels();
        for i in 0..p.len() {
            if p.diag[i].qc > 0.0 {
                let z = p.pos[i].z;
                assert!(
                    z >= lcl - BELOW_LCL_TOLERANCE_M,
                    "frame {frame}: parcel {i} has {:.3} g/kg of cloud at {z:.0} m, below the LCL at {lcl:.0} m",
                    p.diag[i].qc * 1e3
                );
                cloudy_above += 1;
                lowest_cloud = lowest_cloud.min(z);
            }
        }
        sim.step();
    }
    eprintln!(
        "lowest cloudy parcel {lowest_cloud:.2} m, {:.2} m above the LCL",
        lowest_cloud - lcl
    );
    assert!(
        cloudy_above > 0,
        "no cloud formed at all: the test would be vacuous"
    );
}
