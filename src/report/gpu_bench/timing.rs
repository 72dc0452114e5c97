//! Timing one configuration: the cloud-map renderer or the spheroid
//! renderer, and the row that reports it.

use super::{BenchOptions, Row};
use crate::prepare::Prepared;
use crate::render::camera::Camera;
use crate::render::cpu::sky::SkyModel;
use crate::render::gpu::headless::{DensityReads, TARGET_FORMAT};
use crate::render::gpu::spheroids::SpheroidRenderer;
use crate::render::gpu::timer::{FrameTimes, time_frames};
use crate::render::gpu::{GpuContext, GpuError, textures};
use crate::scene::RenderSettings;

struct Features {
    tsaa: bool,
    terrain: bool,
    shadow_steps: u32,
    octaves: u32,
    detail: bool,
    sky: &'static str,
    aerial: bool,
}

fn features_of(r: &RenderSettings) -> Features {
    Features {
        tsaa: r.tsaa,
        terrain: r.terrain.enabled,
        shadow_steps: r.shadow_steps,
        octaves: r.octaves,
        detail: r.detail_strength > 0.0,
        sky: match r.atmosphere.model {
            SkyModel::Physical => "physical",
            SkyModel::Analytic => "analytic",
        },
        aerial: r.atmosphere.aerial_perspective,
    }
}

/// Times the cloud-map renderer on `p` with `r`, and counts one frame's
/// density reads per pixel ([`crate::render::gpu::headless::Headless::density_reads`]).
pub(super) fn time_cloud_map(
    ctx: &GpuContext,
    p: &Prepared,
    r: &RenderSettings,
    o: &BenchOptions,
) -> Result<(FrameTimes, DensityReads), GpuError> {
    let mut hl = p.headless(ctx, &p.gpu_settings(r, r.quality()), r.width, r.height)?;
    let t = hl.time_frames(ctx, &r.camera(), o.warmup, o.frames)?;
    let reads = hl.density_reads(ctx, &r.camera())?;
    Ok((t, reads))
}

/// The spheroid renderer of `p`'s parcels with `r`'s settings.
pub(super) fn spheroid_renderer(
    ctx: &GpuContext,
    p: &Prepared,
    r: &RenderSettings,
) -> SpheroidRenderer {
    let settings = p.gpu_settings(r, r.quality());
    let mut s = SpheroidRenderer::new(
        &ctx.device,
        &ctx.queue,
        TARGET_FORMAT,
        &settings,
        p.cloud_map.noise(),
    );
    s.update_spheroids(&p.spheroids());
    s
}

/// Times a stand-alone pass (`draw` records one frame into the target
/// from the camera) at `r`'s size.
pub(super) fn time_pass(
    ctx: &GpuContext,
    r: &RenderSettings,
    o: &BenchOptions,
    mut draw: impl FnMut(
        &mut wgpu::CommandEncoder,
        &wgpu::TextureView,
        &Camera,
        Option<&wgpu::QuerySet>,
    ),
) -> Result<FrameTimes, GpuError> {
    let target = textures::create_2d(
        &ctx.device,
        "bench.target",
        r.width,
        r.height,
        TARGET_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let view = target.create_view(&Default::default());
    let camera = r.camera();
    time_frames(ctx, o.warmup, o.frames, |enc, q| {
        draw(enc, &view, &camera, q);
        Ok(1)
    })
}

pub(super) fn row(
    group: &'static str,
    renderer: &'static str,
    r: &RenderSettings,
    p: &Prepared,
    (t, reads): (Option<&FrameTimes>, Option<DensityReads>),
    frames: u32,
) -> Row {
    let f = features_of(r);
    Row {
        group,
        renderer,
        width: r.width,
        height: r.height,
        coverage: r.coverage,
        parcels: p.parcels.len(),
        tsaa: f.tsaa,
        terrain: f.terrain,
        shadow_steps: f.shadow_steps,
        octaves: f.octaves,
        detail: f.detail,
        sky: f.sky,
        aerial: f.aerial,
        frames: if t.is_some() { frames } else { 0 },
        p_covered: p.field.covered_fraction(),
        median_ms: t.map_or(f64::NAN, FrameTimes::median),
        p95_ms: t.map_or(f64::NAN, FrameTimes::p95),
        timing: t.map_or("skipped", FrameTimes::source),
        reads_mean: reads.map_or(f64::NAN, |r| r.mean),
        reads_max: reads.map_or(f64::NAN, |r| r.max as f64),
    }
}
