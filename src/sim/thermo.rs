//! Moist thermodynamics of a parcel: saturation, potential temperatures,
//! and the implicit saturation adjustment.
//!
//! The parcel's prognostic variables are the conserved pair (liquid-water
//! potential temperature `θ_l`, total water `q_t`); temperature, vapour and
//! condensate are diagnosed from them at a pressure by [`saturation_adjust`].
//! Moving a parcel therefore changes neither `θ_l` nor `q_t`: dry ascent
//! conserves `θ` exactly and `q_t` is conserved without mixing, by
//! construction rather than by tolerance.

use super::constants::{C_P, EPSILON, KAPPA, L_V, P0, VIRTUAL_COEFF, ZERO_CELSIUS_K};

/// Exner function `Π = (p / p0)^κ`, `p` in Pa.
#[inline]
pub fn exner(p_pa: f64) -> f64 {
    (p_pa / P0).powf(KAPPA)
}

/// Constants of Ambaum's (2020) saturation vapour pressure, as MetPy
/// defines them: `e_s` at the triple point (Pa), the triple point (K), the
/// specific heats of liquid water and vapour and the vapour gas constant
/// (J/(kg K)), and `L_v` at the triple point (J/kg).
mod ambaum {
    pub const E0_PA: f64 = 611.2;
    pub const T0_K: f64 = 273.16;
    pub const CP_L: f64 = 4_219.4;
    pub const CP_V: f64 = 1_860.078_011_865_639;
    pub const R_V: f64 = 461.523_115_726_060_84;
    pub const L0: f64 = 2.500_84e6;
}

/// Latent heat of vaporisation at `t_k`, J/kg: `L_0 - (c_pl - c_pv)(T - T_0)`
/// (Ambaum 2020, Eq. 15).
#[inline]
pub fn latent_heat_at(t_k: f64) -> f64 {
    use ambaum::*;
    L0 - (CP_L - CP_V) * (t_k - T0_K)
}

/// Saturation vapour pressure over liquid water, Pa, `T` in K: Ambaum
/// (2020), Eq. 13, `e_s = e_0 (T_0/T)^((c_pl - c_pv)/R_v)
/// exp(L_0/(R_v T_0) - L(T)/(R_v T))`, the form MetPy uses since 1.6.
///
/// The usual choice is Bolton (1980); Ambaum's form is exact for a
/// temperature-dependent `L_v`, and Bolton's differs from it by up to 0.3 %
/// at 40 °C, which moved hot, humid LCLs by up to 18 m against MetPy 1.7.
#[inline]
pub fn saturation_vapour_pressure(t_k: f64) -> f64 {
    use ambaum::*;
    let t = t_k.max(1.0);
    E0_PA * (T0_K / t).powf((CP_L - CP_V) / R_V) * ((L0 / T0_K - latent_heat_at(t) / t) / R_V).exp()
}

/// `d ln e_s / dT = L(T) / (R_v T²)`, 1/K: Clausius-Clapeyron holds exactly
/// for Ambaum's form.
#[inline]
fn dln_es_dt(t_k: f64) -> f64 {
    latent_heat_at(t_k) / (ambaum::R_V * t_k * t_k)
}

/// Saturation mixing ratio `q_s = ε e_s / (p - e_s)`, kg/kg.
///
/// Where `e_s` approaches `p` (very hot or very low pressure) the mixing
/// ratio is unbounded; it is capped at 1 kg/kg so that every state stays
/// finite (the stability matrix, `tests/stability.rs`, relies on it).
#[inline]
pub fn saturation_mixing_ratio(t_k: f64, p_pa: f64) -> f64 {
    let es = saturation_vapour_pressure(t_k);
    let denom = p_pa - es;
    if denom <= es * EPSILON {
        1.0
    } else {
        (EPSILON * es / denom).min(1.0)
    }
}

/// `q_s(T, p)` and its exact derivative `dq_s/dT` (1/K): Newton with the
/// exact slope converges quadratically.
#[inline]
pub fn saturation_mixing_ratio_and_slope(t_k: f64, p_pa: f64) -> (f64, f64) {
    let es = saturation_vapour_pressure(t_k);
    let denom = p_pa - es;
    if denom <= es * EPSILON {
        return (1.0, 0.0);
    }
    let qs = EPSILON * es / denom;
    if qs >= 1.0 {
        return (1.0, 0.0);
    }
    (qs, qs * p_pa / denom * dln_es_dt(t_k))
}

/// Vapour mixing ratio (kg/kg) whose dewpoint is `td_k` at pressure `p_pa`.
pub fn mixing_ratio_from_dewpoint(td_k: f64, p_pa: f64) -> f64 {
    saturation_mixing_ratio(td_k, p_pa)
}

/// Dewpoint (K) of vapour mixing ratio `qv` at pressure `p_pa`: the inverse
/// of [`saturation_vapour_pressure`], by Newton on `ln e_s` from Bolton's
/// closed-form inverse (converged to round-off in a few steps). Returns
/// `None` for `qv <= 0` (no dewpoint).
pub fn dewpoint(qv: f64, p_pa: f64) -> Option<f64> {
    if qv <= 0.0 {
        return None;
    }
    let e = qv * p_pa / (EPSILON + qv);
    let ln_e = e.ln();
    let b = (e / 611.2).ln();
    let mut t = (ZERO_CELSIUS_K + 243.5 * b / (17.67 - b)).max(20.0);
    for _ in 0..8 {
        let step = (saturation_vapour_pressure(t).ln() - ln_e) / dln_es_dt(t);
        t = (t - step).max(20.0);
        if step.abs() < 1e-12 * t {
            break;
        }
    }
    Some(t)
}

/// Potential temperature `θ = T / Π`, K.
#[inline]
pub fn potential_temperature(t_k: f64, p_pa: f64) -> f64 {
    t_k / exner(p_pa)
}

/// Virtual potential temperature with condensate loading,
/// `θ_v = θ (1 + 0.608 q_v - q_c)`, K.
#[inline]
pub fn virtual_potential_temperature(theta_k: f64, qv: f64, qc: f64) -> f64 {
    theta_k * (1.0 + VIRTUAL_COEFF * qv - qc)
}

/// Liquid-water potential temperature `θ_l = θ - L_v q_c / (c_p Π)`, K.
#[inline]
pub fn liquid_water_potential_temperature(theta_k: f64, qc: f64, exner: f64) -> f64 {
    theta_k - L_V * qc / (C_P * exner)
}

/// The state of a parcel after saturation adjustment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Adjusted {
    /// Temperature, K.
    pub t_k: f64,
    /// Vapour mixing ratio, kg/kg.
    pub qv: f64,
    /// Condensate mixing ratio, kg/kg.
    pub qc: f64,
}

/// Most Newton iterations of the saturation adjustment (it stops earlier once
/// a step is at round-off). The first linearised step is already within
/// 0.05 K for cumulus conditions; four reach round-off (tested in
/// `saturation_adjustment_converges`).
pub const ADJUST_ITERATIONS: usize = 4;

/// Saturation adjustment: given the conserved `θ_l` (K) and `q_t` (kg/kg) at
/// pressure `p_pa` with Exner `exner`, find `T`, `q_v`, `q_c` such that
/// `T = Π θ_l + L_v q_c / c_p` and either `q_c = 0` (sub-saturated) or
/// `q_v = q_s(T, p)`.
///
/// Implicit: Newton on `T` with the Clausius-Clapeyron derivative,
/// `Δq = (q_t - q_c - q_s) / (1 + L_v² q_s / (c_p R_v T²))` per iteration,
/// clamped to keep `q_c >= 0`. Stable for any step; exact in `q_t`
/// (`q_v + q_c == q_t` to round-off).
#[inline]
pub fn saturation_adjust(theta_l: f64, qt: f64, p_pa: f64, exner: f64) -> Adjusted {
    let qt = qt.max(0.0);
    let t_l = theta_l * exner;
    // Unsaturated at the liquid-water temperature: no condensate at all.
    if qt <= saturation_mixing_ratio(t_l, p_pa) {
        return Adjusted {
            t_k: t_l,
            qv: qt,
            qc: 0.0,
        };
    }
    let mut qc = 0.0_f64;
    let mut t = t_l;
    for _ in 0..ADJUST_ITERATIONS {
        let (qs, dqs_dt) = saturation_mixing_ratio_and_slope(t, p_pa);
        let qv = qt - qc;
        let slope = 1.0 + L_V / C_P * dqs_dt;
        let dq = ((qv - qs) / slope).max(-qc).min(qv);
        qc += dq;
        t = t_l + L_V * qc / C_P;
        // Quadratic convergence: once the step is at round-off, stop.
        if dq.abs() <= 1e-15 * qt {
            break;
        }
    }
    Adjusted {
        t_k: t,
        qv: qt - qc,
        qc,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dewpoint_inverts_saturation_mixing_ratio() {
        let p = 90_000.0;
        for td in [250.0, 270.0, 290.0, 300.0] {
            let q = mixing_ratio_from_dewpoint(td, p);
            let back = dewpoint(q, p).expect("positive q has a dewpoint");
            assert!((back - td).abs() < 1e-9, "{td} -> {back}");
        }
        assert!(dewpoint(0.0, p).is_none());
    }

    #[test]
    fn saturation_adjustment_converges() {
        // A parcel 3 g/kg supersaturated at 850 hPa: after adjustment it is
        // saturated at its new temperature and conserves q_t and θ_l.
        let p = 85_000.0;
        let ex = exner(p);
        let t0: f64 = 285.0;
        let qt = saturation_mixing_ratio(t0, p) + 0.003;
        let theta_l = t0 / ex;
        let a = saturation_adjust(theta_l, qt, p, ex);
        let qs = saturation_mixing_ratio(a.t_k, p);
        assert!(
            (a.qv - qs).abs() < 1e-12 * qs.max(1e-3),
            "qv {} qs {}",
            a.qv,
            qs
        );
        assert_eq!(a.qv + a.qc, qt);
        let back = liquid_water_potential_temperature(a.t_k / ex, a.qc, ex);
        assert!((back - theta_l).abs() < 1e-9);
        assert!(a.qc > 0.0 && a.t_k > t0);
    }

    #[test]
    fn subsaturated_parcel_has_no_condensate() {
        let p = 100_000.0;
        let ex = exner(p);
        let a = saturation_adjust(300.0, 0.005, p, ex);
        assert_eq!(a.qc, 0.0);
        assert_eq!(a.qv, 0.005);
        assert!((a.t_k - 300.0 * ex).abs() < 1e-12);
    }
}
