//! Error against cost for the CPU's stills: each way of spending marches
//! (`render.cpu_sampling`, `render.cpu_offsets`) against the converged
//! still of the same frame, its cost counted in marches per pixel (the
//! same on any machine).

use std::path::Path;

use super::ReportError;
use super::render_quality::{CLOUD_OPACITY, highpass_energy};
use crate::io::write_atomically;
use crate::render::cpu::frame::Frame;
use crate::render::cpu::still_reconstruction::render_still_adaptive;
use crate::render::cpu::stills::{render_clouds_linear, render_still};
use crate::render::cpu::tone_map::to_srgb8;
use crate::scene::CpuSampling;

/// Marches a pixel of the converged still the others are measured
/// against (every pixel, averaged).
pub const CONVERGED_OFFSETS: u32 = 32;

/// The stills measured: uniform at 1, 2, 4 and 8 marches, adaptive with
/// 4 and 8 at edges.
pub const STILLS: [(CpuSampling, u32); 6] = [
    (CpuSampling::Uniform, 1),
    (CpuSampling::Uniform, 2),
    (CpuSampling::Uniform, 4),
    (CpuSampling::Uniform, 8),
    (CpuSampling::Adaptive, 4),
    (CpuSampling::Adaptive, 8),
];

/// One still measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StillRow {
    pub sampling: CpuSampling,
    pub offsets: u32,
    /// Marches per pixel, on average.
    pub marches_per_pixel: f64,
    /// Mean absolute difference from the converged still, tone-mapped
    /// sRGB8 levels (0..255) over all channels and pixels.
    pub mean_levels: f64,
    /// Its 99th percentile, levels.
    pub p99_levels: f64,
    /// The cloud pixels' high-pass energy over the converged still's: the
    /// grain left (1: none beyond the converged still's own detail).
    pub grain: f64,
}

/// The name of a sampling in the CSV.
pub fn sampling_name(s: CpuSampling) -> &'static str {
    match s {
        CpuSampling::Adaptive => "adaptive",
        CpuSampling::Uniform => "uniform",
    }
}

/// Renders `frame` at `width x height` as each of [`STILLS`] and as the
/// converged still, calling `progress` after each.
pub fn measure_stills(
    frame: &Frame,
    width: u32,
    height: u32,
    mut progress: impl FnMut(),
) -> Vec<StillRow> {
    let exposure = frame.quality.exposure;
    let converged = to_srgb8(
        &render_still(width, height, frame, CONVERGED_OFFSETS),
        exposure,
    );
    progress();
    let mask: Vec<bool> = render_clouds_linear(width, height, frame, 1)
        .iter()
        .map(|c| c.w > CLOUD_OPACITY)
        .collect();
    let reference_grain = highpass_energy(&converged, &mask, width, height).max(1e-12);
    STILLS
        .iter()
        .map(|&(sampling, offsets)| {
            let (linear, marches_per_pixel) = match sampling {
                CpuSampling::Uniform => {
                    (render_still(width, height, frame, offsets), offsets as f64)
                }
                CpuSampling::Adaptive => {
                    let s = render_still_adaptive(width, height, frame, offsets, &|_| {});
                    let m = s.marches_per_pixel();
                    (s.linear, m)
                }
            };
            let img = to_srgb8(&linear, exposure);
            let mut d: Vec<f64> = img
                .iter()
                .zip(&converged)
                .map(|(a, b)| (*a as f64 - *b as f64).abs())
                .collect();
            let mean_levels = d.iter().sum::<f64>() / d.len().max(1) as f64;
            d.sort_by(f64::total_cmp);
            let p99_levels = d.get(d.len() * 99 / 100).copied().unwrap_or(0.0);
            progress();
            StillRow {
                sampling,
                offsets,
                marches_per_pixel,
                mean_levels,
                p99_levels,
                grain: highpass_energy(&img, &mask, width, height) / reference_grain,
            }
        })
        .collect()
}

/// Writes `stills.csv` into `dir`.
pub fn write_stills(
    rows: &[StillRow],
    width: u32,
    height: u32,
    dir: &Path,
) -> Result<(), ReportError> {
    let path = dir.join("stills.csv");
    write_atomically(&path, |out| {
        writeln!(
            out,
            "cpu_sampling,cpu_offsets,width,height,marches_per_pixel,mean_abs_levels,p99_abs_levels,grain_ratio"
        )?;
        for r in rows {
            writeln!(
                out,
                "{},{},{width},{height},{:.3},{:.3},{:.1},{:.3}",
                sampling_name(r.sampling),
                r.offsets,
                r.marches_per_pixel,
                r.mean_levels,
                r.p99_levels,
                r.grain
            )?;
        }
        Ok(())
    })
    .map_err(|source| ReportError::Write {
        path: path.clone(),
        source,
    })
}
