//! The parcel solver: [`Simulation`] owns the parcels and the atmosphere,
//! splits each frame of `dt_s` into adaptive sub-steps (SPH first, then
//! the per-parcel update of `update.rs`, whose order of operations is at
//! its top), and re-births spent parcels near the ground (`spawn.rs`).

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::atmosphere::Atmosphere;
use super::budget::{CompensatedSum, WaterBudget};
use super::config::PhysicsConfig;
use super::parcels::{Diag, Life, Parcels, keyed_uniform};
use super::projection::{Band, ProjectedField};
use super::spawn::{air_mass, refresh_diag, release_qt_cap, spawn};
use super::sph::{self, NeighbourGrid, SphParams};
use super::update::{Ctx, advance_parcel, wind_at};

/// The frames that simulate exactly `duration_s` with frames of `dt_s`:
/// `full` frames of `dt_s`, then one shorter frame of `last_s` when
/// `dt_s` does not divide the duration (0: none).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FramePlan {
    pub dt_s: f64,
    pub full: u64,
    pub last_s: f64,
}

impl FramePlan {
    /// The plan for `duration_s` (>= 0) in frames of `dt_s` (> 0). A
    /// quotient within round-off of a whole number counts as whole.
    pub fn new(duration_s: f64, dt_s: f64) -> Self {
        let n = (duration_s / dt_s).round();
        if (n * dt_s - duration_s).abs() <= 1e-9 * duration_s.max(dt_s) {
            return Self {
                dt_s,
                full: n as u64,
                last_s: 0.0,
            };
        }
        let full = (duration_s / dt_s).floor();
        Self {
            dt_s,
            full: full as u64,
            last_s: duration_s - full * dt_s,
        }
    }

    /// Frames in all, the short one included.
    pub fn frames(&self) -> u64 {
        self.full + u64::from(self.last_s > 0.0)
    }

    /// The length of frame `k` (0-based), s.
    pub fn frame_s(&self, k: u64) -> f64 {
        if k < self.full {
            self.dt_s
        } else {
            self.last_s
        }
    }

    /// Whether the state after frame `f` (1-based) is recorded when
    /// records are taken every `every_s` simulated seconds: every
    /// `every_s / dt_s` frames (rounded, at least 1), and the last frame.
    pub fn records_after(&self, f: u64, every_s: f64) -> bool {
        let stride = (every_s / self.dt_s).round().max(1.0) as u64;
        f.is_multiple_of(stride) || f == self.frames()
    }
}

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
    /// The most water a parcel is born with (`spawn::release_qt_cap`).
    qt_cap: f64,
}

/// One parcel's state as the zipped iterators hand it out.
type ParcelRefs<'a> = (
    (
        (((&'a mut DVec3, &'a mut DVec3), &'a mut f64), &'a mut f64),
        &'a mut Diag,
    ),
    &'a mut Life,
);

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
        let qt_cap = release_qt_cap(&cfg, &atm);
        for i in 0..n {
            spawn(&cfg, &atm, &[], qt_cap, &mut parcels, i, 0);
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
            qt_cap,
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
            self.qt_cap,
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

    /// Projects the parcels into `field` (P) over the cloud `band`, with
    /// the configuration's domain and fill scale
    /// ([`ProjectedField::project`]).
    pub fn project_into(&self, field: &mut ProjectedField, band: Band) {
        field.project(
            &self.parcels,
            self.cfg.domain_size_m,
            band,
            self.cfg.fill_full_condensed_fraction,
        );
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_plan_covers_exactly_the_duration() {
        for (d, dt) in [
            (3600.0, 7.0),
            (3600.0, 5.0),
            (0.3, 0.1),
            (1.0, 5.0),
            (10.5, 2.0),
        ] {
            let p = FramePlan::new(d, dt);
            let total: f64 = (0..p.frames()).map(|k| p.frame_s(k)).sum();
            assert!((total - d).abs() < 1e-9 * d, "{d} / {dt}: {p:?}");
            assert!(p.last_s >= 0.0 && p.last_s < dt, "{p:?}");
        }
        assert_eq!(FramePlan::new(0.3, 0.1).frames(), 3);
        assert_eq!(FramePlan::new(3600.0, 7.0).frames(), 515);
    }
}
