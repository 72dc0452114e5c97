//! Error against cost for the CPU renderer: the same frame at primary step
//! counts from low to a high-step reference.

use std::path::Path;
use std::time::Instant;

use glam::Vec3;

use super::ReportError;
use super::plot::{Series, loglog_png};
use crate::io::write_atomically;
use crate::render::cpu::frame::Frame;
use crate::render::cpu::stills::{
    render_clouds_linear, render_converged, render_linear, render_linear_offsets,
};
use crate::render::cpu::tone_map::{to_srgb8_exact, tone_map};
use crate::render::sampling::JITTER_CYCLE;

/// Step counts measured.
pub const STEPS: [u32; 9] = [8, 16, 24, 32, 48, 64, 96, 128, 256];
/// Steps of the reference image (shadow steps 32, same octaves).
pub const REFERENCE_STEPS: u32 = 2048;
/// Target: mean absolute error of the tone-mapped image (0..1 per
/// channel) of 0.0025, two thirds of one 8-bit level (1/255), so the
/// average pixel is indistinguishable from the reference once quantised.
pub const TARGET_MEAN_ERROR: f32 = 0.0025;

/// One measured step count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    pub steps: u32,
    pub wall_s: f64,
    pub mean_error: f32,
    pub max_error: f32,
}

/// The measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    pub width: u32,
    pub height: u32,
    pub reference_wall_s: f64,
    pub rows: Vec<Row>,
    /// Index of the cheapest row meeting [`TARGET_MEAN_ERROR`].
    pub chosen: Option<usize>,
}

/// Renders `frame` at every count in `steps` and at the reference.
pub fn measure(
    frame: &Frame,
    width: u32,
    height: u32,
    steps: &[u32],
    mut progress: impl FnMut(),
) -> Report {
    let exposure = frame.quality.exposure;
    let mut reference_frame = *frame;
    reference_frame.quality.steps = REFERENCE_STEPS;
    reference_frame.quality.shadow_steps = frame.quality.shadow_steps.max(48);
    let start = Instant::now();
    let reference: Vec<Vec3> = render_linear(width, height, &reference_frame)
        .into_iter()
        .map(|c| tone_map(c, exposure))
        .collect();
    let reference_wall_s = start.elapsed().as_secs_f64();
    progress();
    let mut rows = Vec::new();
    for &s in steps {
        let mut f = *frame;
        f.quality.steps = s;
        let start = Instant::now();
        let img = render_linear(width, height, &f);
        let wall_s = start.elapsed().as_secs_f64();
        let (mut sum, mut max) = (0.0_f64, 0.0_f32);
        for (a, b) in img.iter().zip(&reference) {
            let e = (tone_map(*a, exposure) - *b).abs();
            sum += ((e.x + e.y + e.z) / 3.0) as f64;
            max = max.max(e.max_element());
        }
        rows.push(Row {
            steps: s,
            wall_s,
            mean_error: (sum / img.len().max(1) as f64) as f32,
            max_error: max,
        });
        progress();
    }
    let chosen = rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.mean_error <= TARGET_MEAN_ERROR)
        .min_by(|a, b| a.1.wall_s.total_cmp(&b.1.wall_s))
        .map(|(i, _)| i);
    Report {
        width,
        height,
        reference_wall_s,
        rows,
        chosen,
    }
}

/// Steps of the high-pass reference.
pub const HIGHPASS_REFERENCE_STEPS: u32 = 512;

/// Opacity above which a pixel counts as cloud for the high-pass energy.
pub const CLOUD_OPACITY: f32 = 0.05;

/// The high-pass energy of cloud pixels: how much fine-scale variation
/// (grain, checker, moire, speckle, and the clouds' real detail) an
/// image has, against a clean reference of the same view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HighPass {
    pub width: u32,
    pub height: u32,
    /// Steps of the measured frames (the scene's).
    pub steps: u32,
    /// Cloud pixels measured.
    pub cloud_pixels: usize,
    /// Energy of the reference: [`HIGHPASS_REFERENCE_STEPS`] steps, the
    /// [`JITTER_CYCLE`] frames TSAA accumulates averaged.
    pub reference: f64,
    /// Energy of one frame (one march per pixel, its blue-noise dither).
    pub one_frame: f64,
    /// Energy of the [`JITTER_CYCLE`] frames TSAA accumulates, averaged
    /// (what a static camera converges to).
    pub converged: f64,
    /// [`pattern_correlation`] of one frame's error against the mean of
    /// its frames' dither offsets through the same pixel centres: how
    /// structured the dither's grain is.
    pub one_frame_pattern: f64,
}

impl HighPass {
    /// One frame's energy over the reference's.
    pub fn one_frame_ratio(&self) -> f64 {
        self.one_frame / self.reference.max(1e-12)
    }
    /// The converged frames' energy over the reference's: near 1, no
    /// pattern noise is left; above, grain or patterns remain.
    pub fn converged_ratio(&self) -> f64 {
        self.converged / self.reference.max(1e-12)
    }
}

/// Luminance (Rec. 709 weights, `0..1`) of one sRGB8 pixel's values.
fn luminance8(c: &[u8]) -> f64 {
    (0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64) / 255.0
}

/// Mean over the `mask`ed pixels of the squared difference between the
/// luminance of an sRGB8 image (`0..1`, the picture as displayed) and its
/// 3x3 box mean (edges clamped).
pub fn highpass_energy(rgb8: &[u8], mask: &[bool], width: u32, height: u32) -> f64 {
    let (w, h) = (width as i64, height as i64);
    let lum: Vec<f64> = rgb8.chunks_exact(3).map(luminance8).collect();
    let at = |x: i64, y: i64| lum[(y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) as usize];
    let (mut sum, mut n) = (0.0, 0_usize);
    for y in 0..h {
        for x in 0..w {
            if !mask[(y * w + x) as usize] {
                continue;
            }
            let mut m = 0.0;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    m += at(x + dx, y + dy) / 9.0;
                }
            }
            sum += (at(x, y) - m).powi(2);
            n += 1;
        }
    }
    sum / n.max(1) as f64
}

/// The largest correlation (normalised, positive) of the residual
/// `image - reference` (luminance of sRGB8 images) with itself at any lag
/// of 2 to 8 pixels in each direction, over pairs of `mask`ed pixels: how
/// structured the error is. A dither's grain that is fine noise
/// correlates with nothing beyond its neighbours (near 0); a fixed
/// pattern (a checker, the diagonal bands of a gradient noise, banding)
/// repeats at some lag, where its error correlates positively (high).
/// Negative correlations are left out: blue noise is anti-correlated
/// with itself a few pixels away by design (its tile down to -0.09 at
/// these lags), and an error made of nothing but its grain shows that
/// ring (measured at -0.16, a lag of (5, 4), on a view whose grazing
/// rays take enough steps that the grain is all the error left).
pub fn pattern_correlation(
    image: &[u8],
    reference: &[u8],
    mask: &[bool],
    width: u32,
    height: u32,
) -> f64 {
    let r: Vec<f64> = image
        .chunks_exact(3)
        .zip(reference.chunks_exact(3))
        .map(|(a, b)| luminance8(a) - luminance8(b))
        .collect();
    let (w, h) = (width as i64, height as i64);
    let mut best: f64 = 0.0;
    for dy in -8_i64..=8 {
        for dx in -8_i64..=8 {
            if dx.abs().max(dy.abs()) < 2 || (dy < 0) || (dy == 0 && dx < 0) {
                continue;
            }
            let (mut sab, mut saa, mut sbb, mut sa, mut sb, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            for y in 0..h {
                for x in 0..w {
                    let (x2, y2) = (x + dx, y + dy);
                    if x2 < 0 || x2 >= w || y2 >= h {
                        continue;
                    }
                    let (i, j) = ((y * w + x) as usize, (y2 * w + x2) as usize);
                    if !(mask[i] && mask[j]) {
                        continue;
                    }
                    let (a, b) = (r[i], r[j]);
                    sab += a * b;
                    saa += a * a;
                    sbb += b * b;
                    sa += a;
                    sb += b;
                    n += 1.0;
                }
            }
            if n < 100.0 {
                continue;
            }
            let cov = sab / n - sa / n * (sb / n);
            let var = ((saa / n - (sa / n).powi(2)) * (sbb / n - (sb / n).powi(2))).sqrt();
            if var > 0.0 {
                best = best.max(cov / var);
            }
        }
    }
    best
}

/// The cloud pixels of `frame` at `width x height`: opacity above
/// [`CLOUD_OPACITY`] in a [`HIGHPASS_REFERENCE_STEPS`]-step march.
pub fn cloud_mask(frame: &Frame, width: u32, height: u32) -> Vec<bool> {
    let mut f = *frame;
    f.quality.steps = HIGHPASS_REFERENCE_STEPS;
    render_clouds_linear(width, height, &f, 1)
        .iter()
        .map(|c| c.w > CLOUD_OPACITY)
        .collect()
}

/// The high-pass reference of `frame`: [`HIGHPASS_REFERENCE_STEPS`]
/// steps, the [`JITTER_CYCLE`] frames TSAA accumulates averaged, as sRGB8.
pub fn highpass_reference(frame: &Frame, width: u32, height: u32) -> Vec<u8> {
    let mut f = *frame;
    f.quality.steps = HIGHPASS_REFERENCE_STEPS;
    to_srgb8_exact(
        &render_converged(width, height, &f, JITTER_CYCLE),
        f.quality.exposure,
    )
}

/// Measures [`HighPass`] for `frame` at `width x height`.
pub fn measure_highpass(frame: &Frame, width: u32, height: u32) -> HighPass {
    let exposure = frame.quality.exposure;
    let mask = cloud_mask(frame, width, height);
    let energy = |img: &[u8]| highpass_energy(img, &mask, width, height);
    let reference = energy(&highpass_reference(frame, width, height));
    let one = to_srgb8_exact(&render_linear(width, height, frame), exposure);
    let many = to_srgb8_exact(
        &render_converged(width, height, frame, JITTER_CYCLE),
        exposure,
    );
    let (one_frame, converged) = (energy(&one), energy(&many));
    // The dither's own error: one frame against the mean of its frames'
    // offsets through the same pixel centres.
    let centres = to_srgb8_exact(
        &render_linear_offsets(width, height, frame, JITTER_CYCLE),
        exposure,
    );
    let one_frame_pattern = pattern_correlation(&one, &centres, &mask, width, height);
    HighPass {
        width,
        height,
        steps: frame.quality.steps,
        cloud_pixels: mask.iter().filter(|&&m| m).count(),
        reference,
        one_frame,
        converged,
        one_frame_pattern,
    }
}

/// Writes `highpass.csv` into `dir`.
pub fn write_highpass(hp: &HighPass, dir: &Path) -> Result<(), ReportError> {
    let path = dir.join("highpass.csv");
    write_atomically(&path, |out| {
        writeln!(
            out,
            "image,steps,frames,width,height,cloud_pixels,highpass_energy,ratio_to_reference"
        )?;
        let mut row = |name: &str, steps: u32, frames: u32, e: f64| {
            writeln!(
                out,
                "{name},{steps},{frames},{},{},{},{e:.9},{:.4}",
                hp.width,
                hp.height,
                hp.cloud_pixels,
                e / hp.reference.max(1e-12)
            )
        };
        row(
            "reference",
            HIGHPASS_REFERENCE_STEPS,
            JITTER_CYCLE,
            hp.reference,
        )?;
        row("one_frame", hp.steps, 1, hp.one_frame)?;
        row("converged", hp.steps, JITTER_CYCLE, hp.converged)?;
        Ok(())
    })
    .map_err(|source| ReportError::Write {
        path: path.clone(),
        source,
    })
}

/// Writes `render_quality.csv` and `render_quality.png` into `dir`.
pub fn write(report: &Report, dir: &Path) -> Result<(), ReportError> {
    let path = dir.join("render_quality.csv");
    write_atomically(&path, |out| {
        writeln!(out, "steps,wall_s,mean_abs_error,max_abs_error")?;
        for r in &report.rows {
            writeln!(
                out,
                "{},{:.6},{:.6},{:.6}",
                r.steps, r.wall_s, r.mean_error, r.max_error
            )?;
        }
        Ok(())
    })
    .map_err(|source| ReportError::Write {
        path: path.clone(),
        source,
    })?;
    let pts = |f: fn(&Row) -> f32| {
        report
            .rows
            .iter()
            .map(|r| (r.wall_s.max(1e-6), (f(r) as f64).max(1e-6)))
            .collect()
    };
    let marked = report
        .chosen
        .map(|i| {
            let r = &report.rows[i];
            vec![(
                r.wall_s.max(1e-6),
                (r.mean_error as f64).max(1e-6),
                format!("least cost meeting the target: {} steps", r.steps),
            )]
        })
        .unwrap_or_default();
    loglog_png(
        &dir.join("render_quality.png"),
        &format!(
            "CPU render error against time ({}x{}, reference {} steps)",
            report.width, report.height, REFERENCE_STEPS
        ),
        "wall time of the frame, s",
        "abs error of the tone-mapped image (0..1)",
        &[
            Series {
                joined: true,
                name: "mean".into(),
                points: pts(|r| r.mean_error),
            },
            Series {
                joined: true,
                name: "max".into(),
                points: pts(|r| r.max_error),
            },
        ],
        &marked,
    )
}
