//! Physical constants, SI units.

/// Gravitational acceleration, m/s².
pub const G: f64 = 9.80665;
/// Gas constant of dry air, J/(kg K).
pub const R_D: f64 = 287.04;
/// Gas constant of water vapour, J/(kg K).
pub const R_V: f64 = 461.5;
/// Ratio of the gas constants, `R_d / R_v`.
pub const EPSILON: f64 = R_D / R_V;
/// Specific heat of dry air at constant pressure, J/(kg K).
pub const C_P: f64 = 1004.7;
/// Latent heat of vaporisation, J/kg.
pub const L_V: f64 = 2.501e6;
/// Reference pressure of potential temperature, Pa.
pub const P0: f64 = 100_000.0;
/// Poisson exponent `R_d / c_p`.
pub const KAPPA: f64 = R_D / C_P;
/// Virtual-temperature coefficient `R_v/R_d - 1`.
pub const VIRTUAL_COEFF: f64 = 0.608;
/// 0 °C in kelvin.
pub const ZERO_CELSIUS_K: f64 = 273.15;
