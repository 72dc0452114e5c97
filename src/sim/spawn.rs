//! Birth of a parcel: a seeded position (on a spawn site when there are
//! any) and radius, and environment air at the release height plus the
//! scene's excess.

use glam::{DVec2, DVec3};

use super::atmosphere::{Atmosphere, EnvSample};
use super::config::PhysicsConfig;
use super::constants::R_D;
use super::lift::surface_lcl_height;
use super::parcels::{Life, Parcels, keyed_uniform};
use super::thermo::{saturation_mixing_ratio, unsaturated_temperature};
use super::update::{diagnose, wind_at};

pub(super) fn air_mass(env: &EnvSample, radius_m: f64) -> f64 {
    let rho = env.p_pa / (R_D * env.theta_v * env.exner);
    rho * 4.0 / 3.0 * std::f64::consts::PI * radius_m.powi(3)
}

/// The most total water a released parcel may carry, kg/kg: the saturation
/// mixing ratio where the parcel, lifted unsaturated (moist air's adiabat) from the release
/// height with its `θ_l` excess, reaches the surface air's LCL (the cloud
/// base). With at most this much water a parcel cannot saturate below the
/// cloud base, however small the saturation mixing ratio of cold air is
/// (at -20 °C it is about 0.8 g/kg, less than the default 1 g/kg excess).
pub(super) fn release_qt_cap(cfg: &PhysicsConfig, atm: &Atmosphere) -> f64 {
    let z0 = cfg.release_height_m;
    let theta_l = atm.at(z0).theta_l + cfg.initial_excess_k;
    let base = surface_lcl_height(atm).unwrap_or(atm.top_m()).max(z0);
    let e = atm.at(base);
    // Unsaturated below the base. The cap depends on q_t itself through
    // the moist adiabat's exponent; three fixed-point passes from the
    // release-height air's water settle it to far below a part in a million.
    let mut cap = atm.at(z0).qt;
    for _ in 0..3 {
        cap = saturation_mixing_ratio(unsaturated_temperature(theta_l, cap, e.p_pa), e.p_pa);
    }
    cap
}

/// Places parcel `i` for its `generation`-th life: seeded position and
/// radius, environment air at the release height plus the excess, its
/// total water at most `qt_cap` ([`release_qt_cap`]) unless the
/// environment there already has more.
pub(super) fn spawn(
    cfg: &PhysicsConfig,
    atm: &Atmosphere,
    sites: &[DVec2],
    qt_cap: f64,
    p: &mut Parcels,
    i: usize,
    generation: u32,
) {
    let u = |s| keyed_uniform(cfg.seed, i as u64, generation, s);
    let l = cfg.domain_size_m;
    let z = cfg.release_height_m;
    let env = atm.at(z);
    let radius = cfg.radius_m * (1.0 + cfg.radius_jitter * (2.0 * u(2) - 1.0));
    let xy = if sites.is_empty() {
        DVec2::new(u(0) * l, u(1) * l)
    } else {
        let site = sites[((u(5) * sites.len() as f64) as usize).min(sites.len() - 1)];
        let (a, r) = (u(0) * std::f64::consts::TAU, cfg.radius_m * u(1).sqrt());
        site + DVec2::new(a.cos(), a.sin()) * r
    };
    p.pos[i] = DVec3::new(xy.x.rem_euclid(l), xy.y.rem_euclid(l), z);
    let w = wind_at(cfg, z);
    p.vel[i] = DVec3::new(w.x, w.y, 0.0);
    p.theta_l[i] = env.theta_l + cfg.initial_excess_k;
    p.qt[i] = (env.qt + cfg.initial_excess_qt_gkg * 1e-3)
        .min(qt_cap.max(env.qt))
        .max(0.0);
    p.life[i] = Life {
        radius_m: radius,
        mass_kg: air_mass(&env, radius),
        age_s: 0.0,
        peak_qc: 0.0,
        generation,
        ..Life::default()
    };
    refresh_diag(atm, p, i);
}

pub(super) fn refresh_diag(atm: &Atmosphere, p: &mut Parcels, i: usize) {
    let env = atm.at(p.pos[i].z);
    p.diag[i] = diagnose(&env, p.theta_l[i], p.qt[i]);
}
