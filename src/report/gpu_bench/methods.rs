//! The animation and rendering methods side by side on one scene: the
//! cloud map fed by the parcels (ours), the cloud map fed by the cellular
//! automaton, and the pseudo-spheroid renderer of the same parcels; for
//! each, the frame, the simulation step and (spheroids) the light grid's
//! CPU build.

use std::time::Instant;

use super::timing::{time_cloud_map, time_spheroids, time_volume};
use super::{BenchError, BenchOptions, MethodRow};
use crate::endless::{Database, Player, ThresholdRow, threshold_sweep};
use crate::prepare::{Prepared, spawn_sites};
use crate::render::cloud_map::CloudMap;
use crate::render::gpu::GpuContext;
use crate::render::gpu::spheroids::SpheroidRenderer;
use crate::render::gpu::textures::field_texels;
use crate::render::gpu::timer::FrameTimes;
use crate::scene::{Method, Scene};
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

/// One simulation step of `sc`'s method, spun up for the scene's
/// `time_s` (at most 240 steps), ms and the sky seconds it advances.
fn step_cost(sc: &Scene, samples: usize) -> Result<(f64, f64), BenchError> {
    let atm = sc.atmosphere(None)?;
    let band = sc.band(&atm);
    let spin = Prepared::frames(sc).min(240);
    Ok(match sc.simulation.method {
        Method::Parcels | Method::Endless => {
            let mut sim = Simulation::new(sc.physics.clone(), atm);
            let map = CloudMap::generate(&sc.render.cloud_map);
            sim.set_spawn_sites(spawn_sites(&map, sc.physics.domain_size_m));
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
            let map = CloudMap::generate(&sc.render.cloud_map);
            let sites = spawn_sites(&map, sc.physics.domain_size_m);
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
    for (sc, method) in [(base, "parcels"), (&automaton, "automaton")] {
        progress(&format!("methods: {method}, cloud map"));
        let p = Prepared::from_scene(sc, || {})?;
        let t = time_cloud_map(ctx, &p, r, o)?;
        let (step_ms, step_s) = step_cost(sc, samples)?;
        rows.push(MethodRow {
            method,
            renderer: "cloud_map",
            width: r.width,
            height: r.height,
            p_covered: p.field.covered_fraction(),
            median_ms: t.median(),
            p95_ms: t.p95(),
            timing: t.source(),
            step_ms,
            step_s,
            light_grid_ms: 0.0,
            state_bytes: field_texels(&p.field).len() * 2,
        });
        if sc.simulation.method == Method::Parcels {
            progress("methods: parcels, spheroids");
            let ts = time_spheroids(ctx, &p, r, o)?;
            let settings = p.gpu_settings(r, r.quality());
            let mut s = SpheroidRenderer::new(
                &ctx.device,
                &ctx.queue,
                crate::render::gpu::headless::TARGET_FORMAT,
                &settings,
            );
            let spheroids = p.spheroids();
            let grid_ms = median_ms(samples.min(5), || s.update_spheroids(&spheroids));
            rows.push(MethodRow {
                method,
                renderer: "spheroids",
                width: r.width,
                height: r.height,
                p_covered: p.field.covered_fraction(),
                median_ms: ts.median(),
                p95_ms: ts.p95(),
                timing: ts.source(),
                step_ms,
                step_s,
                light_grid_ms: grid_ms,
                state_bytes: spheroids.len() * size_of::<crate::render::cpu::spheroids::Spheroid>()
                    + 4 * (12
                        + crate::render::cpu::spheroids::LIGHT_GRID_DIMS
                            .iter()
                            .product::<usize>()),
            });
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
    let p = Prepared::from_scene(base, || {})?;
    let t = time_volume(ctx, &p, r, o, &stack, params)?;
    // One step picks the pair to show: far under a timer's resolution,
    // so timed over a thousand.
    let step_ms = median_ms(samples, || {
        for k in 0..1000 {
            std::hint::black_box(player.at(k as f64 * sc_step(base), db.interval_s));
        }
    }) / 1000.0;
    rows.push(MethodRow {
        method: "endless",
        renderer: "volume",
        width: r.width,
        height: r.height,
        p_covered: p.field.covered_fraction(),
        median_ms: t.median(),
        p95_ms: t.p95(),
        timing: t.source(),
        step_ms,
        step_s: sc_step(base),
        light_grid_ms: 0.0,
        state_bytes: db.bytes(),
    });
    let sweep = threshold_sweep(&db, &SIMILARITIES, 10_000, base.physics.seed);
    Ok((rows, sweep))
}

/// The sky seconds one physics step advances (the volumes' playback is
/// stepped as often, for a like-for-like row).
fn sc_step(sc: &Scene) -> f64 {
    sc.physics.dt_s
}
