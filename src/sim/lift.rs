//! Lifting a surface parcel without mixing (what MetPy's `parcel_profile`
//! does): the unsaturated adiabat of the moist air to the lifting
//! condensation level (Romps 2017), then a moist adiabat, either
//! pseudo-adiabatic (condensate falls out) or reversible (condensate
//! carried: total water and moist entropy conserved, Emanuel 1994).

use serde::{Deserialize, Serialize};

use super::atmosphere::Atmosphere;
use super::constants::{C_P, EPSILON, G, L_V, R_D, R_V, VIRTUAL_COEFF};
use super::sounding::Sounding;
use super::thermo::{
    dewpoint, dln_es_dt, latent_heat_at, ln_saturation_vapour_pressure, saturation_mixing_ratio,
    saturation_mixing_ratio_and_slope, saturation_vapour_pressure,
};

/// Which moist adiabat the parcel follows above its LCL.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Adiabat {
    /// Condensate removed as it forms (meteorologists' default).
    #[default]
    Pseudo,
    /// Condensate carried with the parcel.
    Reversible,
}

/// The lifting condensation level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lcl {
    /// Pressure, Pa.
    pub pressure_pa: f64,
    /// Temperature, K.
    pub temperature_k: f64,
}

/// Specific heat of water vapour at constant pressure, J/(kg K) (MetPy's).
const C_PV: f64 = 1_860.078_011_865_639;
/// Specific heat of liquid water, J/(kg K) (MetPy's).
const C_L: f64 = 4_219.4;

/// Poisson exponent `R_m / c_pm` of moist air with vapour mixing ratio `qv`
/// (Romps 2017): the unsaturated adiabat of air that carries its vapour.
pub fn moist_air_kappa(qv: f64) -> f64 {
    let q = qv / (1.0 + qv);
    ((1.0 - q) * R_D + q * R_V) / ((1.0 - q) * C_P + q * C_PV)
}

/// LCL of air at `t_k`, vapour mixing ratio `qv`, pressure `p_pa`: where its
/// unsaturated adiabat, `T (p/p_0)^(R_m/c_pm)` with the moist air's own gas
/// constant and heat capacity, meets the dewpoint of the conserved mixing
/// ratio. This is the problem Romps (2017) solves in closed form (MetPy's
/// `lcl` since 1.6); here by Newton's method in `ln p`, to round-off. With
/// the dry `κ` the LCL
/// of hot, humid air is up to 17 m too low. Saturated (or supersaturated)
/// air is at its LCL.
pub fn lcl(t_k: f64, qv: f64, p_pa: f64) -> Lcl {
    let Some(td0) = dewpoint(qv, p_pa) else {
        // Dry air never condenses: report the top of the atmosphere.
        return Lcl {
            pressure_pa: 0.0,
            temperature_k: 0.0,
        };
    };
    if td0 >= t_k {
        return Lcl {
            pressure_pa: p_pa,
            temperature_k: t_k,
        };
    }
    let kappa = moist_air_kappa(qv);
    // Where the air's temperature meets its dewpoint, its vapour pressure
    // e = p q/(ε + q) meets e_s(T). In x = ln p, with ln T = ln T_0 +
    // κ (x - ln p_0), the gap ln e_s(T) - ln e rises with x (its slope
    // κ L/(R_v T) - 1 is about 4), positive at the ground and negative
    // aloft: Newton, kept inside a bracket that bisects when a step
    // would leave it.
    let (ln_t0, ln_p0) = (t_k.ln(), p_pa.ln());
    let ln_share = (qv / (EPSILON + qv)).ln();
    let gap = |x: f64| {
        let ln_t = ln_t0 + kappa * (x - ln_p0);
        let t = ln_t.exp();
        let g = ln_saturation_vapour_pressure(t, ln_t) - ln_share - x;
        (g, dln_es_dt(t) * kappa * t - 1.0)
    };
    let (mut lo, mut hi) = (0.0_f64, ln_p0);
    let mut x = ln_p0;
    for _ in 0..100 {
        let (g, slope) = gap(x);
        if g > 0.0 {
            hi = x
        } else {
            lo = x
        }
        let newton = x - g / slope;
        let next = if slope > 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        let done = (next - x).abs() < 1e-14 || hi - lo < 1e-14;
        x = next;
        if done {
            break;
        }
    }
    let p = x.exp();
    Lcl {
        pressure_pa: p,
        temperature_k: t_k * (p / p_pa).powf(kappa),
    }
}

/// Pseudo-adiabatic lapse `dT/dp`, K/Pa (the form MetPy's `moist_lapse`
/// integrates): `(R_d T + L_v r_s) / (c_p + L_v² r_s ε / (R_d T²)) / p`.
fn pseudo_lapse(t: f64, p: f64) -> f64 {
    let rs = saturation_mixing_ratio(t, p);
    (R_D * t + L_V * rs) / (C_P + L_V * L_V * rs * EPSILON / (R_D * t * t)) / p
}

/// The longest RK4 step of [`pseudo_adiabat`], Pa. From 1000 to 100 hPa
/// it stays within 1e-5 K of 5 Pa steps (`pseudo_adiabat_steps_converge`):
/// below MetPy's own integration error (7.7e-5 K), and a ten-thousandth of
/// the 0.09 K by which the profile matches MetPy.
pub const PSEUDO_STEP_PA: f64 = 1000.0;

/// Integrates the pseudo-adiabat from `(t, p0)` to `p1` with RK4 in steps of
/// at most [`PSEUDO_STEP_PA`].
pub fn pseudo_adiabat(t: f64, p0: f64, p1: f64) -> f64 {
    pseudo_adiabat_with_step(t, p0, p1, PSEUDO_STEP_PA)
}

fn pseudo_adiabat_with_step(t: f64, p0: f64, p1: f64, max_step_pa: f64) -> f64 {
    let n = rk4_steps(p0, p1, max_step_pa);
    let dp = (p1 - p0) / n as f64;
    let (mut t, mut p) = (t, p0);
    for _ in 0..n {
        let k1 = pseudo_lapse(t, p);
        let k2 = pseudo_lapse(t + 0.5 * dp * k1, p + 0.5 * dp);
        let k3 = pseudo_lapse(t + 0.5 * dp * k2, p + 0.5 * dp);
        let k4 = pseudo_lapse(t + dp * k3, p + dp);
        t += dp / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        p += dp;
    }
    t
}

/// Reversible moist entropy per unit mass of dry air of saturated air with
/// total water `rt` (kg/kg) at `t` (K), `p` (Pa), up to a constant
/// (Emanuel 1994, Eq. 4.5.9 with H = 1), J/(kg K):
/// `(c_pd + r_t c_l) ln T - R_d ln(p - e_s) + L_v(T) r_s / T`, with
/// `L_v(T)` from Kirchhoff's law (as Ambaum's `e_s`).
pub fn saturated_entropy(t: f64, p: f64, rt: f64) -> f64 {
    let es = saturation_vapour_pressure(t).min(0.5 * p);
    let rs = EPSILON * es / (p - es);
    (C_P + rt * C_L) * t.ln() - R_D * (p - es).ln() + latent_heat_at(t) * rs / t
}

/// The temperature at which saturated air with total water `rt` at `p` has
/// the entropy `s` ([`saturated_entropy`]): Newton's method from `guess`
/// (the entropy rises with T, so it converges from any nearby guess).
pub fn reversible_temperature(s: f64, rt: f64, p: f64, guess: f64) -> f64 {
    let mut t = guess;
    for _ in 0..50 {
        let h = 1e-3;
        let f = saturated_entropy(t, p, rt) - s;
        let slope = (saturated_entropy(t + h, p, rt) - saturated_entropy(t - h, p, rt)) / (2.0 * h);
        let dt = (f / slope).clamp(-20.0, 20.0);
        t = (t - dt).max(100.0);
        if dt.abs() < 1e-9 {
            break;
        }
    }
    t
}

/// RK4 steps from `p0` to `p1`.
fn rk4_steps(p0: f64, p1: f64, max_step_pa: f64) -> usize {
    ((p1 - p0).abs() / max_step_pa).ceil().max(1.0) as usize
}

/// The pseudo-adiabat tabulated at RK4 nodes `PSEUDO_STEP_PA` apart,
/// with its lapse rate, the saturation mixing ratio and that ratio's rate
/// of change along the adiabat at each node, for cubic Hermite
/// interpolation of both.
struct PseudoNodes {
    /// Falling pressures, Pa.
    p: Vec<f64>,
    t: Vec<f64>,
    dtdp: Vec<f64>,
    qs: Vec<f64>,
    /// `dq_s/dp` along the adiabat: `∂q_s/∂T dT/dp + ∂q_s/∂p`, 1/Pa.
    dqsdp: Vec<f64>,
}

/// A node's lapse rate (as [`pseudo_lapse`]), saturation mixing ratio and
/// that ratio's rate of change along the adiabat, with
/// `∂q_s/∂p = -q_s (ε + q_s) / (ε p)` at fixed T.
fn node_rates(t: f64, p: f64) -> (f64, f64, f64) {
    let (qs, dqs_dt) = saturation_mixing_ratio_and_slope(t, p);
    let dtdp = (R_D * t + L_V * qs) / (C_P + L_V * L_V * qs * EPSILON / (R_D * t * t)) / p;
    let dqs_dp_at_t = -qs * (EPSILON + qs) / (EPSILON * p);
    (dtdp, qs, dqs_dt * dtdp + dqs_dp_at_t)
}

/// The cubic Hermite basis at `s` in 0..=1: the weights of the two ends'
/// values and slopes (slopes per unit `s`).
fn hermite(s: f64) -> [f64; 4] {
    let (s2, s3) = (s * s, s * s * s);
    [
        2.0 * s3 - 3.0 * s2 + 1.0,
        s3 - 2.0 * s2 + s,
        -2.0 * s3 + 3.0 * s2,
        s3 - s2,
    ]
}

impl PseudoNodes {
    /// From `(t0, p0)` up to `p_top` (< `p0`; none when not): one RK4 step
    /// from node to node, its first stage the node's own lapse rate.
    fn integrate(t0: f64, p0: f64, p_top: f64) -> Self {
        let n = if p_top < p0 {
            rk4_steps(p0, p_top, PSEUDO_STEP_PA)
        } else {
            0
        };
        let dp = if n > 0 { (p_top - p0) / n as f64 } else { 0.0 };
        let mut nodes = Self {
            p: Vec::with_capacity(n + 1),
            t: Vec::with_capacity(n + 1),
            dtdp: Vec::with_capacity(n + 1),
            qs: Vec::with_capacity(n + 1),
            dqsdp: Vec::with_capacity(n + 1),
        };
        let (mut t, mut p) = (t0, p0);
        for k in 0..=n {
            let (k1, qs, dqsdp) = node_rates(t, p);
            nodes.p.push(p);
            nodes.t.push(t);
            nodes.dtdp.push(k1);
            nodes.qs.push(qs);
            nodes.dqsdp.push(dqsdp);
            if k < n {
                let k2 = pseudo_lapse(t + 0.5 * dp * k1, p + 0.5 * dp);
                let k3 = pseudo_lapse(t + 0.5 * dp * k2, p + 0.5 * dp);
                let k4 = pseudo_lapse(t + dp * k3, p + dp);
                t += dp / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                p = p0 + (k + 1) as f64 * dp;
            }
        }
        nodes
    }

    /// The temperature and saturation mixing ratio at `p` (clamped to the
    /// nodes' span). `cursor` is the interval the previous call used:
    /// levels in falling order find theirs without a search.
    fn at(&self, p: f64, cursor: &mut usize) -> (f64, f64) {
        let n = self.p.len();
        if n < 2 {
            let t = self.t.first().copied().unwrap_or(f64::NAN);
            let q = self.qs.first().copied().unwrap_or(f64::NAN);
            return (t, q);
        }
        // The interval whose nodes straddle p (pressures fall): the
        // previous one, the next, or a binary search.
        let within = |k: usize| k + 1 < n && self.p[k] >= p && p >= self.p[k + 1];
        let k = if within(*cursor) {
            *cursor
        } else if within(*cursor + 1) {
            *cursor + 1
        } else {
            self.p.partition_point(|&q| q > p).clamp(1, n - 1) - 1
        };
        *cursor = k;
        let (p0, p1) = (self.p[k], self.p[k + 1]);
        let h = p1 - p0;
        let [a0, b0, a1, b1] = hermite(((p - p0) / h).clamp(0.0, 1.0));
        let t =
            a0 * self.t[k] + b0 * h * self.dtdp[k] + a1 * self.t[k + 1] + b1 * h * self.dtdp[k + 1];
        let q = a0 * self.qs[k]
            + b0 * h * self.dqsdp[k]
            + a1 * self.qs[k + 1]
            + b1 * h * self.dqsdp[k + 1];
        (t, q)
    }
}

/// One level of a lifted parcel's profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileRow {
    pub height_m: f64,
    pub pressure_pa: f64,
    pub env_t_k: f64,
    pub parcel_t_k: f64,
    pub parcel_qv: f64,
    pub parcel_qc: f64,
    /// `g (T_v,parcel - T_v,env) / T_v,env`, m/s².
    pub buoyancy: f64,
}

/// A lifted surface parcel: its LCL (with height) and one row per level.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    pub lcl: Lcl,
    /// Height of the LCL above ground, m (log-pressure interpolation between
    /// levels); `None` if the parcel never saturates within the sounding.
    pub lcl_height_m: Option<f64>,
    pub rows: Vec<ProfileRow>,
    /// RK4 steps taken along the pseudo-adiabat (one table from the LCL to
    /// the top, read by every level): the work grows with the pressure
    /// span, not with levels × span.
    pub rk4_steps: usize,
}

/// The parcel's state at one pressure level of [`lift_parcel`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LiftedLevel {
    /// Temperature, K.
    pub t_k: f64,
    /// Vapour mixing ratio, kg/kg.
    pub qv: f64,
    /// Condensate carried, kg/kg (0 on the pseudo-adiabat).
    pub qc: f64,
}

/// Air lifted without mixing through given pressures: its LCL and its
/// state at each pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct LiftedParcel {
    pub lcl: Lcl,
    /// One per pressure asked, in the same order.
    pub levels: Vec<LiftedLevel>,
    /// RK4 steps taken along the pseudo-adiabat (see [`Profile::rk4_steps`]).
    pub rk4_steps: usize,
}

/// Lifts air at `t0_k`, vapour mixing ratio `qv0` (capped at saturation)
/// and `p0_pa` without mixing through `pressures_pa` (MetPy's
/// `parcel_profile` with the air's mixing ratio in place of its dewpoint):
/// the unsaturated adiabat of the moist air up to the LCL, then the moist
/// adiabat `adiabat`. Pressures may come in any order; the reversible
/// adiabat is solved from the previous level's temperature, so falling
/// pressures are the fast order.
pub fn lift_parcel(
    t0_k: f64,
    qv0: f64,
    p0_pa: f64,
    pressures_pa: &[f64],
    adiabat: Adiabat,
) -> LiftedParcel {
    let q0v = qv0.min(saturation_mixing_ratio(t0_k, p0_pa));
    let lcl = lcl(t0_k, q0v, p0_pa);
    // Reversible: the total water and the moist entropy of the air at its
    // LCL are conserved above it.
    let s_lcl = saturated_entropy(lcl.temperature_k, lcl.pressure_pa, qv0);
    let mut t_rev = lcl.temperature_k;
    // The pseudo-adiabat is integrated once from the LCL to the top level
    // in RK4 steps of PSEUDO_STEP_PA; each level then reads it by cubic
    // Hermite interpolation (the slope is the lapse rate itself), so the
    // work grows with the pressure span, not with levels times span.
    let top = pressures_pa.iter().copied().fold(lcl.pressure_pa, f64::min);
    let nodes = match adiabat {
        Adiabat::Pseudo => PseudoNodes::integrate(lcl.temperature_k, lcl.pressure_pa, top),
        Adiabat::Reversible => {
            PseudoNodes::integrate(lcl.temperature_k, lcl.pressure_pa, lcl.pressure_pa)
        }
    };
    let kappa = moist_air_kappa(q0v);
    let mut cursor = 0;
    let levels = pressures_pa
        .iter()
        .map(|&p| {
            if p >= lcl.pressure_pa {
                // The unsaturated adiabat of the moist air (Romps 2017), the
                // same one the LCL lies on, so the profile is continuous
                // there. (MetPy's parcel_profile uses the dry κ here and so
                // starts its moist adiabat ~0.1 K colder than its own LCL.)
                LiftedLevel {
                    t_k: t0_k * (p / p0_pa).powf(kappa),
                    qv: q0v,
                    qc: 0.0,
                }
            } else {
                match adiabat {
                    Adiabat::Pseudo => {
                        let (t, qv) = nodes.at(p, &mut cursor);
                        LiftedLevel {
                            t_k: t,
                            qv,
                            qc: 0.0,
                        }
                    }
                    Adiabat::Reversible => {
                        t_rev = reversible_temperature(s_lcl, qv0, p, t_rev);
                        let qv = saturation_mixing_ratio(t_rev, p).min(qv0);
                        LiftedLevel {
                            t_k: t_rev,
                            qv,
                            qc: qv0 - qv,
                        }
                    }
                }
            }
        })
        .collect();
    LiftedParcel {
        lcl,
        levels,
        rk4_steps: nodes.p.len().saturating_sub(1),
    }
}

/// Lifts the sounding's lowest level through all its levels.
pub fn lift_sounding(s: &Sounding, adiabat: Adiabat) -> Profile {
    let lv = s.levels();
    let p_of = |i: usize| lv[i].pressure_pa.unwrap_or(f64::NAN);
    let pressures: Vec<f64> = (0..lv.len()).map(p_of).collect();
    let lifted = lift_parcel(
        lv[0].temperature_k,
        lv[0].mixing_ratio,
        pressures[0],
        &pressures,
        adiabat,
    );
    let lcl = lifted.lcl;
    let lcl_height_m = if lcl.pressure_pa >= pressures[0] {
        Some(lv[0].height_m)
    } else {
        (1..lv.len())
            .find(|&i| pressures[i] <= lcl.pressure_pa)
            .map(|i| {
                let (pa, pb) = (pressures[i - 1], pressures[i]);
                let f = ((lcl.pressure_pa.ln() - pa.ln()) / (pb.ln() - pa.ln())).clamp(0.0, 1.0);
                lv[i - 1].height_m + f * (lv[i].height_m - lv[i - 1].height_m)
            })
    };
    let rows = lv
        .iter()
        .zip(&pressures)
        .zip(&lifted.levels)
        .map(|((l, &p), a)| {
            let qs_env = saturation_mixing_ratio(l.temperature_k, p);
            let env_qv = l.mixing_ratio.min(qs_env);
            let env_qc = l.mixing_ratio - env_qv;
            let tv_env = l.temperature_k * (1.0 + VIRTUAL_COEFF * env_qv - env_qc);
            let tv = a.t_k * (1.0 + VIRTUAL_COEFF * a.qv - a.qc);
            ProfileRow {
                height_m: l.height_m,
                pressure_pa: p,
                env_t_k: l.temperature_k,
                parcel_t_k: a.t_k,
                parcel_qv: a.qv,
                parcel_qc: a.qc,
                buoyancy: G * (tv - tv_env) / tv_env,
            }
        })
        .collect();
    Profile {
        lcl,
        lcl_height_m,
        rows,
        rk4_steps: lifted.rk4_steps,
    }
}

/// LCL height (m) of the air at the bottom of a tabulated atmosphere, if it
/// condenses below the table's top: the default cloud base.
pub fn surface_lcl_height(atm: &Atmosphere) -> Option<f64> {
    let e = atm.at(0.0);
    let l = lcl(e.t_k, e.qv, e.p_pa);
    if l.pressure_pa >= e.p_pa {
        return Some(0.0);
    }
    atm.height_at_pressure(l.pressure_pa)
}

#[cfg(test)]
#[path = "lift_tests.rs"]
mod tests;
