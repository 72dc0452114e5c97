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

/// Saturation vapour pressure over water, Pa (Bolton 1980, `T` in K).
#[inline]
pub fn saturation_vapour_pressure(t_k: f64) -> f64 {
    let tc = t_k - ZERO_CELSIUS_K;
    611.2 * (17.67 * tc / (tc + 243.5)).exp()
}

/// Saturation mixing ratio `q_s = ε e_s / (p - e_s)`, kg/kg.
///
/// Where `e_s` approaches `p` (very hot or very low pressure) the mixing
/// ratio is unbounded; it is capped at 1 kg/kg so that every state stays
/// finite (physics.md section 4).
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

/// `q_s(T, p)` and its exact derivative `dq_s/dT` (1/K) for Bolton's
/// formula: Newton with the exact slope converges quadratically (the
/// Clausius-Clapeyron estimate `L_v q_s / (R_v T²)` only linearly).
#[inline]
pub fn saturation_mixing_ratio_and_slope(t_k: f64, p_pa: f64) -> (f64, f64) {
    let tc = t_k - ZERO_CELSIUS_K;
    let es = 611.2 * (17.67 * tc / (tc + 243.5)).exp();
    let denom = p_pa - es;
    if denom <= es * EPSILON {
        return (1.0, 0.0);
    }
    let qs = EPSILON * es / denom;
    if qs >= 1.0 {
        return (1.0, 0.0);
    }
    let dln_es = 17.67 * 243.5 / ((tc + 243.5) * (tc + 243.5));
    (qs, qs * p_pa / denom * dln_es)
}

/// Vapour mixing ratio (kg/kg) whose dewpoint is `td_k` at pressure `p_pa`.
pub fn mixing_ratio_from_dewpoint(td_k: f64, p_pa: f64) -> f64 {
    saturation_mixing_ratio(td_k, p_pa)
}

/// Dewpoint (K) of vapour mixing ratio `qv` at pressure `p_pa`: the inverse
/// of Bolton's formula. Returns `None` for `qv <= 0` (no dewpoint).
pub fn dewpoint(qv: f64, p_pa: f64) -> Option<f64> {
    if qv <= 0.0 {
        return None;
    }
    let e = qv * p_pa / (EPSILON + qv);
    let ln = (e / 611.2).ln();
    Some(ZERO_CELSIUS_K + 243.5 * ln / (17.67 - ln))
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
