//! The parcel solver. One frame of `dt_s` is split into adaptive sub-steps;
//! each sub-step does, in this order (physics.md section 2):
//!
//! 0. SPH accelerations between released parcels (if on).
//! 1. Half kick: `w += Δt/2 (B/(1+γ) + a_sph,z)` with quadratic drag
//!    (`ε|w|w + (3/8) C_D w|w|/R`) solved implicitly and exactly, and the
//!    same for the horizontal velocity relative to the wind.
//! 2. Drift: move the parcel (periodic in the plane, ground and table top
//!    stop it).
//! 3. Entrainment: exact exponential relaxation of `θ_l`, `q_t` and the
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
use rayon::prelude::*;

use super::atmosphere::Atmosphere;
use super::budget::{CompensatedSum, WaterBudget};
use super::config::PhysicsConfig;
use super::constants::{C_P, G, L_V, R_D};
use super::parcels::{Diag, Life, Parcels, keyed_uniform};
use super::sph::{self, NeighbourGrid, SphParams};
use super::thermo::{saturation_adjust, virtual_potential_temperature};

/// Above this many parcels the per-parcel update runs on all cores.
pub const PARALLEL_THRESHOLD: usize = 1024;

/// Condensate below this (kg/kg) counts as none for the life cycle.
const QC_EPS: f64 = 1e-7;

/// What one frame did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepStats {
    /// Sub-steps taken.
    pub substeps: usize,
    /// The sub-step cap was reached: the last sub-step was longer than the
    /// stability bounds asked for.
    pub capped: bool,
    /// Shortest sub-step, s.
    pub min_substep_s: f64,
    /// Parcels re-born in this frame.
    pub recycled: usize,
}

/// Running totals over all frames.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Totals {
    /// Frames stepped.
    pub frames: u64,
    /// Sub-steps taken.
    pub substeps: u64,
    /// Frames whose sub-step cap was reached.
    pub capped_frames: u64,
    /// Re-births.
    pub recycled: u64,
}

/// A parcel simulation: configuration, environment, parcels, time, books.
#[derive(Debug, Clone)]
pub struct Simulation {
    cfg: PhysicsConfig,
    atm: Atmosphere,
    parcels: Parcels,
    time_s: f64,
    initial_water_kg: f64,
    /// Exchange of parcels that have since been re-born.
    retired_entrained: CompensatedSum,
    retired_detrained: CompensatedSum,
    totals: Totals,
    grid: NeighbourGrid,
    sph_acc: Vec<DVec3>,
    active: Vec<u32>,
    /// Where parcels are born (m, in the domain); empty: anywhere.
    sites: Vec<DVec2>,
}

/// One parcel's state as the zipped iterators hand it out.
type ParcelRefs<'a> = (
    (
        (((&'a mut DVec3, &'a mut DVec3), &'a mut f64), &'a mut f64),
        &'a mut Diag,
    ),
    &'a mut Life,
);

/// Per-frame constants of the per-parcel update.
#[derive(Clone, Copy)]
struct Ctx<'a> {
    atm: &'a Atmosphere,
    cfg: &'a PhysicsConfig,
    dt: f64,
    /// Unit vector the wind blows towards.
    wind_dir: DVec2,
}

impl Simulation {
    /// A simulation with `cfg.parcels` parcels released over
    /// `cfg.release_stagger_s`. `cfg` is assumed valid (see
    /// [`crate::scene::Scene::validate`]).
    pub fn new(cfg: PhysicsConfig, atm: Atmosphere) -> Self {
        let n = cfg.parcels;
        let mut parcels = Parcels {
            pos: vec![DVec3::ZERO; n],
            vel: vec![DVec3::ZERO; n],
            theta_l: vec![0.0; n],
            qt: vec![0.0; n],
            diag: vec![Diag::default(); n],
            life: vec![Life::default(); n],
        };
        for i in 0..n {
            spawn(&cfg, &atm, &[], &mut parcels, i, 0);
            let wait = cfg.release_stagger_s * keyed_uniform(cfg.seed, i as u64, 0, 4);
            parcels.life[i].age_s = -wait;
        }
        let initial_water_kg = parcels.water_kg();
        Self {
            cfg,
            atm,
            parcels,
            time_s: 0.0,
            initial_water_kg,
            retired_entrained: CompensatedSum::default(),
            retired_detrained: CompensatedSum::default(),
            totals: Totals::default(),
            grid: NeighbourGrid::default(),
            sph_acc: Vec::new(),
            active: Vec::new(),
            sites: Vec::new(),
        }
    }

    /// Births (and re-births) happen at these horizontal sites, m (e.g. the
    /// cloud map's cell centres, so footprints land on cloud cells: the
    /// paper's Alg. 1, line 2), each within a parcel radius of its site.
    /// Parcels not yet released move to their new sites now.
    pub fn set_spawn_sites(&mut self, sites: Vec<DVec2>) {
        self.sites = sites;
        for i in 0..self.parcels.len() {
            if !self.parcels.life[i].released() {
                // Still waiting: re-place it, keeping its release time.
                let age = self.parcels.life[i].age_s;
                self.respawn(i, self.parcels.life[i].generation);
                self.parcels.life[i].age_s = age;
            }
        }
    }

    /// Re-births parcel `i` as life `generation`: its water and its life's
    /// exchange are retired to the books, the new air's water is drawn from
    /// the environment. The one place a re-birth touches the water books.
    fn respawn(&mut self, i: usize, generation: u32) {
        let life = self.parcels.life[i];
        self.retired_detrained.merge(&life.detrained_kg);
        self.retired_entrained.merge(&life.entrained_kg);
        self.retired_detrained
            .add(self.parcels.qt[i] * life.mass_kg);
        spawn(
            &self.cfg,
            &self.atm,
            &self.sites,
            &mut self.parcels,
            i,
            generation,
        );
        self.retired_entrained
            .add(self.parcels.qt[i] * self.parcels.life[i].mass_kg);
    }

    /// Places parcels explicitly (released, at rest relative to the wind,
    /// with the environment's `θ_l` and `q_t` plus the configured excess):
    /// for tests and for callers that choose positions themselves.
    pub fn with_positions(cfg: PhysicsConfig, atm: Atmosphere, positions: &[DVec3]) -> Self {
        let mut cfg = cfg;
        cfg.parcels = positions.len();
        cfg.release_stagger_s = 0.0;
        let mut sim = Self::new(cfg, atm);
        for (i, &p) in positions.iter().enumerate() {
            sim.set_parcel(
                i,
                p,
                sim.cfg.initial_excess_k,
                sim.cfg.initial_excess_qt_gkg * 1e-3,
            );
        }
        // The placed parcels are the start: open fresh books.
        sim.initial_water_kg = sim.parcels.water_kg();
        sim.retired_entrained = CompensatedSum::default();
        sim.retired_detrained = CompensatedSum::default();
        sim
    }

    /// Moves parcel `i` to `pos` with `θ_l` and `q_t` of the environment there
    /// plus the given excesses (K, kg/kg), at rest relative to the wind.
    /// Counts as a re-birth in the water books.
    pub fn set_parcel(&mut self, i: usize, pos: DVec3, excess_k: f64, excess_qt: f64) {
        let old = self.parcels.qt[i] * self.parcels.life[i].mass_kg;
        let env = self.atm.at(pos.z);
        let p = &mut self.parcels;
        p.pos[i] = DVec3::new(
            pos.x.rem_euclid(self.cfg.domain_size_m),
            pos.y.rem_euclid(self.cfg.domain_size_m),
            pos.z.max(0.0),
        );
        p.theta_l[i] = env.theta_l + excess_k;
        p.qt[i] = (env.qt + excess_qt).max(0.0);
        let w = wind_at(&self.cfg, pos.z);
        p.vel[i] = DVec3::new(w.x, w.y, 0.0);
        p.life[i].age_s = 0.0;
        p.life[i].mass_kg = air_mass(&env, p.life[i].radius_m);
        let new = p.qt[i] * p.life[i].mass_kg;
        self.retired_detrained.add(old);
        self.retired_entrained.add(new);
        refresh_diag(&self.atm, p, i);
    }

    /// Sets parcel `i`'s vertical velocity, m/s.
    pub fn set_vertical_velocity(&mut self, i: usize, w: f64) {
        self.parcels.vel[i].z = w;
    }

    /// The parcels.
    pub fn parcels(&self) -> &Parcels {
        &self.parcels
    }

    /// The environment.
    pub fn atmosphere(&self) -> &Atmosphere {
        &self.atm
    }

    /// Changes the wind from now on (the demo's live control).
    pub fn set_wind(&mut self, wind: crate::sim::config::Wind) {
        self.cfg.wind = wind;
    }

    /// The configuration.
    pub fn config(&self) -> &PhysicsConfig {
        &self.cfg
    }

    /// Simulated time, s.
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Totals over all frames.
    pub fn totals(&self) -> Totals {
        self.totals
    }

    /// The water books since the start.
    pub fn water_budget(&self) -> WaterBudget {
        let mut ent = self.retired_entrained;
        let mut det = self.retired_detrained;
        for l in &self.parcels.life {
            ent.merge(&l.entrained_kg);
            det.merge(&l.detrained_kg);
        }
        WaterBudget {
            initial_kg: self.initial_water_kg,
            parcels_kg: self.parcels.water_kg(),
            entrained_kg: ent.value(),
            detrained_kg: det.value(),
        }
    }

    /// Advances one frame of `cfg.dt_s`.
    pub fn step(&mut self) -> StepStats {
        self.advance(self.cfg.dt_s)
    }

    /// Advances `dt_s` seconds in adaptive sub-steps.
    pub fn advance(&mut self, dt_s: f64) -> StepStats {
        let mut stats = StepStats {
            min_substep_s: f64::INFINITY,
            ..StepStats::default()
        };
        if !dt_s.is_finite() || dt_s <= 0.0 {
            return StepStats {
                min_substep_s: 0.0,
                ..stats
            };
        }
        let cap = self.cfg.substeps.max_per_frame.max(1);
        let mut left = dt_s;
        while left > 0.0 {
            let bound = self.substep_bound();
            let mut dt = bound.min(left);
            if stats.substeps + 1 == cap && dt < left {
                dt = left;
                stats.capped = true;
            }
            // Avoid a sliver of a last step.
            if left - dt < 1e-9 * dt_s {
                dt = left;
            }
            self.substep(dt);
            stats.substeps += 1;
            stats.min_substep_s = stats.min_substep_s.min(dt);
            left -= dt;
        }
        if self.cfg.recycling.enabled {
            stats.recycled = self.recycle();
        }
        self.time_s += dt_s;
        self.totals.frames += 1;
        self.totals.substeps += stats.substeps as u64;
        self.totals.capped_frames += u64::from(stats.capped);
        self.totals.recycled += stats.recycled as u64;
        stats
    }

    /// The longest sub-step the stability and accuracy bounds allow now, s.
    fn substep_bound(&self) -> f64 {
        let s = &self.cfg.substeps;
        let (mut max_w, mut max_v) = (0.0_f64, 0.0_f64);
        for (v, l) in self.parcels.vel.iter().zip(&self.parcels.life) {
            if l.released() {
                max_w = max_w.max(v.z.abs());
                max_v = max_v.max(v.length());
            }
        }
        let mut bound = f64::INFINITY;
        let n = self.atm.max_buoyancy_frequency();
        if n > 0.0 {
            bound = bound.min(s.max_buoyancy_phase / n);
        }
        if max_w > 0.0 {
            bound = bound.min(s.max_rise_m / max_w);
        }
        if self.cfg.sph.enabled {
            let h = self.smoothing_m();
            bound = bound.min(s.sph_courant * h / max_v.max(self.cfg.sph.sound_speed_mps));
            if self.cfg.sph.viscosity_m2ps > 0.0 {
                bound = bound.min(0.125 * h * h / self.cfg.sph.viscosity_m2ps);
            }
        }
        if bound.is_finite() && bound > 0.0 {
            bound
        } else {
            f64::INFINITY
        }
    }

    fn smoothing_m(&self) -> f64 {
        self.cfg.sph.smoothing_radii * self.cfg.radius_m
    }

    fn substep(&mut self, dt: f64) {
        let n = self.parcels.len();
        let sph_on = self.cfg.sph.enabled && n > 1;
        if sph_on {
            self.active.clear();
            self.active
                .extend((0..n as u32).filter(|&i| self.parcels.life[i as usize].released()));
            let params = SphParams {
                h: self.smoothing_m(),
                domain_m: self.cfg.domain_size_m,
                sound_speed: self.cfg.sph.sound_speed_mps,
                viscosity: self.cfg.sph.viscosity_m2ps,
            };
            sph::accelerations(
                &mut self.grid,
                &self.parcels.pos,
                &self.parcels.vel,
                &self.active,
                &params,
                self.active.len() >= sph::PARALLEL_THRESHOLD,
                &mut self.sph_acc,
            );
        }
        let a = self.cfg.wind.direction_deg.to_radians();
        let ctx = Ctx {
            atm: &self.atm,
            cfg: &self.cfg,
            dt,
            wind_dir: DVec2::new(a.sin(), a.cos()),
        };
        let zero = [DVec3::ZERO];
        let acc: &[DVec3] = if sph_on { &self.sph_acc } else { &zero };
        let p = &mut self.parcels;
        let update = |(i, (((((pos, vel), th), qt), diag), life)): (usize, ParcelRefs)| {
            let a = if sph_on { acc[i] } else { DVec3::ZERO };
            advance_parcel(&ctx, a, pos, vel, th, qt, diag, life);
        };
        if n >= PARALLEL_THRESHOLD {
            p.pos
                .par_iter_mut()
                .zip(p.vel.par_iter_mut())
                .zip(p.theta_l.par_iter_mut())
                .zip(p.qt.par_iter_mut())
                .zip(p.diag.par_iter_mut())
                .zip(p.life.par_iter_mut())
                .enumerate()
                .with_min_len(256)
                .for_each(update);
        } else {
            p.pos
                .iter_mut()
                .zip(p.vel.iter_mut())
                .zip(p.theta_l.iter_mut())
                .zip(p.qt.iter_mut())
                .zip(p.diag.iter_mut())
                .zip(p.life.iter_mut())
                .enumerate()
                .for_each(update);
        }
    }

    /// Re-births spent parcels; returns how many.
    fn recycle(&mut self) -> usize {
        let r = self.cfg.recycling.clone();
        let mut count = 0;
        for i in 0..self.parcels.len() {
            let life = self.parcels.life[i];
            let qc = self.parcels.diag[i].qc;
            let decayed = life.peak_qc > QC_EPS && qc < r.spent_fraction_of_peak * life.peak_qc;
            if life.released() && (decayed || life.age_s > r.max_age_s) {
                self.respawn(i, life.generation + 1);
                count += 1;
            }
        }
        count
    }
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

fn air_mass(env: &super::atmosphere::EnvSample, radius_m: f64) -> f64 {
    let rho = env.p_pa / (R_D * env.theta_v * env.exner);
    rho * 4.0 / 3.0 * std::f64::consts::PI * radius_m.powi(3)
}

/// Places parcel `i` for its `generation`-th life: seeded position and
/// radius, environment air at the release height plus the excess.
fn spawn(
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

fn refresh_diag(atm: &Atmosphere, p: &mut Parcels, i: usize) {
    let env = atm.at(p.pos[i].z);
    p.diag[i] = diagnose(&env, p.theta_l[i], p.qt[i]);
}

#[inline]
fn diagnose(env: &super::atmosphere::EnvSample, theta_l: f64, qt: f64) -> Diag {
    let a = saturation_adjust(theta_l, qt, env.p_pa, env.exner);
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
fn advance_parcel(
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
        // Liquid leaves at the parcel's temperature: θ is unchanged, θ_l rises.
        *theta_l += L_V * shed / (C_P * env.exner);
        life.detrained_kg.add(shed * life.mass_kg);
        // Same as re-adjusting: T and q_v (= q_s(T)) are unchanged.
        d.qc -= shed;
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
