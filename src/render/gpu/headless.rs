//! Offscreen rendering of a prepared scene: `cumulus render --backend gpu`,
//! the GPU tests and the frame timings.

use std::time::Instant;

use super::context::{GpuContext, GpuError};
use super::renderer::{CloudRenderer, GpuSettings};
use super::textures;
use crate::render::cpu::camera::Camera;
use crate::render::prepare::Prepared;

/// The offscreen target's format: 8-bit sRGB, the CPU `to_srgb8`'s encoding.
pub const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// A renderer with its own offscreen target.
pub struct Headless {
    pub renderer: CloudRenderer,
    target: wgpu::Texture,
    timer: Option<(wgpu::QuerySet, wgpu::Buffer)>,
}

/// Timestamp queries the renderer may write (two per pass, four passes).
const QUERIES: u32 = 8;

impl Headless {
    /// A `width x height` offscreen renderer of `prepared` with `settings`.
    pub fn new(
        ctx: &GpuContext,
        prepared: &Prepared,
        settings: &GpuSettings,
        width: u32,
        height: u32,
    ) -> Result<Self, GpuError> {
        ctx.checked(|| {
            let mut renderer = CloudRenderer::new(
                &ctx.device,
                &ctx.queue,
                TARGET_FORMAT,
                settings,
                &prepared.cloud_map,
                prepared.terrain.as_ref(),
            );
            renderer.update_field(&ctx.queue, &prepared.field);
            renderer.resize(width, height);
            let target = textures::create_2d(
                &ctx.device,
                "headless.target",
                width,
                height,
                TARGET_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            );
            Self {
                renderer,
                target,
                timer: None,
            }
        })
    }

    /// Resizes the renderer and the target.
    pub fn resize(&mut self, ctx: &GpuContext, width: u32, height: u32) {
        self.renderer.resize(width, height);
        self.target = textures::create_2d(
            &ctx.device,
            "headless.target",
            width,
            height,
            TARGET_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
    }

    /// Renders `frames` frames from `camera` (TSAA accumulates across them)
    /// and waits for the GPU.
    pub fn render(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        frames: u32,
    ) -> Result<(), GpuError> {
        for _ in 0..frames {
            self.render_frame(ctx, camera)?;
        }
        ctx.wait()
    }

    fn render_frame(&mut self, ctx: &GpuContext, camera: &Camera) -> Result<(), GpuError> {
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
            if let Some((q, b)) = &self.timer {
                let n = 2 * self.renderer.last_passes().len() as u32;
                if n > 0 {
                    encoder.resolve_query_set(q, 0..n, b, 0);
                }
            }
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

    /// Times `frames` frames after `warmup` frames: per frame, the GPU
    /// time of all passes from timestamp queries (`gpu: true`) or, without
    /// them, the CPU wall time from submit to idle (`gpu: false`), ms.
    pub fn time_frames(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        warmup: u32,
        frames: u32,
    ) -> Result<FrameTimes, GpuError> {
        self.render(ctx, camera, warmup)?;
        if ctx.timestamps && self.timer.is_none() {
            let q = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("frame.timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: QUERIES,
            });
            let b = ctx.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame.timestamps"),
                size: QUERIES as u64 * 8,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            self.renderer.set_timestamp_queries(Some(q.clone()));
            self.timer = Some((q, b));
        }
        let period_ns = ctx.queue.get_timestamp_period() as f64;
        let mut ms = Vec::with_capacity(frames as usize);
        let mut per_pass: Vec<Vec<f64>> = Vec::new();
        for _ in 0..frames {
            let start = Instant::now();
            self.render_frame(ctx, camera)?;
            ctx.wait()?;
            let wall = start.elapsed().as_secs_f64() * 1e3;
            match &self.timer {
                Some((_, b)) => {
                    let ticks = read_u64s(ctx, b, QUERIES)?;
                    let n = self.renderer.last_passes().len();
                    let passes: Vec<f64> = (0..n)
                        .map(|k| {
                            ticks[2 * k + 1].saturating_sub(ticks[2 * k]) as f64 * period_ns * 1e-6
                        })
                        .collect();
                    ms.push(ticks[2 * n - 1].saturating_sub(ticks[0]) as f64 * period_ns * 1e-6);
                    per_pass.push(passes);
                }
                None => ms.push(wall),
            }
        }
        Ok(FrameTimes {
            gpu: self.timer.is_some(),
            ms,
            per_pass,
            passes: self.renderer.last_passes().to_vec(),
        })
    }
}

fn read_u64s(ctx: &GpuContext, src: &wgpu::Buffer, n: u32) -> Result<Vec<u64>, GpuError> {
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("timestamps.readback"),
        size: n as u64 * 8,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut e = ctx.device.create_command_encoder(&Default::default());
    e.copy_buffer_to_buffer(src, 0, &staging, 0, n as u64 * 8);
    ctx.queue.submit([e.finish()]);
    let slice = staging.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    ctx.wait()?;
    rx.recv()
        .map_err(|e| GpuError::Readback(e.to_string()))?
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    let data = slice
        .get_mapped_range()
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    let v = bytemuck::cast_slice::<u8, u64>(&data).to_vec();
    drop(data);
    staging.unmap();
    Ok(v)
}

/// Frame times of [`Headless::time_frames`].
#[derive(Debug, Clone)]
pub struct FrameTimes {
    /// From GPU timestamps (else CPU wall time, submit to idle).
    pub gpu: bool,
    /// Per frame, ms.
    pub ms: Vec<f64>,
    /// Per frame and pass (GPU timestamps only), ms.
    pub per_pass: Vec<Vec<f64>>,
    /// The passes, in order.
    pub passes: Vec<&'static str>,
}

impl FrameTimes {
    /// The `q`-quantile (0..=1) of `v`.
    pub fn quantile(v: &[f64], q: f64) -> f64 {
        let mut s = v.to_vec();
        s.sort_by(f64::total_cmp);
        if s.is_empty() {
            return f64::NAN;
        }
        s[((s.len() - 1) as f64 * q).round() as usize]
    }

    /// Median frame time, ms.
    pub fn median(&self) -> f64 {
        Self::quantile(&self.ms, 0.5)
    }

    /// 95th percentile, ms.
    pub fn p95(&self) -> f64 {
        Self::quantile(&self.ms, 0.95)
    }
}
