//! `cumulus stats`: the statistics of the cloud field seen from above
//! (cloud fraction and its profile, the area-perimeter dimension D, the
//! size density and its exponent), from the renderer's density.

use std::path::PathBuf;

use anyhow::{Result, bail};

use cumulus::prepare::Prepared;
use cumulus::report::field_stats::{self, column_field};

use crate::{load_scene, progress_bar, with_overrides};

#[derive(clap::Args)]
#[command(after_help = "Example:\n  cumulus stats --scene scenes/bomex.toml --out stats/")]
pub struct StatsArgs {
    /// Scene TOML file, or the name of a built-in shipped scene
    /// (fair_weather, evening, strong_inversion, ...: `--scene fair_weather`).
    #[arg(long)]
    scene: PathBuf,
    /// Output directory (clouds.csv, size_density.csv,
    /// cloud_fraction_profile.csv, stats.json, repetition.json,
    /// area_perimeter.png, size_density.png, optical_depth.png, and
    /// repetition.png: five periods of the domain from above); created
    /// if missing.
    #[arg(long)]
    out: PathBuf,
    /// Columns along each side of the domain (16..=2048).
    #[arg(long, default_value_t = 512)]
    resolution: usize,
    /// Density samples down each column through the cloud band (1..=512).
    #[arg(long, default_value_t = 48)]
    levels: usize,
    /// A column is cloudy when its optical depth reaches this (> 0).
    #[arg(long, default_value_t = 1.0)]
    tau_min: f64,
    /// Clouds of fewer columns are counted in the cloud fraction but not
    /// in the fits (their outlines are pixels).
    #[arg(long, default_value_t = 4)]
    min_cells: usize,
    /// Simulated seconds before the field is taken (overrides render.time_s).
    #[arg(long)]
    time_s: Option<f64>,
}

pub fn run(a: StatsArgs) -> Result<()> {
    if !(16..=2048).contains(&a.resolution) {
        bail!("--resolution is {}, expected 16..=2048", a.resolution);
    }
    if !(1..=512).contains(&a.levels) {
        bail!("--levels is {}, expected 1..=512", a.levels);
    }
    if !(a.tau_min.is_finite() && a.tau_min > 0.0) {
        bail!(
            "--tau-min is {}, expected a positive optical depth",
            a.tau_min
        );
    }
    let flags = [("--time-s", "render.time_s")];
    let scene = with_overrides(load_scene(&a.scene)?, &flags, |s| {
        if let Some(t) = a.time_s {
            s.render.time_s = t;
        }
    })?;
    crate::create_output_folder(&a.out)?;
    let bar = progress_bar(Prepared::frames(&scene), "simulating");
    let prepared = Prepared::from_scene(&scene, || bar.inc(1))?;
    bar.finish_and_clear();
    let r = &scene.render;
    let frame = prepared.density_frame(r, r.quality());
    let field = column_field(&frame, a.resolution, a.levels);
    let s = field_stats::field_stats(&field, a.tau_min, a.min_cells);
    let name = if scene.name.is_empty() {
        a.scene.display().to_string()
    } else {
        scene.name.clone()
    };
    field_stats::write(&s, &name, &a.out)?;
    field_stats::write_optical_depth(&field, a.tau_min, &a.out)?;
    println!(
        "{}x{} columns of {:.1} m, cloudy at optical depth >= {}",
        s.width, s.height, s.cell_m, s.tau_min
    );
    println!("cloud_fraction={:.4}", s.cloud_fraction);
    let fitted = s.clouds.iter().filter(|c| c.cells >= s.min_cells).count();
    println!(
        "clouds={} ({fitted} of at least {} columns in the fits)",
        s.clouds.len(),
        s.min_cells
    );
    match (s.dimension, s.area_perimeter) {
        (Some(d), Some(f)) => println!("area_perimeter_dimension={d:.3} (r²={:.3})", f.r2),
        _ => println!("area_perimeter_dimension=none (fewer than two clouds)"),
    }
    match s.size_fit {
        Some(f) => println!(
            "size_density_exponent={:.3} over {:.2} decades of diameter (r²={:.3})",
            f.slope, s.size_decades, f.r2
        ),
        None => println!("size_density_exponent=none (fewer than two size bins)"),
    }
    let off = s.departures_from_nature();
    if off.is_empty() {
        println!("natural=yes (D, size exponent and its span in real cumulus fields' range)");
    } else {
        println!("natural=no: {}", off.join("; "));
    }
    // Repetition: five periods of the map seen from above, centred on the
    // simulated domain (a high flight's view over 50 km), 128 columns a
    // period (78 m over the shipped 10 km domains), 24 levels.
    let (l, periods) = (field.cell_m * field.width as f64, 5);
    let wide =
        field_stats::column_field_over(&frame, -2.0 * l, periods as f64 * l, 128 * periods, 24);
    let rep = field_stats::repetition(&wide.mask(a.tau_min), 128);
    println!(
        "repetition: correlation {:.3} at the map's period, at most {:.3} at other lags of its length ({})",
        rep.period_max(),
        rep.other_max(),
        if rep.hidden() {
            "not visible"
        } else {
            "visible"
        }
    );
    field_stats::write_repetition(&rep, &a.out)?;
    field_stats::write_optical_depth_as(&wide, a.tau_min, &a.out.join("repetition.png"))?;
    println!("wrote {}", a.out.display());
    Ok(())
}
