//! Moist thermodynamics of a parcel: saturation, potential temperatures,
//! and the implicit saturation adjustment.
//!
//! The parcel's prognostic variables are the conserved pair (liquid-water
//! potential temperature `θ_l`, total water `q_t`); temperature, vapour and
//! condensate are diagnosed from them at a pressure by [`saturation_adjust`].
//! Moving a parcel therefore changes neither `θ_l` nor `q_t`, by
//! construction rather than by tolerance.
//!
//! `θ_l` is the exact one of Emanuel (1994, Eq. 4.5.15), a function of the
//! reversible moist entropy and `q_t` alone, so a saturated parcel that
//! carries its condensate follows the exact reversible adiabat to any
//! height (the linearised `T = Π θ_l + L_v q_c / c_p` runs 7 K too warm
//! at 12 km in a tropical column). Unsaturated air rises on the
//! adiabat of moist air, `T ∝ p^χ` with `χ = (R_d + r_t R_v)/(c_pd + r_t
//! c_pv)`, the adiabat the LCL (Romps 2017) is computed on (up to the
//! fifth digit of R_v: Ambaum's here, 461.5 J/(kg K) in `lift`).

use super::constants::{C_P, EPSILON, KAPPA, L_V, P0, R_D, VIRTUAL_COEFF, ZERO_CELSIUS_K};

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
    let t = t_k.max(1.0);
    ln_saturation_vapour_pressure(t, t.ln()).exp()
}

/// `ln e_s(T)` from `T` and `ln T` (Ambaum's form as one sum of logs, so a
/// caller that has `ln T` pays one `exp` for `e_s`, no `powf`).
#[inline]
pub(crate) fn ln_saturation_vapour_pressure(t: f64, ln_t: f64) -> f64 {
    use ambaum::*;
    E0_PA.ln()
        + (CP_L - CP_V) / R_V * (T0_K.ln() - ln_t)
        + (L0 / T0_K - latent_heat_at(t) / t) / R_V
}

/// `d ln e_s / dT = L(T) / (R_v T²)`, 1/K: Clausius-Clapeyron holds exactly
/// for Ambaum's form.
#[inline]
pub(crate) fn dln_es_dt(t_k: f64) -> f64 {
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

/// Heat capacity `c_pd + r_t c_pv` (J/(kg K) per kg of dry air) and the
/// exponents `χ = (R_d + r_t R_v)/(c_pd + r_t c_pv)` and
/// `γ = r_t R_v/(c_pd + r_t c_pv)` of moist air with total water `r_t`.
#[derive(Debug, Clone, Copy)]
struct MoistExponents {
    c: f64,
    chi: f64,
    gamma: f64,
}

impl MoistExponents {
    #[inline]
    fn new(rt: f64) -> Self {
        let c = C_P + rt * ambaum::CP_V;
        Self {
            c,
            chi: (R_D + rt * ambaum::R_V) / c,
            gamma: rt * ambaum::R_V / c,
        }
    }
}

/// `ln θ_l` of air at `ln T`, pressure `p_pa`, total water `rt` of which
/// `rl` is condensate (mixing ratios, kg/kg).
#[inline]
fn ln_theta_l(x: &MoistExponents, ln_t: f64, t: f64, p_pa: f64, rt: f64, rl: f64) -> f64 {
    // All water condensed (only where e_s underflows): keep ln r_v finite.
    let rv = (rt - rl).max(f64::MIN_POSITIVE);
    let mut y = ln_t + x.chi * ((P0 / p_pa) * (EPSILON + rv) / (EPSILON + rt)).ln();
    if rl > 0.0 {
        y -= x.gamma * (rv / rt).ln() + latent_heat_at(t) * rl / (x.c * t);
    }
    y
}

/// Liquid-water potential temperature, K, of air at `t_k`, `p_pa` with
/// total water `qt` of which `qc` is condensate (kg/kg), exactly as
/// Emanuel (1994, Eq. 4.5.15):
/// `θ_l = T (p0/p)^χ (1 - r_l/(ε + r_t))^χ (1 - r_l/r_t)^(-γ)
/// exp(-L_v(T) r_l / ((c_pd + r_t c_pv) T))`.
///
/// It is the temperature the air would have if all its condensate were
/// evaporated and it were brought reversibly to `p0`; a function of the
/// moist entropy and `r_t` only. For dry air it is `θ`.
#[inline]
pub fn liquid_water_potential_temperature(t_k: f64, p_pa: f64, qt: f64, qc: f64) -> f64 {
    let qt = qt.max(0.0);
    let qc = qc.clamp(0.0, qt);
    ln_theta_l(&MoistExponents::new(qt), t_k.ln(), t_k, p_pa, qt, qc).exp()
}

/// Temperature, K, of unsaturated air with liquid-water potential
/// temperature `theta_l` and water `qt` at `p_pa`: `θ_l (p/p0)^χ`.
#[inline]
pub fn unsaturated_temperature(theta_l: f64, qt: f64, p_pa: f64) -> f64 {
    let qt = qt.max(0.0);
    let x = MoistExponents::new(qt);
    theta_l * (p_pa / P0).powf(x.chi)
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

/// Most iterations of the saturation adjustment (it stops once a step is
/// below 1e-9 K). Newton from the linearised guess takes 3-6 in cumulus and
/// tropical columns; the bracket's bisection steps bound the rest.
pub const ADJUST_ITERATIONS: usize = 40;

/// Saturation adjustment: given the conserved `θ_l` (K) and `q_t` (kg/kg) at
/// pressure `p_pa`, find `T`, `q_v`, `q_c` such that
/// [`liquid_water_potential_temperature`]`(T, p, q_t, q_c) = θ_l` and either
/// `q_c = 0` (sub-saturated) or `q_v = q_s(T, p)`.
///
/// Implicit: Newton on `T` for `ln θ_l` with its exact derivative, from the
/// linearised guess `T_u + L_v Δq / (c (1 + L_v q_s' / c))` (`T_u` the
/// unsaturated temperature, `c = c_pd + r_t c_pv`), safeguarded by a
/// bracket that every evaluation narrows: it starts as `[T_u, T_u + 1.01
/// L_v(T_u) q_t / c]`, and a Newton step that leaves it, or lands where all
/// the water would be vapour, is replaced by bisection. Stable for any
/// state; exact in `q_t` (`q_v + q_c == q_t`).
#[inline]
pub fn saturation_adjust(theta_l: f64, qt: f64, p_pa: f64) -> Adjusted {
    let qt = qt.max(0.0);
    let x = MoistExponents::new(qt);
    let ln_p = p_pa.ln();
    let t_u = theta_l * (x.chi * (ln_p - P0.ln())).exp();
    // Unsaturated at the unsaturated temperature: no condensate at all.
    let (qs_u, dqs_u) = saturation_mixing_ratio_and_slope(t_u, p_pa);
    if qt <= qs_u || !t_u.is_finite() {
        return Adjusted {
            t_k: t_u,
            qv: qt,
            qc: 0.0,
        };
    }
    // At T_u, with condensate, ln θ_l is below the target; at the
    // temperature where all the water is vapour it is above (f > 0 there),
    // and the root is below T_u + L_v(T_u) q_t / c (L_v falls with T).
    let l_c = L_V / x.c;
    let (mut lo, mut hi) = (t_u, t_u + 1.01 * latent_heat_at(t_u) * qt / x.c);
    let mut t = (t_u + l_c * (qt - qs_u) / (1.0 + l_c * dqs_u)).clamp(lo, hi);
    // Saturated, with e = e_s(T) and p_d = p - e: ε + q_s = ε p / p_d and
    // ln q_s = ln ε + ln e - ln p_d, so
    // ln θ_l = ln T - χ ln p_d - γ (ln e - ln p_d) - L_v r_l / (c T) + c0,
    // three transcendentals a step (ln T, e from ln e, ln p_d).
    let c0 =
        x.chi * (P0.ln() + EPSILON.ln() - (EPSILON + qt).ln()) - x.gamma * (EPSILON.ln() - qt.ln());
    let target = theta_l.ln() - c0;
    let (mut qs, mut dqs_last, mut last_step) = (qs_u, 0.0, f64::INFINITY);
    for _ in 0..ADJUST_ITERATIONS {
        let ln_t = t.ln();
        let ln_e = ln_saturation_vapour_pressure(t, ln_t);
        let e = ln_e.exp();
        let pd = p_pa - e;
        let q = if pd > e * EPSILON {
            EPSILON * e / pd
        } else {
            qt
        };
        let next = if q >= qt {
            // All the water would be vapour: above the root.
            hi = t;
            last_step = f64::INFINITY;
            0.5 * (lo + hi)
        } else {
            let ln_pd = pd.ln();
            let rl = qt - q;
            let lv = latent_heat_at(t);
            let inv_ct = 1.0 / (x.c * t);
            let f = ln_t - x.chi * ln_pd - x.gamma * (ln_e - ln_pd) - lv * rl * inv_ct - target;
            if f < 0.0 {
                lo = t;
            } else {
                hi = t;
            }
            // dq_s/dT = q_s (p / p_d) L / (R_v T²); the χ and γ terms in
            // closed form (no division by q_s, which can underflow).
            let k = lv / (ambaum::R_V * t * t);
            let dqs = q * p_pa / pd * k;
            let slope = 1.0 / t + x.chi * e / pd * k - x.gamma * p_pa / pd * k
                + ((ambaum::CP_L - ambaum::CP_V) * rl + lv * dqs) * inv_ct
                + lv * rl * inv_ct / t;
            let newton = t - f / slope;
            let next = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            (qs, dqs_last, last_step) = (q, dqs, next - t);
            next
        };
        let moved = (next - t).abs();
        t = next;
        if moved < 1e-9 || hi - lo < 1e-9 {
            break;
        }
    }
    // q_s at the final T: after a step below 1e-6 K the linear update is
    // exact to round-off; otherwise it is evaluated again.
    let qs = if last_step.abs() < 1e-6 {
        (qs + dqs_last * last_step).min(qt)
    } else {
        saturation_mixing_ratio(t, p_pa).min(qt)
    };
    Adjusted {
        t_k: t,
        qv: qs,
        qc: qt - qs,
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
        let t0: f64 = 285.0;
        let qt = saturation_mixing_ratio(t0, p) + 0.003;
        let theta_l = liquid_water_potential_temperature(t0, p, qt, 0.0);
        let a = saturation_adjust(theta_l, qt, p);
        let qs = saturation_mixing_ratio(a.t_k, p);
        assert!(
            (a.qv - qs).abs() < 1e-12 * qs.max(1e-3),
            "qv {} qs {}",
            a.qv,
            qs
        );
        assert_eq!(a.qv + a.qc, qt);
        let back = liquid_water_potential_temperature(a.t_k, p, qt, a.qc);
        assert!((back - theta_l).abs() < 1e-9, "{back} vs {theta_l}");
        assert!(a.qc > 0.0 && a.t_k > t0);
    }

    #[test]
    fn adjustment_inverts_theta_l_over_the_troposphere() {
        // Saturated states from the tropical surface to 150 hPa and cold
        // arctic air: the adjustment recovers the temperature that made θ_l.
        for (t, p, extra) in [
            (300.0, 100_000.0, 1e-4),
            (295.0, 90_000.0, 5e-3),
            (260.0, 50_000.0, 2e-3),
            (220.0, 15_000.0, 1e-3),
            (240.0, 80_000.0, 1e-6),
            // Extreme air (q_t 40-80 g/kg aloft, found to 2-cycle an
            // unbracketed Newton) and cold air where L_v(T) > L_v(T_0).
            (288.3, 32_000.0, 0.03),
            (300.0, 50_000.0, 0.05),
            (305.0, 60_000.0, 0.02),
            (160.0, 10_000.0, 1e-5),
            (150.0, 5_000.0, 1e-6),
        ] {
            let qs = saturation_mixing_ratio(t, p);
            let qt = qs + extra;
            let theta_l = liquid_water_potential_temperature(t, p, qt, extra);
            let a = saturation_adjust(theta_l, qt, p);
            assert!((a.t_k - t).abs() < 1e-7, "{t} K {p} Pa: {}", a.t_k);
            let back = liquid_water_potential_temperature(a.t_k, p, qt, a.qc);
            assert!(
                (back - theta_l).abs() < 1e-9 * theta_l,
                "{t} K {p} Pa: θ_l {back}"
            );
            assert!(
                (a.qc - extra).abs() < 1e-10 * qt.max(1e-3),
                "{} vs {extra}",
                a.qc
            );
        }
    }

    #[test]
    fn dry_theta_l_is_theta() {
        for (t, p) in [(290.0, 95_000.0), (230.0, 20_000.0)] {
            let th = liquid_water_potential_temperature(t, p, 0.0, 0.0);
            assert!((th - potential_temperature(t, p)).abs() < 1e-10 * th);
        }
    }

    #[test]
    fn subsaturated_parcel_has_no_condensate() {
        let p = 100_000.0;
        let a = saturation_adjust(300.0, 0.005, p);
        assert_eq!(a.qc, 0.0);
        assert_eq!(a.qv, 0.005);
        assert!((a.t_k - unsaturated_temperature(300.0, 0.005, p)).abs() < 1e-12);
        // Moist air's adiabat is slightly less steep than dry air's.
        let b = saturation_adjust(300.0, 0.005, 80_000.0);
        assert!(b.qc == 0.0 && b.t_k > 300.0 * exner(80_000.0));
    }
}
