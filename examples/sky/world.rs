//! The live sky: a scene, its parcel simulation (or, with `[simulation]
//! method = "automaton"`, its cellular automaton), P, the cloud map and
//! the terrain, and the history of one picked parcel (the paper's Fig. 5).
//! The demo draws every scene with the cloud map: the spheroid and
//! endless-volume methods are `cumulus render`'s (it says so on load).

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::time::Instant;

use cumulus::panel::PanelState;
use cumulus::prepare::spawn_sites;
use cumulus::render::cloud_map::CloudMap;
use cumulus::render::terrain::Heightfield;
use cumulus::scene::{Method, RenderMethod, Scene, SceneError};
use cumulus::sim::automaton::Automaton;
use cumulus::sim::{Atmosphere, Band, ProjectedField, Simulation};

/// One sample of the picked parcel's curves.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    pub t_min: f64,
    pub z_m: f64,
    pub w_mps: f64,
    pub theta_v_k: f64,
    pub theta_v_env_k: f64,
    pub qc_gkg: f64,
}

/// Samples kept for the plot (20 simulated minutes at one a frame).
const HISTORY: usize = 2400;

pub struct World {
    pub scene: Scene,
    pub path: PathBuf,
    pub atmosphere: Atmosphere,
    pub band: Band,
    pub sim: Simulation,
    /// The automaton, when the scene's method is one (then `sim` is idle).
    pub automaton: Option<Automaton>,
    /// Sky seconds the automaton has not yet stepped.
    automaton_lag_s: f64,
    pub field: ProjectedField,
    pub cloud_map: CloudMap,
    pub terrain: Option<Heightfield>,
    pub panel: PanelState,
    /// Simulated seconds per real second.
    pub speed: f64,
    pub paused: bool,
    /// The parcel whose curves are plotted, and its generation when picked.
    pub picked: Option<(usize, u32)>,
    pub history: VecDeque<Sample>,
    /// Wall time of the last physics advance and projection, ms.
    pub physics_ms: f64,
    pub projection_ms: f64,
    /// Bumped whenever P changed (the debug view re-uploads it).
    pub field_version: u64,
}

/// Simulated minutes run when a scene is loaded, so clouds are already up.
pub const SPIN_UP_S: f64 = 1200.0;

impl World {
    /// Loads `path` and spins its sky up.
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let (scene, builtin) = Scene::load_or_builtin(path)?;
        if builtin {
            eprintln!(
                "scene: the built-in copy of scenes/{}.toml (pass --scene PATH for a file)",
                path.display()
            );
        }
        Self::from_scene(scene, path.to_owned())
    }

    /// Builds the world of `scene`.
    pub fn from_scene(scene: Scene, path: PathBuf) -> Result<Self, SceneError> {
        let atmosphere = scene.atmosphere(None)?;
        let band = scene.band(&atmosphere);
        let cloud_map = CloudMap::generate(&scene.render.cloud_map);
        let terrain = scene
            .render
            .terrain
            .enabled
            .then(|| Heightfield::generate(&scene.render.terrain));
        let panel = PanelState::from_scene(&scene, band);
        if scene.simulation.method == Method::Endless
            || scene.render.renderer == RenderMethod::Spheroids
        {
            eprintln!(
                "{}: the demo animates it with the parcels and draws it with the cloud map; \
                 `cumulus render --scene {0}` draws it with its own method (docs/methods.md)",
                path.display()
            );
        }
        let mut w = Self {
            sim: Simulation::new(scene.physics.clone(), atmosphere.clone()),
            automaton: None,
            automaton_lag_s: 0.0,
            field: ProjectedField::new(scene.projection.width, scene.projection.height),
            scene,
            path,
            atmosphere,
            band,
            cloud_map,
            terrain,
            panel,
            speed: 60.0,
            paused: false,
            picked: None,
            history: VecDeque::new(),
            physics_ms: 0.0,
            projection_ms: 0.0,
            field_version: 0,
        };
        w.restart_simulation();
        Ok(w)
    }

    /// A new simulation with the scene's physics, born on the cloud map's
    /// cells and spun up for [`SPIN_UP_S`].
    pub fn restart_simulation(&mut self) {
        let l = self.scene.physics.domain_size_m;
        self.automaton = None;
        if self.scene.simulation.method == Method::Automaton {
            let mut a = Automaton::new(
                &self.scene.simulation.automaton,
                &self.scene.physics,
                self.band,
                &spawn_sites(&self.cloud_map, l),
                self.field.width(),
                self.field.height(),
            );
            for _ in 0..(SPIN_UP_S / a.step_s()) as usize {
                a.step();
            }
            self.automaton = Some(a);
            self.automaton_lag_s = 0.0;
            self.picked = None;
            self.history.clear();
            self.project();
            return;
        }
        let mut sim = Simulation::new(self.scene.physics.clone(), self.atmosphere.clone());
        sim.set_spawn_sites(spawn_sites(&self.cloud_map, l));
        let dt = self.scene.physics.dt_s;
        for _ in 0..(SPIN_UP_S / dt) as usize {
            sim.step();
        }
        self.sim = sim;
        self.picked = None;
        self.history.clear();
        self.project();
    }

    /// Advances the simulation by `real_dt_s` of wall time at the chosen
    /// speed, in frames of at most the scene's `dt_s`, then projects P.
    pub fn update(&mut self, real_dt_s: f64) {
        if self.paused {
            return;
        }
        self.advance(real_dt_s * self.speed);
    }

    /// Advances `sim_s` simulated seconds and projects.
    pub fn advance(&mut self, sim_s: f64) {
        let start = Instant::now();
        if let Some(a) = &mut self.automaton {
            self.automaton_lag_s += sim_s.min(10.0 * a.step_s());
            while self.automaton_lag_s >= a.step_s() {
                a.step();
                self.automaton_lag_s -= a.step_s();
            }
            self.physics_ms = start.elapsed().as_secs_f64() * 1e3;
            self.project();
            return;
        }
        let dt = self.scene.physics.dt_s;
        let mut left = sim_s.min(10.0 * dt);
        while left > 1e-9 {
            let h = left.min(dt);
            self.sim.advance(h);
            left -= h;
        }
        self.physics_ms = start.elapsed().as_secs_f64() * 1e3;
        self.record_picked();
        self.project();
    }

    /// Simulated seconds since the spin-up began (the automaton's steps
    /// times its step, or the parcels' clock).
    pub fn time_s(&self) -> f64 {
        match &self.automaton {
            Some(a) => a.steps() as f64 * a.step_s() + self.automaton_lag_s,
            None => self.sim.time_s(),
        }
    }

    /// Projects the parcels into P.
    pub fn project(&mut self) {
        let start = Instant::now();
        match &self.automaton {
            Some(a) => a.project_into(&mut self.field),
            None => self.sim.project_into(&mut self.field, self.band),
        }
        self.projection_ms = start.elapsed().as_secs_f64() * 1e3;
        self.field_version += 1;
    }

    /// Picks the parcel nearest to map coordinate `(u, v)` (0..1).
    pub fn pick(&mut self, u: f64, v: f64) {
        let l = self.scene.physics.domain_size_m;
        let p = self.sim.parcels();
        let d = |i: usize| {
            let dx = (p.pos[i].x / l - u + 0.5).rem_euclid(1.0) - 0.5;
            let dy = (p.pos[i].y / l - v + 0.5).rem_euclid(1.0) - 0.5;
            dx * dx + dy * dy
        };
        self.picked = (0..p.len())
            .min_by(|&a, &b| d(a).total_cmp(&d(b)))
            .map(|i| (i, p.life[i].generation));
        self.history.clear();
        self.record_picked();
    }

    fn record_picked(&mut self) {
        let Some((i, generation)) = self.picked else {
            return;
        };
        let p = self.sim.parcels();
        if i >= p.len() || p.life[i].generation != generation {
            // Re-born: a new life, a new curve.
            self.picked = (i < p.len()).then(|| (i, p.life[i].generation));
            self.history.clear();
        }
        let d = &p.diag[i];
        self.history.push_back(Sample {
            t_min: self.sim.time_s() / 60.0,
            z_m: p.pos[i].z,
            w_mps: p.vel[i].z,
            theta_v_k: d.theta_v,
            theta_v_env_k: d.theta_v_env,
            qc_gkg: d.qc * 1e3,
        });
        while self.history.len() > HISTORY {
            self.history.pop_front();
        }
    }

    /// Applies the panel to the scene and the running simulation; returns
    /// what the renderer must rebuild.
    pub fn apply_panel(&mut self) -> Changes {
        let before = self.scene.clone();
        self.panel.apply(&mut self.scene);
        let s = self.scene.clone();
        let mut changes = Changes::default();
        if s.physics.wind != before.physics.wind {
            self.sim.set_wind(s.physics.wind.clone());
        }
        if s.physics.parcels != before.physics.parcels {
            self.restart_simulation();
        }
        if s.projection != before.projection {
            self.band = self.scene.band(&self.atmosphere);
            self.project();
        }
        if s.render.terrain.enabled != before.render.terrain.enabled {
            self.terrain = s
                .render
                .terrain
                .enabled
                .then(|| Heightfield::generate(&s.render.terrain));
            changes.terrain = true;
        }
        changes.settings = s.render != before.render || s.projection != before.projection;
        changes
    }
}

/// What changed for the renderer.
#[derive(Debug, Default, Clone, Copy)]
pub struct Changes {
    pub settings: bool,
    pub terrain: bool,
}

/// The scene files in `dir`, sorted.
pub fn scene_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(Result::ok)
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|e| e == "toml"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}
