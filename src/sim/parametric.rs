//! [`ParametricProfile`]: the scenes' default atmosphere as a few numbers
//! (surface state, lapse rates, an inversion, humidity decay), with its
//! domain checks.

use serde::{Deserialize, Serialize};

/// A parametric profile: the default scenes' atmosphere.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ParametricProfile {
    /// Air temperature at the ground, K. Domain 180..=340. Default 295.
    pub surface_temperature_k: f64,
    /// Pressure at the ground, hPa. Domain 300..=1100. Default 1013.25.
    pub surface_pressure_hpa: f64,
    /// Relative humidity at the ground, 0..=1.2 (above 1 is supersaturated
    /// input, kept as haze). Default 0.8.
    pub surface_relative_humidity: f64,
    /// Lapse rate below the inversion, K/km (positive: cooling with height).
    /// Default 7.0.
    pub lapse_rate_k_per_km: f64,
    /// Height of the inversion base above ground, m. Default 1500.
    pub inversion_base_m: f64,
    /// Thickness of the inversion, m (> 0). Default 200.
    pub inversion_thickness_m: f64,
    /// Strength of the inversion, K: at its top the air is this much warmer
    /// than the lower lapse rate continued would make it (0 = no inversion,
    /// the lower lapse rate goes on to the inversion top). Default 5.
    pub inversion_strength_k: f64,
    /// Lapse rate above the inversion, K/km. Default 6.0.
    pub lapse_rate_above_k_per_km: f64,
    /// e-folding height of the relative humidity below the inversion, m.
    /// Default 5000.
    pub humidity_scale_height_m: f64,
    /// Relative humidity just above the inversion as a fraction of the value
    /// below it, 0..=1. Default 0.3.
    pub humidity_drop_above_inversion: f64,
    /// Top of the table, m. Default 8000.
    pub top_m: f64,
}

impl Default for ParametricProfile {
    fn default() -> Self {
        Self::FAIR_WEATHER
    }
}

impl ParametricProfile {
    /// Every field against its domain, under the scene key `prefix`
    /// (e.g. `atmosphere.parametric.`).
    pub fn checks(&self, prefix: &str) -> Vec<super::check::Check> {
        let pp = self;
        [
            (
                "surface_temperature_k",
                pp.surface_temperature_k,
                180.0,
                340.0,
                "180..=340 K",
            ),
            (
                "surface_pressure_hpa",
                pp.surface_pressure_hpa,
                300.0,
                1100.0,
                "300..=1100 hPa",
            ),
            (
                "surface_relative_humidity",
                pp.surface_relative_humidity,
                0.0,
                1.2,
                "0..=1.2",
            ),
            (
                "lapse_rate_k_per_km",
                pp.lapse_rate_k_per_km,
                -20.0,
                20.0,
                "-20..=20 K/km",
            ),
            (
                "inversion_base_m",
                pp.inversion_base_m,
                0.0,
                20_000.0,
                "0..=20000 m",
            ),
            (
                "inversion_thickness_m",
                pp.inversion_thickness_m,
                1.0,
                5000.0,
                "1..=5000 m",
            ),
            (
                "inversion_strength_k",
                pp.inversion_strength_k,
                0.0,
                40.0,
                "0..=40 K",
            ),
            (
                "lapse_rate_above_k_per_km",
                pp.lapse_rate_above_k_per_km,
                -20.0,
                20.0,
                "-20..=20 K/km",
            ),
            (
                "humidity_scale_height_m",
                pp.humidity_scale_height_m,
                1.0,
                1e6,
                "1..=1e6 m",
            ),
            (
                "humidity_drop_above_inversion",
                pp.humidity_drop_above_inversion,
                0.0,
                1.0,
                "0..=1",
            ),
            ("top_m", pp.top_m, 100.0, 30_000.0, "100..=30000 m"),
        ]
        .into_iter()
        .map(|(name, v, lo, hi, expected)| {
            super::check::Check::range(format!("{prefix}{name}"), v, lo, hi, expected)
        })
        .collect()
    }
    /// A fair-weather cumulus morning: moist boundary layer capped at 1.5 km.
    pub const FAIR_WEATHER: Self = Self {
        surface_temperature_k: 295.0,
        surface_pressure_hpa: 1013.25,
        surface_relative_humidity: 0.8,
        lapse_rate_k_per_km: 7.0,
        inversion_base_m: 1500.0,
        inversion_thickness_m: 200.0,
        inversion_strength_k: 5.0,
        lapse_rate_above_k_per_km: 6.0,
        humidity_scale_height_m: 5000.0,
        humidity_drop_above_inversion: 0.3,
        top_m: 8000.0,
    };

    /// Temperature (K) and relative humidity at height `z_m`.
    pub(super) fn temperature_and_rh(&self, z_m: f64) -> (f64, f64) {
        let zi = self.inversion_base_m;
        let dz = self.inversion_thickness_m.max(1e-3);
        let below = self.lapse_rate_k_per_km * 1e-3;
        let above = self.lapse_rate_above_k_per_km * 1e-3;
        let t0 = self.surface_temperature_k;
        let rh0 = self.surface_relative_humidity;
        let rh_base = rh0 * (-zi / self.humidity_scale_height_m.max(1.0)).exp();
        if z_m <= zi {
            let rh = rh0 * (-z_m / self.humidity_scale_height_m.max(1.0)).exp();
            (t0 - below * z_m, rh)
        } else if z_m <= zi + dz {
            let f = (z_m - zi) / dz;
            let t = t0 - below * z_m + self.inversion_strength_k * f;
            let rh = rh_base * (1.0 - f * (1.0 - self.humidity_drop_above_inversion));
            (t, rh)
        } else {
            let t = t0 - below * (zi + dz) + self.inversion_strength_k - above * (z_m - zi - dz);
            let rh = rh_base
                * self.humidity_drop_above_inversion
                * (-(z_m - zi - dz) / self.humidity_scale_height_m.max(1.0)).exp();
            (t, rh)
        }
    }
}
