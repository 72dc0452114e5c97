//! The lifted-parcel profile against MetPy 1.7.1 (values made once by
//! tests/reference/metpy_reference.py and committed).

use std::path::PathBuf;

use cumulus::sim::Sounding;
use cumulus::sim::lift::{Adiabat, lift_sounding};

/// LCL height tolerance, m (the 10 m).
const LCL_HEIGHT_TOLERANCE_M: f64 = 10.0;
/// Moist-adiabat temperature tolerance up to 3 km above the LCL, K (the
/// issue's 0.2 K; MetPy uses Ambaum's saturation pressure, we use Bolton's,
/// which differ by ~0.1 %).
const MOIST_ADIABAT_TOLERANCE_K: f64 = 0.2;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn sounding_path(name: &str) -> PathBuf {
    if name == "bomex" {
        root().join("scenes/bomex_sounding.csv")
    } else {
        root().join(format!("tests/data/{name}.csv"))
    }
}

fn read_reference(file: &str) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(root().join("tests/reference").join(file))
        .expect("reference file is committed");
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect()
}

fn load(name: &str) -> Sounding {
    Sounding::load(&sounding_path(name), 101_325.0).expect("test sounding is valid")
}

#[test]
fn lcl_matches_metpy_within_10_m() {
    let rows = read_reference("lcl.csv");
    assert_eq!(rows.len(), 4);
    for r in rows {
        let (name, p_ref, t_ref, z_ref): (&str, f64, f64, f64) = (
            &r[0],
            r[1].parse().unwrap(),
            r[2].parse().unwrap(),
            r[3].parse().unwrap(),
        );
        let prof = lift_sounding(&load(name), Adiabat::Pseudo);
        let z = prof.lcl_height_m.expect("saturates");
        assert!(
            (z - z_ref).abs() < LCL_HEIGHT_TOLERANCE_M,
            "{name}: LCL {z:.1} m vs MetPy {z_ref:.1} m"
        );
        assert!(
            (prof.lcl.pressure_pa / 100.0 - p_ref).abs() < 1.0,
            "{name}: {} hPa vs {p_ref}",
            prof.lcl.pressure_pa / 100.0
        );
        assert!(
            (prof.lcl.temperature_k - t_ref).abs() < 0.1,
            "{name}: {} K vs {t_ref}",
            prof.lcl.temperature_k
        );
    }
}

#[test]
fn pseudo_adiabat_matches_metpy_within_0_2_k_up_to_3_km_above_lcl() {
    let lcl = read_reference("lcl.csv");
    let rows = read_reference("parcel_profile.csv");
    let mut checked = 0;
    for name in [
        "bomex",
        "continental_summer",
        "tropical_humid",
        "cool_maritime",
    ] {
        let z_lcl: f64 = lcl.iter().find(|r| r[0] == name).expect("listed")[3]
            .parse()
            .unwrap();
        let prof = lift_sounding(&load(name), Adiabat::Pseudo);
        for r in rows.iter().filter(|r| r[0] == name) {
            let (z, t_ref): (f64, f64) = (r[1].parse().unwrap(), r[3].parse().unwrap());
            if z > z_lcl + 3000.0 {
                continue;
            }
            let row = prof
                .rows
                .iter()
                .find(|p| (p.height_m - z).abs() < 1e-6)
                .expect("same levels");
            assert!(
                (row.parcel_t_k - t_ref).abs() < MOIST_ADIABAT_TOLERANCE_K,
                "{name} at {z} m: {:.3} K vs MetPy {t_ref:.3} K",
                row.parcel_t_k
            );
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked} levels compared");
}

#[test]
fn hydrostatic_fill_matches_metpy_hypsometric_pressures() {
    // cool_maritime gives only the surface pressure; the reference filled
    // the rest with MetPy's virtual temperature and the hypsometric equation.
    let s = load("cool_maritime");
    let rows = read_reference("parcel_profile.csv");
    for r in rows.iter().filter(|r| r[0] == "cool_maritime") {
        let (z, p_ref): (f64, f64) = (r[1].parse().unwrap(), r[2].parse().unwrap());
        let l = s
            .levels()
            .iter()
            .find(|l| (l.height_m - z).abs() < 1e-6)
            .expect("same levels");
        let p = l.pressure_pa.expect("filled") / 100.0;
        // 0.05 hPa ≈ 0.5 m of height: far inside the LCL tolerance.
        assert!((p - p_ref).abs() < 0.05, "{z} m: {p} hPa vs {p_ref}");
    }
}

/// The pseudo-adiabat is integrated level to level: its work grows with the
/// pressure span (one RK4 step per `PSEUDO_STEP_PA` plus one per level),
/// not with levels times span (re-integrating from the LCL for every
/// level takes about 1 s for 2,501 levels).
#[test]
fn pseudo_profile_work_is_linear_in_levels() {
    use cumulus::sim::lift::PSEUDO_STEP_PA;
    let s = Sounding::analytic_tropical(2501);
    let prof = lift_sounding(&s, Adiabat::Pseudo);
    let span = prof.lcl.pressure_pa - prof.rows.last().expect("rows").pressure_pa;
    let bound = (span / PSEUDO_STEP_PA).ceil() as usize + s.levels().len();
    assert!(
        prof.rk4_steps <= bound,
        "{} steps > {bound}",
        prof.rk4_steps
    );
    // The same temperatures as one integration from the LCL to each level.
    for r in prof.rows.iter().step_by(100) {
        if r.pressure_pa < prof.lcl.pressure_pa {
            let direct = cumulus::sim::lift::pseudo_adiabat(
                prof.lcl.temperature_k,
                prof.lcl.pressure_pa,
                r.pressure_pa,
            );
            assert!((r.parcel_t_k - direct).abs() < 2e-5, "{r:?} vs {direct}");
        }
    }
}

/// The exact reversible adiabat's tolerance up to 12 km, K (the issue's
/// 0.3 K; the reference uses MetPy's gas constants, which differ from ours
/// in the fifth digit).
const REVERSIBLE_TOLERANCE_K: f64 = 0.3;

/// `cumulus profile --adiabat reversible` on a deep tropical column against
/// an independent solution of conserved reversible moist entropy (Emanuel
/// 1994, Eq. 4.5.9) with MetPy's constants,
/// `tests/reference/reversible_reference.py`. A linearised θ_l ran 7 K warm
/// at 12 km.
#[test]
fn reversible_adiabat_conserves_moist_entropy_to_12_km() {
    let s = Sounding::load(&root().join("tests/data/deep_tropical.csv"), 101_000.0)
        .expect("valid sounding");
    let prof = lift_sounding(&s, Adiabat::Reversible);
    let rows = read_reference("reversible_deep_tropical.csv");
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for r in rows {
        let z: f64 = r[0].parse().expect("height");
        if z > 12_000.0 {
            continue;
        }
        let t_ref: f64 = r[2].parse().expect("T");
        let row = prof
            .rows
            .iter()
            .find(|x| (x.height_m - z).abs() < 0.05)
            .expect("same levels");
        let d = row.parcel_t_k - t_ref;
        worst = worst.max(d.abs());
        assert!(
            d.abs() <= REVERSIBLE_TOLERANCE_K,
            "{z} m: {} K against {t_ref} K",
            row.parcel_t_k
        );
        checked += 1;
    }
    eprintln!("reversible adiabat: worst {worst:.3} K over {checked} levels to 12 km");
    assert!(checked > 100);
}

/// The simulator's own conserved pair (θ_l, q_t) against the same exact
/// reversible reference: a parcel carrying the surface air's θ_l and q_t,
/// placed at each reference pressure, is diagnosed by the simulator's
/// saturation adjustment. A linearised θ_l runs 7 K warm at 12 km (0.3 K
/// off by 2.7 km).
#[test]
fn simulator_parcels_follow_the_exact_reversible_adiabat_to_12_km() {
    use cumulus::sim::config::PhysicsConfig;
    use cumulus::sim::{Atmosphere, Simulation};
    use glam::DVec3;

    let s = Sounding::load(&root().join("tests/data/deep_tropical.csv"), 101_000.0)
        .expect("valid sounding");
    let atm = Atmosphere::from_sounding(&s);
    let surface = atm.at(0.0);
    let mut cfg = PhysicsConfig::default();
    cfg.recycling.enabled = false;
    let mut sim = Simulation::with_positions(cfg, atm.clone(), &[DVec3::ZERO]);
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for r in read_reference("reversible_deep_tropical.csv") {
        let z_ref: f64 = r[0].parse().expect("height");
        if z_ref > 12_000.0 {
            continue;
        }
        let p_ref: f64 = r[1].parse().expect("pressure");
        let t_ref: f64 = r[2].parse().expect("T");
        let z = atm.height_at_pressure(p_ref).expect("inside the column");
        let env = atm.at(z);
        sim.set_parcel(
            0,
            DVec3::new(0.0, 0.0, z),
            surface.theta_l - env.theta_l,
            surface.qt - env.qt,
        );
        let d = sim.parcels().diag[0].t_k - t_ref;
        worst = worst.max(d.abs());
        assert!(
            d.abs() <= REVERSIBLE_TOLERANCE_K,
            "{z_ref} m ({p_ref} Pa): simulator {} K against {t_ref} K",
            sim.parcels().diag[0].t_k
        );
        checked += 1;
    }
    eprintln!("simulator's reversible adiabat: worst {worst:.3} K over {checked} levels");
    assert!(checked > 100);
}
