//! The statistics' files: CSV, JSON and the two log-log plots.

use std::path::Path;

use super::{Cloud, ColumnField, FieldStats, Fit, Repetition};
use crate::io::{write_atomically, write_png_atomically};
use crate::report::ReportError;
use crate::report::plot::{Series, loglog_png};

/// Clouds per m per m² in clouds per km per km².
const PER_KM_PER_KM2: f64 = 1e9;

/// Writes `repetition.json` ([`Repetition`]).
pub fn write_repetition(r: &Repetition, dir: &Path) -> Result<(), ReportError> {
    let path = dir.join("repetition.json");
    write_atomically(&path, |out| {
        serde_json::to_writer_pretty(&mut *out, r).map_err(std::io::Error::other)?;
        writeln!(out)
    })
    .map_err(ReportError::writing(&path))
}

/// Writes `optical_depth.png`: the field seen from straight above, one
/// pixel per column, grey `1 - e^{-τ}` (black: clear sky; white: opaque),
/// the clouds the statistics count outlined where `τ` crosses `tau_min`
/// (red).
pub fn write_optical_depth(f: &ColumnField, tau_min: f64, dir: &Path) -> Result<(), ReportError> {
    write_optical_depth_as(f, tau_min, &dir.join("optical_depth.png"))
}

/// [`write_optical_depth`] into `path`.
pub fn write_optical_depth_as(
    f: &ColumnField,
    tau_min: f64,
    path: &Path,
) -> Result<(), ReportError> {
    let (w, h) = (f.width, f.height);
    let cloudy = |x: usize, y: usize| f.tau[(y % h) * w + (x % w)] >= tau_min;
    let img = image::RgbImage::from_fn(w as u32, h as u32, |x, y| {
        let (x, y) = (x as usize, y as usize);
        let edge = cloudy(x, y)
            && !(cloudy(x + 1, y)
                && cloudy(x + w - 1, y)
                && cloudy(x, y + 1)
                && cloudy(x, y + h - 1));
        if edge {
            return image::Rgb([220, 40, 30]);
        }
        let g = (255.0 * (1.0 - (-f.tau[y * w + x]).exp())).round() as u8;
        image::Rgb([g, g, g])
    });
    write_png_atomically(path, &img).map_err(ReportError::writing(path))
}

/// Writes `clouds.csv` (one row per cloud), `size_density.csv`,
/// `cloud_fraction_profile.csv`, `stats.json` and the two log-log plots
/// (`area_perimeter.png`, `size_density.png`) into `dir`.
pub fn write(s: &FieldStats, title: &str, dir: &Path) -> Result<(), ReportError> {
    let path = dir.join("clouds.csv");
    write_atomically(&path, |out| {
        writeln!(out, "cells,area_m2,perimeter_m,diameter_m")?;
        for c in &s.clouds {
            writeln!(
                out,
                "{},{:.1},{:.1},{:.2}",
                c.cells, c.area_m2, c.perimeter_m, c.diameter_m
            )?;
        }
        Ok(())
    })
    .map_err(ReportError::writing(&path))?;
    let path = dir.join("size_density.csv");
    write_atomically(&path, |out| {
        writeln!(out, "diameter_m,lo_m,hi_m,count,density_per_m3")?;
        for b in &s.sizes {
            writeln!(
                out,
                "{:.2},{:.2},{:.2},{},{:.6e}",
                b.diameter_m, b.lo_m, b.hi_m, b.count, b.density
            )?;
        }
        Ok(())
    })
    .map_err(ReportError::writing(&path))?;
    let path = dir.join("cloud_fraction_profile.csv");
    write_atomically(&path, |out| {
        writeln!(out, "height_m,cloud_fraction")?;
        for (z, f) in &s.profile {
            writeln!(out, "{z:.1},{f:.5}")?;
        }
        Ok(())
    })
    .map_err(ReportError::writing(&path))?;
    let path = dir.join("stats.json");
    write_atomically(&path, |out| {
        serde_json::to_writer_pretty(&mut *out, s).map_err(std::io::Error::other)?;
        writeln!(out)
    })
    .map_err(ReportError::writing(&path))?;
    let fitted = |f: Option<Fit>, xs: Vec<f64>| -> Vec<(f64, f64)> {
        f.map(|f| {
            xs.iter()
                .map(|&x| (x, (f.intercept + f.slope * x.ln()).exp()))
                .collect()
        })
        .unwrap_or_default()
    };
    let big: Vec<&Cloud> = s.clouds.iter().filter(|c| c.cells >= s.min_cells).collect();
    let areas: Vec<f64> = big.iter().map(|c| c.area_m2).collect();
    let span = |v: &[f64]| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(0.0, f64::max);
        if lo.is_finite() { vec![lo, hi] } else { vec![] }
    };
    loglog_png(
        &dir.join("area_perimeter.png"),
        &format!(
            "Area against perimeter, {title}: D = {}",
            s.dimension.map_or("n/a".into(), |d| format!("{d:.2}"))
        ),
        "area, m²",
        "perimeter, m",
        &[
            Series {
                joined: false,
                name: "clouds".into(),
                points: big.iter().map(|c| (c.area_m2, c.perimeter_m)).collect(),
            },
            Series {
                joined: true,
                name: "fit".into(),
                points: fitted(s.area_perimeter, span(&areas)),
            },
        ],
        &[],
    )?;
    let diameters: Vec<f64> = s.sizes.iter().map(|b| b.diameter_m).collect();
    loglog_png(
        &dir.join("size_density.png"),
        &format!(
            "Cloud size density, {title}: exponent {}",
            s.size_fit
                .map_or("n/a".into(), |f| format!("{:.2}", f.slope))
        ),
        "diameter, m",
        "clouds per km of diameter per km²",
        &[
            Series {
                joined: true,
                name: "clouds".into(),
                points: s
                    .sizes
                    .iter()
                    .map(|b| (b.diameter_m, b.density * PER_KM_PER_KM2))
                    .collect(),
            },
            Series {
                joined: true,
                name: "fit".into(),
                points: fitted(s.size_fit, span(&diameters))
                    .into_iter()
                    .map(|(d, n)| (d, n * PER_KM_PER_KM2))
                    .collect(),
            },
        ],
        &[],
    )
}
