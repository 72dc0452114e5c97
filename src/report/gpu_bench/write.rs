//! The benchmark's files: CSV, JSON and the plots.

use std::path::Path;

use super::{FEATURES, Report, Row};
use crate::io::write_atomically;
use crate::report::ReportError;
use crate::report::plot::{Series, bars_png, loglog_png};

/// Writes `bench.csv`, `physics_in_frame.csv`, `methods.csv`, `endless_threshold.csv`, `render_error.csv`,
/// `bench.json` and the plots into `dir`.
pub fn write(report: &Report, dir: &Path) -> Result<(), ReportError> {
    let path = dir.join("bench.csv");
    write_atomically(&path, |out| {
        writeln!(out, "group,renderer,width,height,coverage,parcels,tsaa,terrain,shadow_steps,octaves,detail,sky,aerial,frames,p_covered,median_ms,p95_ms,timing,reads_mean,reads_max")?;
        for r in &report.rows {
            writeln!(
                out,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.4},{:.4},{:.4},{},{:.1},{:.0}",
                r.group, r.renderer, r.width, r.height, r.coverage, r.parcels, r.tsaa, r.terrain, r.shadow_steps, r.octaves, r.detail, r.sky, r.aerial, r.frames, r.p_covered, r.median_ms, r.p95_ms, r.timing, r.reads_mean, r.reads_max
            )?;
        }
        Ok(())
    })
    .map_err(ReportError::writing(&path))?;
    let path = dir.join("physics_in_frame.csv");
    write_atomically(&path, |out| {
        writeln!(
            out,
            "parcels,physics_ms,projection_ms,upload_ms,frame_ms,share_pct"
        )?;
        for r in &report.physics {
            writeln!(
                out,
                "{},{:.4},{:.4},{:.4},{:.4},{:.3}",
                r.parcels, r.physics_ms, r.projection_ms, r.upload_ms, r.frame_ms, r.share_pct
            )?;
        }
        Ok(())
    })
    .map_err(ReportError::writing(&path))?;
    let path = dir.join("methods.csv");
    write_atomically(&path, |out| {
        writeln!(out, "method,renderer,width,height,p_covered,median_ms,p95_ms,timing,step_ms,step_s,light_grid_ms,state_bytes")?;
        for r in &report.methods {
            writeln!(
                out,
                "{},{},{},{},{:.4},{:.4},{:.4},{},{:.7},{},{:.3},{}",
                r.method, r.renderer, r.width, r.height, r.p_covered, r.median_ms, r.p95_ms, r.timing, r.step_ms, r.step_s, r.light_grid_ms, r.state_bytes
            )?;
        }
        Ok(())
    })
    .map_err(ReportError::writing(&path))?;
    let path = dir.join("endless_threshold.csv");
    write_atomically(&path, |out| {
        writeln!(
            out,
            "similarity,steps,jumps_per_100,mean_jump,max_jump,distinct,distinct_late"
        )?;
        for r in &report.endless {
            writeln!(
                out,
                "{},{},{:.2},{:.4},{:.4},{},{}",
                r.similarity,
                r.steps,
                r.jumps_per_100,
                r.mean_jump,
                r.max_jump,
                r.distinct,
                r.distinct_late
            )?;
        }
        Ok(())
    })
    .map_err(ReportError::writing(&path))?;
    let path = dir.join("render_error.csv");
    write_atomically(&path, |out| {
        writeln!(out, "knob,value,ms,mean_abs_error,is_default")?;
        for r in &report.quality {
            writeln!(
                out,
                "{},{},{:.4},{:.6},{}",
                r.knob, r.value, r.ms, r.mean_error, r.is_default
            )?;
        }
        Ok(())
    })
    .map_err(ReportError::writing(&path))?;
    let path = dir.join("bench.json");
    write_atomically(&path, |out| {
        serde_json::to_writer_pretty(&mut *out, report).map_err(std::io::Error::other)?;
        writeln!(out)
    })
    .map_err(ReportError::writing(&path))?;

    if report.rows.is_empty() {
        // A methods-only run: no sweeps to plot.
        return Ok(());
    }
    let device = format!("{} ({} timing)", report.adapter, report.timing);
    let series_of = |group: &str, renderer: &str, x: fn(&Row) -> f64| Series {
        joined: true,
        name: renderer.replace('_', "-"),
        points: report
            .rows
            .iter()
            .filter(|r| r.group == group && r.renderer == renderer && r.timing != "skipped")
            .map(|r| (x(r), r.median_ms))
            .collect(),
    };
    loglog_png(
        &dir.join("ms_vs_coverage.png"),
        &format!("Frame time against coverage, {device}"),
        "coverage",
        "frame, ms",
        &[series_of("coverage", "cloud_map", |r| r.coverage as f64)],
        &[],
    )?;
    loglog_png(
        &dir.join("ms_vs_parcels.png"),
        &format!("Frame time against parcels, {device}"),
        "parcels",
        "frame, ms",
        &[
            series_of("parcels", "cloud_map", |r| r.parcels as f64),
            series_of("parcels", "per_parcel", |r| r.parcels as f64),
        ],
        &[],
    )?;
    let bars: Vec<(String, f64)> = report
        .rows
        .iter()
        .filter(|r| r.group == "features")
        .enumerate()
        .map(|(k, r)| {
            (
                FEATURES.get(k).copied().unwrap_or("?").to_owned(),
                r.median_ms,
            )
        })
        .collect();
    bars_png(
        &dir.join("ms_per_feature.png"),
        &format!("Frame time per feature, {device}"),
        "frame, ms",
        &bars,
    )?;
    let knobs = ["steps", "shadow_steps", "octaves", "tsaa_frames"];
    let series: Vec<Series> = knobs
        .iter()
        .map(|k| Series {
            joined: true,
            name: k.to_string(),
            points: report
                .quality
                .iter()
                .filter(|q| q.knob == *k)
                .map(|q| (q.ms.max(1e-6), q.mean_error.max(1e-6)))
                .collect(),
        })
        .collect();
    // The defaults, one ring each; those within 10 % of an earlier one in
    // time and error (the same settings, measured in each knob's sweep)
    // share its ring and label, so that one setting's three labels are
    // not drawn over each other.
    let mut marked: Vec<(f64, f64, String)> = Vec::new();
    for q in report.quality.iter().filter(|q| q.is_default) {
        let (ms, error) = (q.ms.max(1e-6), q.mean_error.max(1e-6));
        let near = |a: f64, b: f64| (a / b - 1.0).abs() < 0.1;
        match marked
            .iter_mut()
            .find(|m| near(m.0, ms) && near(m.1, error))
        {
            Some(m) => m.2 = format!("{}, {} {}", m.2, q.knob, q.value),
            None => marked.push((ms, error, format!("{} {}", q.knob, q.value))),
        }
    }
    loglog_png(
        &dir.join("render_error.png"),
        &format!(
            "Render error against GPU time, {}x{}, {device}",
            report.quality_size[0], report.quality_size[1]
        ),
        "ms",
        "mean abs. error",
        &series,
        &marked,
    )
}
