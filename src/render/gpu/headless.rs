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

/// The HDR offscreen target's format: linear radiance as 32-bit floats,
/// not tone-mapped (the composite pass leaves a float target linear), for
/// OpenEXR output.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// An offscreen target of `format` that can be read back.
pub fn target(
    ctx: &GpuContext,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
) -> wgpu::Texture {
    textures::create_2d(
        &ctx.device,
        "headless.target",
        width,
        height,
        format,
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
        size: (u32, u32),
    ) -> Result<Self, GpuError> {
        Self::with_format(
            ctx,
            field,
            cloud_map,
            terrain,
            settings,
            size,
            TARGET_FORMAT,
        )
    }

    /// [`Self::new`] with a target of `format`: [`TARGET_FORMAT`] for
    /// tone-mapped sRGB pixels ([`Self::read_rgb8`]), [`HDR_FORMAT`] for
    /// linear radiance ([`Self::read_linear`]).
    pub fn with_format(
        ctx: &GpuContext,
        field: &ProjectedField,
        cloud_map: &CloudMap,
        terrain: Option<&Heightfield>,
        settings: &GpuSettings,
        (width, height): (u32, u32),
        format: wgpu::TextureFormat,
    ) -> Result<Self, GpuError> {
        let mut renderer = CloudRenderer::new(
            &ctx.device,
            &ctx.queue,
            format,
            settings,
            cloud_map,
            terrain,
        )?;
        ctx.checked(|| {
            renderer.update_field(&ctx.queue, field);
            renderer.resize(width, height);
            let target = target(ctx, width, height, format);
            Self { renderer, target }
        })
    }

    /// Resizes the renderer and the target.
    pub fn resize(&mut self, ctx: &GpuContext, width: u32, height: u32) {
        self.renderer.resize(width, height);
        self.target = target(ctx, width, height, self.target.format());
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

    /// The linear radiance of a [`HDR_FORMAT`] target, RGB per pixel,
    /// row-major; `None` for a target of another format.
    pub fn read_linear(&self, ctx: &GpuContext) -> Result<Option<Vec<f32>>, GpuError> {
        if self.target.format() != HDR_FORMAT {
            return Ok(None);
        }
        let rgba: Vec<f32> = ctx
            .read_texture(&self.target, 16)?
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        Ok(Some(
            rgba.chunks_exact(4)
                .flat_map(|p| [p[0], p[1], p[2]])
                .collect(),
        ))
    }

    /// The target's pixels as tightly packed RGB8 (sRGB); an error for a
    /// [`HDR_FORMAT`] target (read it with [`Self::read_linear`]).
    pub fn read_rgb8(&self, ctx: &GpuContext) -> Result<Vec<u8>, GpuError> {
        if self.target.format() != TARGET_FORMAT {
            return Err(GpuError::Readback(format!(
                "the target is {:?}, not 8-bit sRGB: read it with read_linear",
                self.target.format()
            )));
        }
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

    /// The density reads of one frame from `camera`, per output pixel
    /// ([`DensityReads`]): the frame marched again with
    /// `debug_sample_count`, which writes each pixel's count (its shadow
    /// rays' reads too) in place of its clouds, then the settings
    /// restored (and the history restarted). A count that does not depend
    /// on the machine, beside the milliseconds.
    pub fn density_reads(
        &mut self,
        ctx: &GpuContext,
        camera: &impl ToView,
    ) -> Result<DensityReads, GpuError> {
        let settings = *self.renderer.settings();
        let mut counting = settings;
        counting.debug_sample_count = true;
        counting.tsaa = None;
        self.renderer.set_settings(&counting);
        let counted =
            self.render(ctx, camera, 1)
                .and_then(|()| match self.renderer.cloud_layer() {
                    Some(layer) => ctx.read_rgba16f(layer),
                    None => Ok(Vec::new()),
                });
        self.renderer.set_settings(&settings);
        let counts = counted?;
        let n = counts.len().max(1) as f64;
        Ok(DensityReads {
            mean: counts.iter().map(|c| c[0] as f64).sum::<f64>() / n,
            max: counts.iter().map(|c| c[0]).fold(0.0, f32::max),
        })
    }
}

/// Density reads per output pixel of one frame ([`Headless::density_reads`]):
/// the march's samples and its shadow rays', read back as half floats
/// (exact to 2,048).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DensityReads {
    pub mean: f64,
    pub max: f32,
}
