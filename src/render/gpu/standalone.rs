//! What the two stand-alone passes share, the pseudo-spheroids
//! (`spheroids.rs`) and the precomputed volumes (`volume_pass.rs`): one
//! full-screen draw straight into the target, bind group 0 the frame
//! uniforms alone (so the analytic sky), the settings' constants, and an
//! 8-bit read-back for tools and tests.

use super::settings::GpuSettings;
use super::uniforms::{FrameInputs, FrameUniforms};
use super::{GpuContext, GpuError};
use crate::render::camera::Camera;

/// The pipeline constants for a target of `format`.
pub(super) fn constants(
    settings: &GpuSettings,
    format: wgpu::TextureFormat,
) -> Vec<(&'static str, f64)> {
    let mut c = settings.constants();
    c.push(("ENCODE_SRGB", (!format.is_srgb()) as u8 as f64));
    c.push((
        "TONE_MAP",
        (!super::composite_pass::is_hdr(format)) as u8 as f64,
    ));
    c
}

/// The frame uniforms of a still `width x height` view from `camera`.
pub(super) fn uniforms(
    settings: &GpuSettings,
    camera: &Camera,
    width: u32,
    height: u32,
) -> FrameUniforms {
    let aspect = width as f32 / height.max(1) as f32;
    FrameUniforms::new(&FrameInputs {
        view: camera.view(aspect, settings.quality.max_distance_m),
        depth_flipped: false,
        prev_view_proj: glam::Mat4::IDENTITY,
        width,
        height,
        sun_elevation_deg: settings.sun_elevation_deg,
        sun_azimuth_deg: settings.sun_azimuth_deg,
        density: settings.density,
        quality: settings.quality,
        jitter: [0.0; 3],
        blend: 1.0,
        frame_index: 0,
        terrain: [0.0; 2],
        p_size: [1, 1],
        mask: [1, 1, 1, 0],
        map_size: 1,
    })
}

/// Records one frame with `record` into a new `width x height` target of
/// `format` and reads it back as 8-bit RGB, row-major (`Err` for other
/// than an RGBA8 format).
pub(super) fn read_rgb8(
    ctx: &GpuContext,
    format: wgpu::TextureFormat,
    width: u32,
    height: u32,
    record: impl FnOnce(&mut wgpu::CommandEncoder, &wgpu::TextureView),
) -> Result<Vec<u8>, GpuError> {
    use wgpu::TextureFormat::{Rgba8Unorm, Rgba8UnormSrgb};
    if !matches!(format, Rgba8Unorm | Rgba8UnormSrgb) {
        return Err(GpuError::Readback(format!(
            "a stand-alone pass reads back RGBA8 targets, not {format:?}"
        )));
    }
    let target = super::textures::create_2d(
        &ctx.device,
        "standalone.target",
        width,
        height,
        format,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    let view = target.create_view(&Default::default());
    let mut e = ctx.device.create_command_encoder(&Default::default());
    record(&mut e, &view);
    ctx.queue.submit([e.finish()]);
    let px = ctx.read_texture(&target, 4)?;
    Ok(px
        .chunks_exact(4)
        .flat_map(|q| [q[0], q[1], q[2]])
        .collect())
}
