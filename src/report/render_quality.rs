//! Error against cost for the CPU renderer: the same frame at primary step
//! counts from low to a high-step reference.

use std::path::Path;
use std::time::Instant;

use glam::Vec3;

use super::ReportError;
use super::plot::{Series, loglog_png};
use crate::io::write_atomically;
use crate::render::cpu::renderer::{Frame, render_linear, tone_map};

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

fn tone(c: Vec3, exposure: f32) -> Vec3 {
    Vec3::new(
        tone_map(c.x, exposure),
        tone_map(c.y, exposure),
        tone_map(c.z, exposure),
    )
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
    reference_frame.quality.shadow_steps = frame.quality.shadow_steps.max(32);
    let start = Instant::now();
    let reference: Vec<Vec3> = render_linear(width, height, &reference_frame)
        .into_iter()
        .map(|c| tone(c, exposure))
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
            let e = (tone(*a, exposure) - *b).abs();
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
