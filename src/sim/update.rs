//! The per-parcel update of one sub-step ([`advance_parcel`]), in this
//! order (docs/physics.md, "The model, and the choices made"):
//!
//! 0. SPH accelerations between released parcels (if on).
//! 1. Half kick: `w += Δt/2 (B/(1+γ) + a_sph,z)` with quadratic drag
//!    (`ε|w|w + (3/8) C_D w|w|/R`) solved implicitly and exactly, and the
//!    same for the horizontal velocity relative to the wind.
//! 2. Drift: move the parcel (periodic in the plane, ground and table top
//!    stop it).
//! 3. Entrainment: exact exponential relaxation of `θ_l` (Emanuel's exact
//!    one, `thermo`), `q_t` and the
//!    horizontal velocity towards the environment at the new height.
//! 4. Saturation adjustment at the new pressure (implicit, iterated).
//! 5. Detrainment: cloud water shed exponentially, faster when negatively
//!    buoyant (buoyancy sorting).
//! 6. Buoyancy at the new state, then the second half kick.
//!
//! Steps 1-2 and 6 are velocity Verlet for the buoyancy oscillator (second
//! order, symplectic); the stiff parts (3-5) are exact or implicit. After
//! all sub-steps, spent parcels are re-born near the ground.

use glam::{DVec2, DVec3};

use super::atmosphere::{Atmosphere, EnvSample};
use super::config::PhysicsConfig;
use super::constants::G;
use super::parcels::{Diag, Life};
use super::thermo::{
    liquid_water_potential_temperature, saturation_adjust, virtual_potential_temperature,
};

/// Per-frame constants of the per-parcel update.
#[derive(Clone, Copy)]
pub(super) struct Ctx<'a> {
    pub atm: &'a Atmosphere,
    pub cfg: &'a PhysicsConfig,
    pub dt: f64,
    /// Unit vector the wind blows towards.
    pub wind_dir: DVec2,
}

/// The wind at height `z_m` (zero when off), m/s.
#[inline]
pub fn wind_at(cfg: &PhysicsConfig, z_m: f64) -> DVec2 {
    if !cfg.wind.enabled {
        return DVec2::ZERO;
    }
    let a = cfg.wind.direction_deg.to_radians();
    wind_with_direction(cfg, DVec2::new(a.sin(), a.cos()), z_m)
}

/// [`wind_at`] with the direction's unit vector already computed.
#[inline]
fn wind_with_direction(cfg: &PhysicsConfig, dir: DVec2, z_m: f64) -> DVec2 {
    let w = &cfg.wind;
    if !w.enabled {
        return DVec2::ZERO;
    }
    dir * (w.speed_mps * (1.0 + w.shear_per_km * z_m.max(0.0) * 1e-3).max(0.0))
}

#[inline]
pub(super) fn diagnose(env: &EnvSample, theta_l: f64, qt: f64) -> Diag {
    let a = saturation_adjust(theta_l, qt, env.p_pa);
    let theta_v = virtual_potential_temperature(a.t_k / env.exner, a.qv, a.qc);
    Diag {
        t_k: a.t_k,
        qv: a.qv,
        qc: a.qc,
        theta_v,
        theta_v_env: env.theta_v,
        buoyancy: G * (theta_v - env.theta_v) / env.theta_v,
    }
}

/// `x` wrapped into `[0, l)`; one add or subtract in the usual case of a
/// parcel that moved less than a domain in a sub-step.
#[inline]
fn wrap(x: f64, l: f64) -> f64 {
    let y = if x < 0.0 {
        x + l
    } else if x >= l {
        x - l
    } else {
        return x;
    };
    let y = if (0.0..l).contains(&y) {
        y
    } else {
        y.rem_euclid(l)
    };
    // rem_euclid can round up to l itself.
    if y >= l { 0.0 } else { y }
}

/// `w' + k Δt w'|w'| = w + a Δt`, solved exactly for `w'`: an implicit
/// quadratic drag that cannot overshoot or change sign on its own.
#[inline]
fn implicit_drag_kick(w: f64, a: f64, k: f64, dt: f64) -> f64 {
    let v0 = w + a * dt;
    let kd = k * dt;
    if kd <= 0.0 {
        return v0;
    }
    2.0 * v0 / (1.0 + (1.0 + 4.0 * kd * v0.abs()).sqrt())
}

#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn advance_parcel(
    ctx: &Ctx,
    a_sph: DVec3,
    pos: &mut DVec3,
    vel: &mut DVec3,
    theta_l: &mut f64,
    qt: &mut f64,
    diag: &mut Diag,
    life: &mut Life,
) {
    let cfg = ctx.cfg;
    let dt = ctx.dt;
    if !life.released() {
        life.age_s += dt;
        return;
    }
    let r = life.radius_m;
    let eps = if cfg.entrainment.enabled {
        cfg.entrainment.coefficient / r
    } else {
        0.0
    };
    let drag = 0.375 * cfg.drag_coefficient / r;
    let k = eps + drag;
    let inv_vm = 1.0 / (1.0 + cfg.virtual_mass);
    let half = 0.5 * dt;

    // 1. Half kick.
    let kick = |vel: &mut DVec3, buoyancy: f64, z: f64| {
        vel.z = implicit_drag_kick(vel.z, buoyancy * inv_vm + a_sph.z, k, half);
        let wind = wind_with_direction(cfg, ctx.wind_dir, z);
        let rel = DVec2::new(vel.x, vel.y) - wind;
        let speed = rel.length();
        let rel = if speed > 0.0 {
            let s = implicit_drag_kick(speed, 0.0, drag, half);
            rel * (s / speed)
        } else {
            rel
        } + DVec2::new(a_sph.x, a_sph.y) * half;
        vel.x = wind.x + rel.x;
        vel.y = wind.y + rel.y;
    };
    kick(vel, diag.buoyancy, pos.z);

    // 2. Drift.
    *pos += *vel * dt;
    let l = cfg.domain_size_m;
    pos.x = wrap(pos.x, l);
    pos.y = wrap(pos.y, l);
    let top = ctx.atm.top_m();
    if pos.z < 0.0 {
        pos.z = 0.0;
        vel.z = vel.z.max(0.0);
    } else if pos.z > top {
        pos.z = top;
        vel.z = vel.z.min(0.0);
    }
    let env = ctx.atm.at(pos.z);

    // 3. Entrainment: exact relaxation towards the environment.
    if eps > 0.0 {
        let f = (-eps * vel.z.abs() * dt).exp();
        let qt_old = *qt;
        *theta_l = env.theta_l + (*theta_l - env.theta_l) * f;
        *qt = env.qt + (*qt - env.qt) * f;
        life.entrained_kg.add((*qt - qt_old) * life.mass_kg);
        let wind = wind_with_direction(cfg, ctx.wind_dir, pos.z);
        vel.x = wind.x + (vel.x - wind.x) * f;
        vel.y = wind.y + (vel.y - wind.y) * f;
    }

    // 4. Saturation adjustment at the new pressure.
    let mut d = diagnose(&env, *theta_l, *qt);

    // 5. Detrainment of cloud water, faster when negatively buoyant.
    if cfg.detrainment.enabled && d.qc > 0.0 {
        let det = &cfg.detrainment;
        let rate = det.rate_per_s
            * if d.buoyancy < 0.0 {
                1.0 + det.sorting_factor
            } else {
                1.0
            };
        let shed = d.qc * -(-rate * dt).exp_m1();
        *qt -= shed;
        d.qc -= shed;
        // Liquid leaves at the parcel's temperature and pressure: T and
        // q_v (= q_s(T)) are unchanged, θ_l of what stays rises.
        *theta_l = liquid_water_potential_temperature(d.t_k, env.p_pa, *qt, d.qc);
        life.detrained_kg.add(shed * life.mass_kg);
        d.theta_v = virtual_potential_temperature(d.t_k / env.exner, d.qv, d.qc);
        d.buoyancy = G * (d.theta_v - env.theta_v) / env.theta_v;
    }
    *diag = d;

    // 6. Second half kick with the new buoyancy.
    kick(vel, d.buoyancy, pos.z);
    life.age_s += dt;
    life.peak_qc = life.peak_qc.max(d.qc);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn implicit_drag_kick_solves_its_equation() {
        for (w, a, k, dt) in [
            (3.0, 0.1, 0.01, 5.0),
            (-2.0, 0.0, 1.0, 100.0),
            (0.0, -0.5, 0.002, 600.0),
        ] {
            let w1 = implicit_drag_kick(w, a, k, dt);
            let lhs = w1 + k * dt * w1 * w1.abs();
            assert!((lhs - (w + a * dt)).abs() < 1e-12, "{w} {a} {k} {dt}: {w1}");
        }
    }
}
