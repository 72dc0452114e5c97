//! Rendering error against GPU time: each quality knob swept against a
//! supersampled, many-step CPU reference.

use super::{BenchError, BenchOptions, Knob, QualityRow};
use crate::prepare::Prepared;
use crate::render::cpu::stills::supersampled_srgb8;
use crate::render::gpu::{GpuContext, GpuError};
use crate::scene::{RenderSettings, Scene};

/// Mean absolute difference of two 8-bit images, 0..1.
pub fn mean_abs_diff(a: &[u8], b: &[u8]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| x.abs_diff(*y) as f64)
        .sum::<f64>()
        / (255.0 * a.len().max(1) as f64)
}

/// A CPU reference image: `steps` steps, 2x2 samples per pixel (box
/// filter, what TSAA converges to), tone-mapped to sRGB8.
fn reference(p: &Prepared, r: &RenderSettings, steps: u32) -> Vec<u8> {
    let mut q = r.quality();
    q.steps = steps;
    supersampled_srgb8(r.width, r.height, 2, &p.frame(r, q))
}

pub(super) fn quality_sweep(
    ctx: &GpuContext,
    sc: &Scene,
    p: &Prepared,
    o: &BenchOptions,
) -> Result<(Vec<QualityRow>, [u32; 2]), BenchError> {
    let (w, h) = if o.quick { (32, 24) } else { (160, 120) };
    let d = RenderSettings {
        width: w,
        height: h,
        tsaa: false,
        ..sc.render.clone()
    };
    let ref_steps = if o.quick { 128 } else { 512 };
    let mut out = Vec::new();
    let gpu_image = |r: &RenderSettings, frames: u32| -> Result<(Vec<u8>, f64), GpuError> {
        let mut hl = p.headless(ctx, &p.gpu_settings(r, r.quality()), w, h)?;
        hl.render(ctx, &r.camera(), frames)?;
        let img = hl.read_rgb8(ctx)?;
        let t = hl.time_frames(ctx, &r.camera(), 1, o.frames.min(5))?;
        Ok((img, t.median()))
    };
    // Steps, shadow steps and octaves: each against a reference with that
    // knob high and the rest at the defaults.
    let knobs: [Knob; 3] = [
        (
            "steps",
            vec![8, 16, 32, 48, 64, 128],
            d.steps,
            ref_steps,
            |r, v| r.steps = v,
        ),
        (
            "shadow_steps",
            vec![0, 4, 8, 12, 16, 20],
            d.shadow_steps,
            48,
            |r, v| r.shadow_steps = v,
        ),
        ("octaves", vec![0, 1, 2, 3], d.octaves, 3, |r, v| {
            r.octaves = v
        }),
    ];
    for (knob, values, default, ref_value, set) in knobs {
        let mut rr = d.clone();
        set(&mut rr, ref_value);
        let reference = reference(
            p,
            &rr,
            if knob == "steps" {
                ref_steps
            } else {
                rr.steps.max(256)
            },
        );
        for v in values {
            let mut r = d.clone();
            set(&mut r, v);
            let (img, ms) = gpu_image(&r, 1)?;
            out.push(QualityRow {
                knob,
                value: v,
                ms,
                mean_error: mean_abs_diff(&img, &reference),
                is_default: v == default,
            });
        }
    }
    // TSAA: frames accumulated at the default steps, against the
    // high-step reference; the cost is the frames' total time.
    let reference = reference(p, &d, ref_steps);
    let t = RenderSettings {
        tsaa: true,
        ..d.clone()
    };
    for frames in [1, 2, 4, 8, 16, 32] {
        let (img, ms) = gpu_image(&t, frames)?;
        out.push(QualityRow {
            knob: "tsaa_frames",
            value: frames,
            ms: ms * frames as f64,
            mean_error: mean_abs_diff(&img, &reference),
            is_default: frames == 32,
        });
    }
    Ok((out, [w, h]))
}
