//! `render --quality-report` and `--stills-report`: the CPU renderer's
//! error against cost, measured on the scene's frame, written and printed.

use std::path::Path;

use anyhow::Result;

use cumulus::render::cpu::frame::Frame;
use cumulus::scene::RenderSettings;

use crate::progress_bar;

/// `--stills-report DIR`: the error against cost of the CPU stills'
/// samplings (stills.csv), written to `dir` and printed.
pub(super) fn stills_report(frame: &Frame, r: &RenderSettings, dir: &Path) -> Result<()> {
    use cumulus::report::still_quality;
    crate::create_output_folder(dir)?;
    let (w, h) = (r.width.min(320), r.height.min(240));
    let bar = progress_bar(still_quality::STILLS.len() as u64 + 1, "stills");
    let stills = still_quality::measure_stills(frame, w, h, || bar.inc(1));
    bar.finish_and_clear();
    still_quality::write_stills(&stills, w, h, dir)?;
    println!(
        "stills at {w}x{h} against {} marches a pixel:\n{:>9} {:>7} {:>8} {:>10} {:>9} {:>6}",
        still_quality::CONVERGED_OFFSETS,
        "sampling",
        "offsets",
        "marches",
        "mean_lvls",
        "p99_lvls",
        "grain"
    );
    for s in &stills {
        println!(
            "{:>9} {:>7} {:>8.2} {:>10.3} {:>9.1} {:>6.2}",
            still_quality::sampling_name(s.sampling),
            s.offsets,
            s.marches_per_pixel,
            s.mean_levels,
            s.p99_levels,
            s.grain
        );
    }
    println!("wrote {}/stills.csv", dir.display());
    Ok(())
}

/// `--quality-report DIR`: the error against cost of the step counts
/// (render_quality.csv and .png) and the dither's high-pass energy,
/// written to `dir` and printed.
pub(super) fn quality_report(frame: &Frame, r: &RenderSettings, dir: &Path) -> Result<()> {
    use cumulus::report::render_quality;
    crate::create_output_folder(dir)?;
    let (w, h) = (r.width.min(320), r.height.min(240));
    let bar = progress_bar(render_quality::STEPS.len() as u64 + 2, "rendering");
    let report = render_quality::measure(frame, w, h, &render_quality::STEPS, || bar.inc(1));
    let (hw, hh) = (w.min(160), h.min(120));
    let hp = render_quality::measure_highpass(frame, hw, hh);
    bar.finish_and_clear();
    render_quality::write(&report, dir)?;
    render_quality::write_highpass(&hp, dir)?;
    println!(
        "reference ({} steps) took {:.2} s at {w}x{h}",
        render_quality::REFERENCE_STEPS,
        report.reference_wall_s
    );
    println!(
        "{:>6} {:>9} {:>11} {:>10}",
        "steps", "wall_s", "mean_error", "max_error"
    );
    for row in &report.rows {
        println!(
            "{:>6} {:>9.4} {:>11.5} {:>10.4}",
            row.steps, row.wall_s, row.mean_error, row.max_error
        );
    }
    match report.chosen {
        Some(i) => println!(
            "least-cost step count with mean error <= {}: {}",
            render_quality::TARGET_MEAN_ERROR,
            report.rows[i].steps
        ),
        None => println!(
            "no step count reached mean error <= {}",
            render_quality::TARGET_MEAN_ERROR
        ),
    }
    println!(
        "high-pass energy of {} cloud pixels at {hw}x{hh}, against {} steps x {} frames: \
         one frame {:.2}x, {} frames averaged (TSAA) {:.2}x",
        hp.cloud_pixels,
        render_quality::HIGHPASS_REFERENCE_STEPS,
        cumulus::render::sampling::JITTER_CYCLE,
        hp.one_frame_ratio(),
        cumulus::render::sampling::JITTER_CYCLE,
        hp.converged_ratio()
    );
    println!(
        "wrote {0}/render_quality.csv, {0}/render_quality.png and {0}/highpass.csv",
        dir.display()
    );
    Ok(())
}
