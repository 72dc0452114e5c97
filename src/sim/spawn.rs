//! Birth of a parcel: a seeded position (on a spawn site when there are
//! any) and radius, and environment air at the release height plus the
//! scene's excess.

use glam::{DVec2, DVec3};

use super::atmosphere::{Atmosphere, EnvSample};
use super::config::PhysicsConfig;
use super::constants::R_D;
use super::parcels::{Life, Parcels, keyed_uniform};
use super::update::{diagnose, wind_at};

pub(super) fn air_mass(env: &EnvSample, radius_m: f64) -> f64 {
    let rho = env.p_pa / (R_D * env.theta_v * env.exner);
    rho * 4.0 / 3.0 * std::f64::consts::PI * radius_m.powi(3)
}

/// Places parcel `i` for its `generation`-th life: seeded position and
/// radius, environment air at the release height plus the excess.
pub(super) fn spawn(
    cfg: &PhysicsConfig,
    atm: &Atmosphere,
    sites: &[DVec2],
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
    p.qt[i] = (env.qt + cfg.initial_excess_qt_gkg * 1e-3).max(0.0);
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
