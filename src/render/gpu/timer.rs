//! Frame timing: GPU timestamp queries around each pass when the device
//! has them, else CPU wall time from submit to idle (labelled as such).

use std::time::Instant;

use super::context::{GpuContext, GpuError};

/// Timestamp queries available to a frame: two per pass, up to four passes.
pub const QUERIES: u32 = 8;

/// Frame times of [`time_frames`].
#[derive(Debug, Clone)]
pub struct FrameTimes {
    /// From GPU timestamps (else CPU wall time, submit to idle).
    pub gpu: bool,
    /// Per frame, ms.
    pub ms: Vec<f64>,
    /// Per frame and pass (GPU timestamps only), ms.
    pub per_pass: Vec<Vec<f64>>,
}

impl FrameTimes {
    /// The `q`-quantile (0..=1) of `v` (nearest rank); NaN when empty.
    pub fn quantile(v: &[f64], q: f64) -> f64 {
        let mut s = v.to_vec();
        s.sort_by(f64::total_cmp);
        if s.is_empty() {
            return f64::NAN;
        }
        s[((s.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize]
    }

    /// Median frame time, ms.
    pub fn median(&self) -> f64 {
        Self::quantile(&self.ms, 0.5)
    }

    /// 95th percentile, ms.
    pub fn p95(&self) -> f64 {
        Self::quantile(&self.ms, 0.95)
    }

    /// What the times are: "gpu" (timestamps) or "wall" (CPU, submit to idle).
    pub fn source(&self) -> &'static str {
        if self.gpu { "gpu" } else { "wall" }
    }
}

/// Records `warmup` then `frames` frames with `record` (which gets the
/// query set to write pass timestamps into, two per pass, and returns the
/// number of passes it timed), submits and waits for each, and returns the
/// timed frames' durations.
pub fn time_frames(
    ctx: &GpuContext,
    warmup: u32,
    frames: u32,
    mut record: impl FnMut(
        &mut wgpu::CommandEncoder,
        Option<&wgpu::QuerySet>,
    ) -> Result<usize, GpuError>,
) -> Result<FrameTimes, GpuError> {
    let queries = ctx.timestamps.then(|| {
        let q = ctx.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("frame.timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: QUERIES,
        });
        let resolve = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame.timestamps.resolve"),
            size: QUERIES as u64 * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame.timestamps.readback"),
            size: QUERIES as u64 * 8,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        (q, resolve, staging)
    });
    let period_ns = ctx.queue.get_timestamp_period() as f64;
    let mut out = FrameTimes {
        gpu: queries.is_some(),
        ms: Vec::with_capacity(frames as usize),
        per_pass: Vec::new(),
    };
    for k in 0..warmup + frames {
        let start = Instant::now();
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame"),
            });
        let passes = ctx.checked(|| record(&mut encoder, queries.as_ref().map(|q| &q.0)))??;
        if let Some((q, resolve, staging)) = &queries {
            let n = (2 * passes as u32).min(QUERIES);
            if n > 0 {
                encoder.resolve_query_set(q, 0..n, resolve, 0);
                encoder.copy_buffer_to_buffer(resolve, 0, staging, 0, n as u64 * 8);
            }
        }
        ctx.checked(|| ctx.queue.submit([encoder.finish()]))?;
        ctx.wait()?;
        let wall = start.elapsed().as_secs_f64() * 1e3;
        if k < warmup {
            continue;
        }
        match &queries {
            Some((_, _, staging)) if passes > 0 => {
                let ticks = read_u64s(ctx, staging)?;
                let tick_ms = |a: u64, b: u64| b.saturating_sub(a) as f64 * period_ns * 1e-6;
                let per: Vec<f64> = (0..passes.min(4))
                    .map(|p| tick_ms(ticks[2 * p], ticks[2 * p + 1]))
                    .collect();
                out.ms.push(tick_ms(ticks[0], ticks[2 * passes.min(4) - 1]));
                out.per_pass.push(per);
            }
            _ => out.ms.push(wall),
        }
    }
    Ok(out)
}

fn read_u64s(ctx: &GpuContext, staging: &wgpu::Buffer) -> Result<Vec<u64>, GpuError> {
    Ok(bytemuck::pod_collect_to_vec(&ctx.map_read(staging)?))
}
