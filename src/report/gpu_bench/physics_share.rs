//! The physics' share of a frame: step, projection and upload of P, each
//! timed on the CPU against the GPU frame time.

use std::time::Instant;

use super::{BenchError, PhysicsRow};
use crate::prepare::Prepared;
use crate::render::gpu::GpuContext;
use crate::render::gpu::timer::FrameTimes;
use crate::scene::Scene;
use crate::sim::{ProjectedField, Simulation};

fn median(v: &mut [f64]) -> f64 {
    FrameTimes::quantile(v, 0.5)
}

/// Physics step, projection and upload, each the median of `samples`
/// frames of a simulation spun up for the scene's `time_s` (CPU wall time).
pub(super) fn physics_in_frame(
    ctx: &GpuContext,
    sc: &Scene,
    parcels: usize,
    frame_ms: f64,
    samples: usize,
) -> Result<PhysicsRow, BenchError> {
    let atm = sc.atmosphere(None)?;
    let band = sc.band(&atm);
    let mut sim = Simulation::new(sc.physics.clone(), atm);
    for _ in 0..Prepared::frames(sc).min(240) {
        sim.step();
    }
    let mut quick = sc.clone();
    quick.render.time_s = 0.0;
    let p = Prepared::from_scene(&quick, || {})?;
    let mut hl = p.headless(ctx, &p.gpu_settings(&sc.render, sc.render.quality()), 8, 8)?;
    let mut field = ProjectedField::new(sc.projection.width, sc.projection.height);
    let (mut step, mut project, mut upload) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..samples {
        let t = Instant::now();
        sim.step();
        step.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        sim.project_into(&mut field, band);
        project.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        hl.renderer.update_field(&ctx.queue, &field);
        ctx.queue.submit([]);
        ctx.wait()?;
        upload.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let (s, pr, u) = (median(&mut step), median(&mut project), median(&mut upload));
    Ok(PhysicsRow {
        parcels,
        physics_ms: s,
        projection_ms: pr,
        upload_ms: u,
        frame_ms,
        share_pct: 100.0 * (s + pr + u) / frame_ms,
    })
}
