//! Tests of `lift.rs`: the LCL, the adiabats' convergence and
//! conservation, and the lifted parcel's table reads.

use super::*;

/// The vapour a pseudo-adiabatic level reports is the nodes' Hermite
/// interpolation of `q_s`: the saturation mixing ratio of the level's
/// own temperature and pressure to within 2e-9 kg/kg (a fifth of the
/// last digit `cumulus profile` prints; measured 1.05e-9) and 1e-4 of
/// itself (the relative error grows where `q_s` is a few mg/kg, near
/// 100 hPa; measured 7.5e-5).
#[test]
fn the_interpolated_vapour_is_the_levels_saturation() {
    let s = Sounding::analytic_tropical(4001);
    let p: Vec<f64> = s
        .levels()
        .iter()
        .map(|l| l.pressure_pa.unwrap_or(0.0))
        .collect();
    let lv = s.levels()[0];
    let lifted = lift_parcel(lv.temperature_k, lv.mixing_ratio, p[0], &p, Adiabat::Pseudo);
    let (mut worst, mut worst_rel) = (0.0_f64, 0.0_f64);
    let mut above = 0;
    for (&pk, l) in p.iter().zip(&lifted.levels) {
        if pk < lifted.lcl.pressure_pa {
            let qs = saturation_mixing_ratio(l.t_k, pk);
            worst = worst.max((l.qv - qs).abs());
            worst_rel = worst_rel.max((l.qv - qs).abs() / qs);
            above += 1;
        }
    }
    eprintln!("interpolated q_s: worst {worst:e} kg/kg, {worst_rel:e} relative");
    assert!(above > 3000, "{above} levels above the LCL");
    assert!(worst < 2e-9, "{worst:e} kg/kg");
    assert!(worst_rel < 1e-4, "relative error {worst_rel:e}");
}

/// `lift_parcel` (what the Python package's `parcel_profile` calls)
/// answers each pressure alone: any order gives the same state, and
/// the levels of a sounding give `lift_sounding`'s rows.
#[test]
fn a_lifted_parcel_does_not_depend_on_the_order_of_its_pressures() {
    let falling: Vec<f64> = (0..60).map(|i| 101_000.0 - 1_500.0 * i as f64).collect();
    let mut shuffled = falling.clone();
    shuffled.reverse();
    shuffled.rotate_left(17);
    for how in [Adiabat::Pseudo, Adiabat::Reversible] {
        let a = lift_parcel(300.0, 0.016, falling[0], &falling, how);
        let b = lift_parcel(300.0, 0.016, falling[0], &shuffled, how);
        for (p, lb) in shuffled.iter().zip(&b.levels) {
            let k = falling.iter().position(|q| q == p).expect("same pressures");
            let la = a.levels[k];
            assert!((la.t_k - lb.t_k).abs() < 1e-7, "{how:?} at {p} Pa");
            assert!((la.qc - lb.qc).abs() < 1e-10, "{how:?} at {p} Pa");
        }
    }
    let s = Sounding::analytic_tropical(41);
    let prof = lift_sounding(&s, Adiabat::Reversible);
    let p: Vec<f64> = prof.rows.iter().map(|r| r.pressure_pa).collect();
    let lv = s.levels()[0];
    let alone = lift_parcel(
        lv.temperature_k,
        lv.mixing_ratio,
        p[0],
        &p,
        Adiabat::Reversible,
    );
    for (r, l) in prof.rows.iter().zip(&alone.levels) {
        assert_eq!(r.parcel_t_k, l.t_k);
    }
}

#[test]
fn lcl_lies_on_dry_adiabat_and_dewpoint() {
    let (t, p) = (300.0, 100_000.0);
    let q = saturation_mixing_ratio(290.0, p);
    let l = lcl(t, q, p);
    let td = dewpoint(q, l.pressure_pa).expect("moist");
    assert!((l.temperature_k - td).abs() < 1e-4, "{l:?} td {td}");
    // Bolton (1980) Eq. 15 estimate of T_LCL agrees within 0.1 K.
    let bolton = 1.0 / (1.0 / (290.0 - 56.0) + (300.0_f64 / 290.0).ln() / 800.0) + 56.0;
    assert!(
        (l.temperature_k - bolton).abs() < 0.1,
        "{} vs {bolton}",
        l.temperature_k
    );
}

/// 1000-100 hPa with PSEUDO_STEP_PA steps against 5 Pa steps: below
/// MetPy 1.7's own integration error of its `moist_lapse` (7.7e-5 K
/// against solve_ivp at rtol 1e-12, `benches/metpy_profile_timing.py`).
const STEP_ERROR_K: f64 = 2e-5;

#[test]
fn pseudo_adiabat_steps_converge() {
    for t0 in [260.0, 285.0, 300.0, 305.0] {
        let coarse = pseudo_adiabat(t0, 100_000.0, 10_000.0);
        let fine = pseudo_adiabat_with_step(t0, 100_000.0, 10_000.0, 5.0);
        eprintln!("T0 {t0} K: {:.1e} K from 5 Pa steps", (coarse - fine).abs());
        assert!(
            (coarse - fine).abs() < STEP_ERROR_K,
            "{t0}: {coarse} vs {fine}"
        );
        // Level to level gives the same as in one go.
        let mut t = t0;
        let mut p = 100_000.0;
        for k in 1..=90 {
            let p1 = 100_000.0 - 1_000.0 * k as f64;
            t = pseudo_adiabat(t, p, p1);
            p = p1;
        }
        assert!(
            (t - fine).abs() < STEP_ERROR_K,
            "{t0}: level to level {t} vs {fine}"
        );
    }
}

#[test]
fn pseudo_adiabat_conserves_bolton_equivalent_potential_temperature() {
    // Bolton's (1980) Eq. 43 θ_E is an empirical fit; along the exact
    // pseudo-adiabat it drifts by ~0.9 K over 950-600 hPa, so this is a
    // sanity bound only. The tight check is against MetPy
    // (tests/physics_reference.rs, 0.2 K).
    let thetae = |t: f64, p: f64| {
        let r = saturation_mixing_ratio(t, p) * 1e3;
        t * (100_000.0 / p).powf(0.2854 * (1.0 - 0.28e-3 * r))
            * ((3.376 / t - 0.00254) * r * (1.0 + 0.81e-3 * r)).exp()
    };
    let t1 = pseudo_adiabat(295.0, 95_000.0, 60_000.0);
    let (a, b) = (thetae(295.0, 95_000.0), thetae(t1, 60_000.0));
    assert!((a - b).abs() < 1.5, "{a} {b} {t1}");
    assert!(t1 < 295.0 - 15.0);
}
