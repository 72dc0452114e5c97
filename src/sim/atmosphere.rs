//! The implicit environment: temperature, humidity and pressure against
//! height, tabulated once on a fine grid so that a parcel's lookup is O(1).
//!
//! Two sources build it: a [`ParametricProfile`] (lapse rate, inversion,
//! humidity decay) or a [`super::sounding::Sounding`]. Pressure
//! is integrated hydrostatically, `dp/dz = -p g / (R_d T_v)`, unless the
//! sounding gives it. Supersaturated input (relative humidity above 1) is
//! kept as environmental condensate (haze/fog): vapour is capped at
//! saturation and the excess loads `θ_v`, so every derived quantity stays
//! finite and the environment's total water is what the user gave.

use super::constants::{G, R_D};
pub use super::parametric::ParametricProfile;
use super::sounding::Sounding;
use super::thermo::{
    exner, liquid_water_potential_temperature, saturation_mixing_ratio,
    virtual_potential_temperature,
};

/// Vertical spacing of the table, m. 1 m keeps linear interpolation of a
/// sounding's kinks exact to well under the 10 m LCL tolerance.
pub const TABLE_DZ_M: f64 = 1.0;

/// One row of the environment table.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EnvSample {
    /// Pressure, Pa.
    pub p_pa: f64,
    /// Exner function `(p/p0)^κ`.
    pub exner: f64,
    /// Temperature, K.
    pub t_k: f64,
    /// Vapour mixing ratio, kg/kg.
    pub qv: f64,
    /// Condensate mixing ratio (only for supersaturated input), kg/kg.
    pub qc: f64,
    /// Virtual potential temperature, K.
    pub theta_v: f64,
    /// Liquid-water potential temperature, K (conserved; what entrains).
    pub theta_l: f64,
    /// Total water, kg/kg (conserved; what entrains).
    pub qt: f64,
}

/// The tabulated environment.
#[derive(Debug, Clone)]
pub struct Atmosphere {
    rows: Vec<EnvSample>,
    /// Brunt-Väisälä frequency squared per row, 1/s².
    n2: Vec<f64>,
    max_n: f64,
    inversion_base_m: Option<f64>,
}

impl Atmosphere {
    /// Tabulates a parametric profile.
    pub fn from_parametric(p: &ParametricProfile) -> Self {
        let top = p.top_m.max(100.0);
        let n = (top / TABLE_DZ_M).ceil() as usize + 1;
        let mut rows = Vec::with_capacity(n);
        let mut ln_p = (p.surface_pressure_hpa * 100.0).ln();
        let mut prev_inv_tv: Option<f64> = None;
        for i in 0..n {
            let z = i as f64 * TABLE_DZ_M;
            let (t, rh) = p.temperature_and_rh(z);
            // Vapour at this level depends on p; p depends on T_v below:
            // integrate with the trapezoid rule on 1/T_v, using this level's
            // humidity at the pressure extrapolated from below.
            let t = t.max(150.0);
            let sample_at = |ln_p: f64| {
                let pr = ln_p.exp();
                let q = rh.max(0.0) * saturation_mixing_ratio(t, pr);
                sample(z, pr, t, q)
            };
            let s = if let Some(inv_tv_below) = prev_inv_tv {
                let guess = sample_at(ln_p - G * TABLE_DZ_M * inv_tv_below / R_D);
                let inv_tv = 1.0 / virtual_temperature(&guess);
                ln_p -= G * TABLE_DZ_M * 0.5 * (inv_tv_below + inv_tv) / R_D;
                sample_at(ln_p)
            } else {
                sample_at(ln_p)
            };
            prev_inv_tv = Some(1.0 / virtual_temperature(&s));
            rows.push(s);
        }
        let inversion = (p.inversion_strength_k > 0.0 && p.inversion_base_m < top)
            .then_some(p.inversion_base_m);
        Self::finish(rows, inversion)
    }

    /// Tabulates a sounding (levels already validated: sorted, finite,
    /// pressures filled).
    pub fn from_sounding(s: &Sounding) -> Self {
        let levels = s.levels();
        let z0 = levels[0].height_m;
        let top = levels[levels.len() - 1].height_m;
        // The table starts at the ground (z = 0); below the first level the
        // first level's values are held.
        let n = (top.max(z0) / TABLE_DZ_M).ceil() as usize + 1;
        let mut rows = Vec::with_capacity(n);
        let mut k = 0;
        for i in 0..n {
            let z = (i as f64 * TABLE_DZ_M).min(top);
            while k + 2 < levels.len() && levels[k + 1].height_m < z {
                k += 1;
            }
            let (a, b) = if levels.len() == 1 {
                (&levels[0], &levels[0])
            } else {
                (&levels[k], &levels[k + 1])
            };
            let f = if b.height_m > a.height_m {
                ((z - a.height_m) / (b.height_m - a.height_m)).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let pa = a.pressure_pa.unwrap_or(f64::NAN);
            let pb = b.pressure_pa.unwrap_or(f64::NAN);
            let p = (pa.ln() + f * (pb.ln() - pa.ln())).exp();
            let t = a.temperature_k + f * (b.temperature_k - a.temperature_k);
            let q = a.mixing_ratio + f * (b.mixing_ratio - a.mixing_ratio);
            rows.push(sample(z, p, t, q));
        }
        Self::finish(rows, s.inversion_base_m())
    }

    fn finish(rows: Vec<EnvSample>, inversion_base_m: Option<f64>) -> Self {
        let n = rows.len();
        let mut n2 = vec![0.0; n];
        for i in 0..n {
            let lo = i.saturating_sub(1);
            let hi = (i + 1).min(n - 1);
            if hi > lo {
                let dth = rows[hi].theta_v - rows[lo].theta_v;
                n2[i] = G / rows[i].theta_v * dth / ((hi - lo) as f64 * TABLE_DZ_M);
            }
        }
        let max_n = n2.iter().fold(0.0_f64, |m, &v| m.max(v)).sqrt();
        Self {
            rows,
            n2,
            max_n,
            inversion_base_m,
        }
    }

    /// Environment at height `z_m` (clamped to the table), linearly
    /// interpolated.
    #[inline]
    pub fn at(&self, z_m: f64) -> EnvSample {
        let (i, f) = self.index(z_m);
        let a = &self.rows[i];
        let b = &self.rows[(i + 1).min(self.rows.len() - 1)];
        let l = |x: f64, y: f64| x + f * (y - x);
        EnvSample {
            p_pa: l(a.p_pa, b.p_pa),
            exner: l(a.exner, b.exner),
            t_k: l(a.t_k, b.t_k),
            qv: l(a.qv, b.qv),
            qc: l(a.qc, b.qc),
            theta_v: l(a.theta_v, b.theta_v),
            theta_l: l(a.theta_l, b.theta_l),
            qt: l(a.qt, b.qt),
        }
    }

    /// Brunt-Väisälä frequency squared at `z_m`, 1/s².
    pub fn n_squared(&self, z_m: f64) -> f64 {
        let (i, f) = self.index(z_m);
        let j = (i + 1).min(self.n2.len() - 1);
        self.n2[i] + f * (self.n2[j] - self.n2[i])
    }

    /// The largest Brunt-Väisälä frequency anywhere in the table, 1/s: the
    /// bound that adaptive sub-stepping keeps `N Δt_sub` under.
    pub fn max_buoyancy_frequency(&self) -> f64 {
        self.max_n
    }

    /// Height of the top of the table, m.
    pub fn top_m(&self) -> f64 {
        (self.rows.len() - 1) as f64 * TABLE_DZ_M
    }

    /// The same table with the inversion base set by the caller, m.
    pub fn with_inversion_base(mut self, z_m: f64) -> Self {
        self.inversion_base_m = Some(z_m);
        self
    }

    /// Height of the inversion base if the source names or shows one, m.
    pub fn inversion_base_m(&self) -> Option<f64> {
        self.inversion_base_m
    }

    /// Height (m) at which the pressure falls to `p_pa` (log-linear
    /// interpolation); `None` outside the table.
    pub fn height_at_pressure(&self, p_pa: f64) -> Option<f64> {
        let rows = &self.rows;
        if p_pa > rows[0].p_pa || p_pa < rows[rows.len() - 1].p_pa {
            return None;
        }
        let i = rows.partition_point(|r| r.p_pa > p_pa).max(1);
        let (a, b) = (&rows[i - 1], &rows[i]);
        let f = (p_pa.ln() - a.p_pa.ln()) / (b.p_pa.ln() - a.p_pa.ln());
        Some((i - 1) as f64 * TABLE_DZ_M + f * TABLE_DZ_M)
    }

    #[inline]
    fn index(&self, z_m: f64) -> (usize, f64) {
        let last = self.rows.len() - 1;
        let x = if z_m.is_finite() {
            (z_m / TABLE_DZ_M).clamp(0.0, last as f64)
        } else if z_m > 0.0 {
            last as f64
        } else {
            0.0
        };
        let i = (x as usize).min(last.saturating_sub(1));
        (i, x - i as f64)
    }
}

fn virtual_temperature(s: &EnvSample) -> f64 {
    s.theta_v * s.exner
}

/// Builds one table row from height, pressure, temperature and total water.
fn sample(_z: f64, p_pa: f64, t_k: f64, q_total: f64) -> EnvSample {
    let ex = exner(p_pa);
    let qs = saturation_mixing_ratio(t_k, p_pa);
    let q_total = q_total.max(0.0);
    let qv = q_total.min(qs);
    let qc = q_total - qv;
    let theta = t_k / ex;
    EnvSample {
        p_pa,
        exner: ex,
        t_k,
        qv,
        qc,
        theta_v: virtual_potential_temperature(theta, qv, qc),
        theta_l: liquid_water_potential_temperature(t_k, p_pa, q_total, qc),
        qt: q_total,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::constants::{C_P, KAPPA};

    #[test]
    fn dry_isentropic_layer_has_constant_theta_and_zero_n() {
        // A dry adiabatic lapse rate g/c_p gives constant θ: N² ≈ 0.
        let p = ParametricProfile {
            surface_relative_humidity: 0.0,
            lapse_rate_k_per_km: G / C_P * 1e3,
            inversion_strength_k: 0.0,
            lapse_rate_above_k_per_km: G / C_P * 1e3,
            ..ParametricProfile::FAIR_WEATHER
        };
        let a = Atmosphere::from_parametric(&p);
        let th0 = a.at(0.0).theta_v;
        for z in [100.0, 1000.0, 3000.0, 6000.0] {
            let th = a.at(z).theta_v;
            // The hydrostatic pressure on the 1 m grid is exact to O(dz²).
            assert!((th - th0).abs() < 1e-3, "θ at {z} m: {th} vs {th0}");
            assert!(a.n_squared(z).abs() < 1e-8);
        }
        let _ = KAPPA;
    }

    #[test]
    fn hydrostatic_pressure_matches_isothermal_analytic() {
        // Isothermal dry atmosphere: p = p0 exp(-g z / (R_d T)).
        let p = ParametricProfile {
            surface_relative_humidity: 0.0,
            lapse_rate_k_per_km: 0.0,
            inversion_strength_k: 0.0,
            lapse_rate_above_k_per_km: 0.0,
            ..ParametricProfile::FAIR_WEATHER
        };
        let a = Atmosphere::from_parametric(&p);
        for z in [500.0, 4000.0, 7999.0] {
            let want = 101_325.0 * (-G * z / (R_D * 295.0)).exp();
            let got = a.at(z).p_pa;
            assert!((got - want).abs() / want < 1e-9, "{z}: {got} vs {want}");
        }
    }

    #[test]
    fn height_at_pressure_inverts_table() {
        let a = Atmosphere::from_parametric(&ParametricProfile::FAIR_WEATHER);
        for z in [10.0, 733.3, 5000.0] {
            let p = a.at(z).p_pa;
            let back = a.height_at_pressure(p).expect("inside table");
            assert!((back - z).abs() < 1e-3, "{z} -> {back}");
        }
    }
}
