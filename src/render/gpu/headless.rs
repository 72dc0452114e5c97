//! Offscreen rendering of a prepared scene: `cumulus render --backend gpu`,
//! the GPU tests and the frame timings.

use super::context::{GpuContext, GpuError};
use super::renderer::CloudRenderer;
use super::settings::GpuSettings;
use super::textures;
use super::timer::{FrameTimes, time_frames};
use crate::render::camera::ToView;
use crate::render::cloud_map::CloudMap;
use crate::render::terrain::Heightfield;
use crate::sim::ProjectedField;

/// The offscreen target's format: 8-bit sRGB, the CPU `to_srgb8`'s encoding.
pub const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// An offscreen target that can be read back.
pub fn target(ctx: &GpuContext, width: u32, height: u32) -> wgpu::Texture {
    textures::create_2d(
        &ctx.device,
        "headless.target",
        width,
        height,
        TARGET_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    )
}

/// A renderer with its own offscreen target.
pub struct Headless {
    pub renderer: CloudRenderer,
    target: wgpu::Texture,
}

impl Headless {
    /// A `width x height` offscreen renderer of P (`field`), the cloud
    /// map and the terrain with `settings`.
    pub fn new(
        ctx: &GpuContext,
        field: &ProjectedField,
        cloud_map: &CloudMap,
        terrain: Option<&Heightfield>,
        settings: &GpuSettings,
        (width, height): (u32, u32),
    ) -> Result<Self, GpuError> {
        ctx.checked(|| {
            let mut renderer = CloudRenderer::new(
                &ctx.device,
                &ctx.queue,
                TARGET_FORMAT,
                settings,
                cloud_map,
                terrain,
            );
            renderer.update_field(&ctx.queue, field);
            renderer.resize(width, height);
            let target = target(ctx, width, height);
            Self { renderer, target }
        })
    }

    /// Resizes the renderer and the target.
    pub fn resize(&mut self, ctx: &GpuContext, width: u32, height: u32) {
        self.renderer.resize(width, height);
        self.target = target(ctx, width, height);
    }

    /// Renders `frames` frames from `camera` (TSAA accumulates across them)
    /// and waits for the GPU.
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        camera: &impl ToView,
        frames: u32,
    ) -> Result<(), GpuError> {
        for _ in 0..frames {
            self.render_frame(ctx, camera)?;
        }
        ctx.wait()
    }

    fn render_frame(&mut self, ctx: &GpuContext, camera: &impl ToView) -> Result<(), GpuError> {
        let view = self
            .target
            .create_view(&wgpu::TextureViewDescriptor::default());
        ctx.checked(|| {
            let mut encoder = ctx
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("frame"),
                });
            let r = self.renderer.render(&mut encoder, &view, None, camera);
            ctx.queue.submit([encoder.finish()]);
            r
        })??;
        Ok(())
    }

    /// The target's pixels as tightly packed RGB8 (sRGB).
    pub fn read_rgb8(&self, ctx: &GpuContext) -> Result<Vec<u8>, GpuError> {
        let rgba = ctx.read_texture(&self.target, 4)?;
        Ok(rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect())
    }

    /// Times `frames` frames after `warmup` frames ([`time_frames`]): the
    /// GPU time of all passes from timestamp queries, or CPU wall time
    /// from submit to idle without them.
    pub fn time_frames(
        &mut self,
        ctx: &GpuContext,
        camera: &impl ToView,
        warmup: u32,
        frames: u32,
    ) -> Result<FrameTimes, GpuError> {
        let view = self
            .target
            .create_view(&wgpu::TextureViewDescriptor::default());
        let renderer = &mut self.renderer;
        let t = time_frames(ctx, warmup, frames, |encoder, queries| {
            renderer.set_timestamp_queries(queries.cloned());
            renderer.render(encoder, &view, None, camera)?;
            Ok(renderer.last_passes().len())
        });
        renderer.set_timestamp_queries(None);
        t
    }
}
