//! The animation and rendering methods side by side on one scene: the
//! cloud map fed by the parcels (ours), the cloud map fed by the cellular
//! automaton, the pseudo-spheroid renderer of the same parcels, and the
//! endless volumes; for each, the frame, the simulation step, (spheroids)
//! the light grid's CPU build and the state kept on the GPU; and the
//! endless playback's jumps against its similarity temperature.

use std::time::Instant;

use super::timing::{spheroid_renderer, time_cloud_map, time_pass};
use super::{BenchError, BenchOptions, MethodRow};
use crate::endless::{Database, Player, ThresholdRow, threshold_sweep};
use crate::prepare::{Prepared, spawn_sites};
use crate::render::cloud_map::CloudMap;
use crate::render::cpu::spheroids::{LIGHT_GRID_DIMS, Spheroid};
use crate::render::gpu::GpuContext;
use crate::render::gpu::headless::TARGET_FORMAT;
use crate::render::gpu::textures::field_texels;
use crate::render::gpu::timer::FrameTimes;
use crate::render::gpu::volume_pass::VolumeRenderer;
use crate::scene::{Method, RenderSettings, Scene};
use crate::sim::Simulation;
use crate::sim::automaton::Automaton;

/// Median wall time of `samples` calls of `f`, ms.
fn median_ms(samples: usize, mut f: impl FnMut()) -> f64 {
    let v: Vec<f64> = (0..samples.max(1))
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    FrameTimes::quantile(&v, 0.5)
}

/// One row: `method` drawn by `renderer` at `r`'s size in `t`, its step
/// `(ms, sky s)`, its light grid's build and its state on the GPU.
fn method_row(
    (method, renderer): (&'static str, &'static str),
    r: &RenderSettings,
    p_covered: f64,
    t: &FrameTimes,
    (step_ms, step_s): (f64, f64),
    light_grid_ms: f64,
    state_bytes: usize,
) -> MethodRow {
    MethodRow {
        method,
        renderer,
        width: r.width,
        height: r.height,
        p_covered,
        median_ms: t.median(),
        p95_ms: t.p95(),
        timing: t.source(),
        step_ms,
        step_s,
        light_grid_ms,
        state_bytes,
    }
}

/// One simulation step of `sc`'s method, born on `map`'s cells and spun
/// up for the scene's `time_s` (at most 240 steps), ms and the sky
/// seconds it advances.
fn step_cost(sc: &Scene, map: &CloudMap, samples: usize) -> Result<(f64, f64), BenchError> {
    let atm = sc.atmosphere(None)?;
    let band = sc.band(&atm);
    let spin = Prepared::frames(sc).min(240);
    Ok(match sc.simulation.method {
        Method::Parcels | Method::Endless => {
            let mut sim = Simulation::new(sc.physics.clone(), atm);
            sim.set_spawn_sites(spawn_sites(map, sc.physics.domain_size_m));
            for _ in 0..spin {
                sim.step();
            }
            (
                median_ms(samples, || {
                    sim.step();
                }),
                sc.physics.dt_s,
            )
        }
        Method::Automaton => {
            let sites = spawn_sites(map, sc.physics.domain_size_m);
            let mut a = Automaton::new(
                &sc.simulation.automaton,
                &sc.physics,
                band,
                &sites,
                sc.projection.width,
                sc.projection.height,
            );
            for _ in 0..spin {
                a.step();
            }
            (median_ms(samples, || a.step()), a.step_s())
        }
    })
}

/// The similarity temperatures the endless playback is played at.
pub const SIMILARITIES: [f64; 6] = [0.05, 0.2, 0.5, 1.0, 2.0, 5.0];

/// The methods' rows on `base` at its resolution, and the endless
/// playback's jumps against its similarity temperature.
pub(super) fn compare_methods(
    ctx: &GpuContext,
    base: &Scene,
    o: &BenchOptions,
    mut progress: impl FnMut(&str),
) -> Result<(Vec<MethodRow>, Vec<ThresholdRow>), BenchError> {
    let samples = if o.quick { 3 } else { 20 };
    let r = &base.render;
    let mut rows = Vec::new();
    let mut automaton = base.clone();
    automaton.simulation.method = Method::Automaton;
    let mut parcels_covered = 0.0;
    for (sc, method) in [(base, "parcels"), (&automaton, "automaton")] {
        progress(&format!("methods: {method}, cloud map"));
        let p = Prepared::from_scene(sc, || {})?;
        let covered = p.field.covered_fraction();
        let (t, _) = time_cloud_map(ctx, &p, r, o)?;
        let step = step_cost(sc, &p.cloud_map, samples)?;
        let p_bytes = field_texels(&p.field).len() * 2;
        rows.push(method_row(
            (method, "cloud_map"),
            r,
            covered,
            &t,
            step,
            0.0,
            p_bytes,
        ));
        if sc.simulation.method == Method::Parcels {
            progress("methods: parcels, spheroids");
            parcels_covered = covered;
            let mut s = spheroid_renderer(ctx, &p, r);
            s.resize(r.width, r.height);
            let ts = time_pass(ctx, r, o, |e, v, c, q| s.render(e, v, c, q))?;
            let spheroids = p.spheroids();
            let grid_ms = median_ms(samples.min(5), || s.update_spheroids(&spheroids));
            let bytes = spheroids.len() * size_of::<Spheroid>()
                + 4 * (12 + LIGHT_GRID_DIMS.iter().product::<usize>());
            rows.push(method_row(
                (method, "spheroids"),
                r,
                covered,
                &ts,
                step,
                grid_ms,
                bytes,
            ));
        }
    }
    progress("methods: endless volumes");
    let mut cfg = base.simulation.endless.clone();
    if o.quick {
        cfg.volumes = 3;
        cfg.cells = [16, 4, 16];
    }
    let db = Database::build(base, &cfg, || {})?;
    let mut player = Player::new(&db, cfg.similarity, base.physics.seed);
    let (stack, params) = db.stack(player.at(0.0, db.interval_s));
    let settings = db.gpu_settings(r);
    // The land's fields read the cloud map's detail volume.
    let land = Prepared::unsimulated(base)?;
    let mut v = VolumeRenderer::new(
        &ctx.device,
        &ctx.queue,
        TARGET_FORMAT,
        &settings,
        &stack,
        params,
        land.cloud_map.noise(),
    )?;
    v.resize(r.width, r.height);
    let t = time_pass(ctx, r, o, |e, view, c, q| v.render(e, view, c, q))?;
    // Playback is stepped as often as the physics, for a like-for-like
    // row; one step picks the pair to show, far under a timer's
    // resolution, so it is timed over a thousand.
    let dt = base.physics.dt_s;
    let step_ms = median_ms(samples, || {
        for k in 0..1000 {
            std::hint::black_box(player.at(k as f64 * dt, db.interval_s));
        }
    }) / 1000.0;
    rows.push(method_row(
        ("endless", "volume"),
        r,
        parcels_covered,
        &t,
        (step_ms, dt),
        0.0,
        db.bytes(),
    ));
    let sweep = threshold_sweep(&db, &SIMILARITIES, 10_000, base.physics.seed);
    Ok((rows, sweep))
}
