//! Statistics of a cloud field seen from above, the numbers a researcher
//! compares with satellite and LES cloud fields: cloud fraction, the
//! cloud-fraction profile by height, the area-perimeter fractal dimension
//! D of the cloud outlines (Lovejoy 1982: `P ∝ A^{D/2}`, 1.35 for real
//! fields) and the number density of cloud sizes with its power-law
//! exponent.
//!
//! The field is the renderer's own density ([`density_at`]) integrated
//! down each column into an optical depth, on a grid over one period of
//! the (horizontally periodic) domain; a column is cloudy when its optical
//! depth reaches `tau_min`. Clouds are the 4-connected cloudy regions,
//! joined across the periodic edges; a cloud's perimeter is its number of
//! cell edges that face clear sky, times the cell size.

mod repetition;
mod write;

use rayon::prelude::*;
use serde::Serialize;

pub use repetition::{Lag, Repetition, correlation, repetition};
pub use write::{write, write_optical_depth, write_optical_depth_as, write_repetition};

use crate::render::cpu::density::density_at;
use crate::render::cpu::frame::Frame;

/// A cloud mask on a periodic `width x height` grid of square cells.
#[derive(Debug, Clone, PartialEq)]
pub struct Mask {
    pub width: usize,
    pub height: usize,
    /// Side of a cell, m.
    pub cell_m: f64,
    /// Row-major, `true` where cloudy.
    pub cells: Vec<bool>,
}

/// One cloud: a 4-connected cloudy region.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Cloud {
    pub cells: usize,
    pub area_m2: f64,
    pub perimeter_m: f64,
    /// Diameter of the disc of the same area, m.
    pub diameter_m: f64,
}

/// A least-squares line `y = slope x + intercept` through `n` points.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Fit {
    pub slope: f64,
    pub intercept: f64,
    pub n: usize,
    /// Coefficient of determination.
    pub r2: f64,
}

/// One bin of the size density.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SizeBin {
    /// Geometric centre of the bin, m.
    pub diameter_m: f64,
    pub lo_m: f64,
    pub hi_m: f64,
    pub count: usize,
    /// Clouds per unit diameter per unit domain area, 1/m³.
    pub density: f64,
}

/// The statistics of one field.
#[derive(Debug, Clone, Serialize)]
pub struct FieldStats {
    pub width: usize,
    pub height: usize,
    pub cell_m: f64,
    pub tau_min: f64,
    /// Fraction of columns whose optical depth reaches `tau_min`.
    pub cloud_fraction: f64,
    /// (height, fraction of columns with cloud at that height), m.
    pub profile: Vec<(f64, f64)>,
    pub clouds: Vec<Cloud>,
    /// Clouds of at least this many cells enter the fits.
    pub min_cells: usize,
    /// The area-perimeter fit in log-log: `D = 2 slope`.
    pub area_perimeter: Option<Fit>,
    pub dimension: Option<f64>,
    pub sizes: Vec<SizeBin>,
    /// The power-law fit of the size density in log-log (its slope is the
    /// exponent).
    pub size_fit: Option<Fit>,
    /// Decades of diameter the size fit spans.
    pub size_decades: f64,
}

/// Real cumulus fields' area-perimeter dimension (Lovejoy 1982 measured
/// 1.35 over five decades of cloud and rain areas).
pub const NATURAL_DIMENSION: std::ops::RangeInclusive<f64> = 1.30..=1.40;
/// Exponents of the cloud-size density of trade and fair-weather cumulus
/// in LES and satellite studies (e.g. Neggers et al. 2003, Zhao & Di
/// Girolamo 2007: about -1.7 to -2.7 below the scale break).
pub const NATURAL_SIZE_EXPONENT: std::ops::RangeInclusive<f64> = -3.0..=-1.5;
/// The fewest decades of diameter a size fit must span to say anything.
pub const NATURAL_MIN_DECADES: f64 = 1.0;

impl FieldStats {
    /// How the field differs from a real cumulus field seen from above,
    /// one line per difference (empty: it looks like one by these
    /// measures): the area-perimeter dimension in [`NATURAL_DIMENSION`],
    /// the size density's exponent in [`NATURAL_SIZE_EXPONENT`] over at
    /// least [`NATURAL_MIN_DECADES`] decades.
    pub fn departures_from_nature(&self) -> Vec<String> {
        let mut out = Vec::new();
        match self.dimension {
            Some(d) if NATURAL_DIMENSION.contains(&d) => {}
            Some(d) => out.push(format!(
                "area-perimeter dimension {d:.3} is outside {:.2}..={:.2}",
                NATURAL_DIMENSION.start(),
                NATURAL_DIMENSION.end()
            )),
            None => out.push("too few clouds for an area-perimeter dimension".into()),
        }
        match self.size_fit {
            Some(f) if NATURAL_SIZE_EXPONENT.contains(&f.slope) => {}
            Some(f) => out.push(format!(
                "size-density exponent {:.2} is outside {:.1}..={:.1}",
                f.slope,
                NATURAL_SIZE_EXPONENT.start(),
                NATURAL_SIZE_EXPONENT.end()
            )),
            None => out.push("too few clouds for a size-density fit".into()),
        }
        if self.size_decades < NATURAL_MIN_DECADES {
            out.push(format!(
                "the sizes span {:.1} decades, fewer than {NATURAL_MIN_DECADES}",
                self.size_decades
            ));
        }
        out
    }
}

/// A column field: optical depth per column and the cloudy fraction per
/// height level.
#[derive(Debug, Clone)]
pub struct ColumnField {
    pub width: usize,
    pub height: usize,
    pub cell_m: f64,
    /// Row-major optical depth (dimensionless).
    pub tau: Vec<f64>,
    /// (height, fraction of columns with cloud there), m.
    pub profile: Vec<(f64, f64)>,
}

/// Integrates `frame`'s density down `n x n` columns over one period of
/// the map (`levels` samples through the band per column, at their
/// centres).
pub fn column_field(frame: &Frame, n: usize, levels: usize) -> ColumnField {
    column_field_over(frame, 0.0, frame.density.map_extent_m as f64, n, levels)
}

/// [`column_field`] over a square of `span_m` whose lower corner is at
/// `(origin_m, origin_m)` (several periods of the map, for
/// [`repetition`]).
pub fn column_field_over(
    frame: &Frame,
    origin_m: f64,
    span_m: f64,
    n: usize,
    levels: usize,
) -> ColumnField {
    let d = &frame.density;
    let cell = span_m / n as f64;
    let levels = levels.max(1);
    let dz = (d.band_top_m - d.band_bottom_m) / levels as f32;
    // The textures are read at the level of detail of a column's width,
    // as a renderer looking down at this resolution reads them.
    let footprint_m = cell as f32;
    let rows: Vec<(Vec<f64>, Vec<u32>)> = (0..n)
        .into_par_iter()
        .map(|j| {
            let mut tau = vec![0.0; n];
            let mut cloudy = vec![0u32; levels];
            for (i, t) in tau.iter_mut().enumerate() {
                let (x, z) = (
                    (origin_m + (i as f64 + 0.5) * cell) as f32,
                    (origin_m + (j as f64 + 0.5) * cell) as f32,
                );
                for (k, c) in cloudy.iter_mut().enumerate() {
                    let y = d.band_bottom_m + (k as f32 + 0.5) * dz;
                    let sigma = density_at(
                        glam::Vec3::new(x, y, z),
                        &frame.fields,
                        d,
                        true,
                        footprint_m,
                    );
                    if sigma > 0.0 {
                        *t += (sigma * dz) as f64;
                        *c += 1;
                    }
                }
            }
            (tau, cloudy)
        })
        .collect();
    let mut tau = Vec::with_capacity(n * n);
    let mut counts = vec![0u64; levels];
    for (row, cloudy) in rows {
        tau.extend(row);
        for (c, k) in counts.iter_mut().zip(cloudy) {
            *c += k as u64;
        }
    }
    let profile = counts
        .iter()
        .enumerate()
        .map(|(k, &c)| {
            let y = d.band_bottom_m + (k as f32 + 0.5) * dz;
            (y as f64, c as f64 / (n * n) as f64)
        })
        .collect();
    ColumnField {
        width: n,
        height: n,
        cell_m: cell,
        tau,
        profile,
    }
}

impl ColumnField {
    /// The columns whose optical depth reaches `tau_min`.
    pub fn mask(&self, tau_min: f64) -> Mask {
        Mask {
            width: self.width,
            height: self.height,
            cell_m: self.cell_m,
            cells: self.tau.iter().map(|&t| t >= tau_min).collect(),
        }
    }
}

impl Mask {
    /// A `width x height` mask of cells of `cell_m`, cloudy where
    /// `cloudy(x, y)`.
    pub fn from_fn(
        width: usize,
        height: usize,
        cell_m: f64,
        cloudy: impl Fn(usize, usize) -> bool,
    ) -> Self {
        Self {
            width,
            height,
            cell_m,
            cells: (0..width * height)
                .map(|k| cloudy(k % width, k / width))
                .collect(),
        }
    }

    /// The clouds: 4-connected cloudy regions, joined across the periodic
    /// edges, with area and perimeter.
    pub fn clouds(&self) -> Vec<Cloud> {
        let (w, h) = (self.width, self.height);
        let mut parent: Vec<usize> = (0..w * h).collect();
        fn find(p: &mut [usize], mut i: usize) -> usize {
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        let at = |x: usize, y: usize| self.cells[y * w + x];
        for y in 0..h {
            for x in 0..w {
                if !at(x, y) {
                    continue;
                }
                for (nx, ny) in [((x + 1) % w, y), (x, (y + 1) % h)] {
                    if at(nx, ny) {
                        let (a, b) = (find(&mut parent, y * w + x), find(&mut parent, ny * w + nx));
                        if a != b {
                            parent[a.max(b)] = a.min(b);
                        }
                    }
                }
            }
        }
        let mut cells = vec![0usize; w * h];
        let mut edges = vec![0usize; w * h];
        for y in 0..h {
            for x in 0..w {
                if !at(x, y) {
                    continue;
                }
                let r = find(&mut parent, y * w + x);
                cells[r] += 1;
                let neighbours = [
                    ((x + 1) % w, y),
                    ((x + w - 1) % w, y),
                    (x, (y + 1) % h),
                    (x, (y + h - 1) % h),
                ];
                edges[r] += neighbours.iter().filter(|&&(a, b)| !at(a, b)).count();
            }
        }
        let c = self.cell_m;
        (0..w * h)
            .filter(|&i| cells[i] > 0)
            .map(|i| {
                let area = cells[i] as f64 * c * c;
                Cloud {
                    cells: cells[i],
                    area_m2: area,
                    perimeter_m: edges[i] as f64 * c,
                    diameter_m: (4.0 * area / std::f64::consts::PI).sqrt(),
                }
            })
            .collect()
    }

    /// The cloudy fraction of the cells.
    pub fn fraction(&self) -> f64 {
        self.cells.iter().filter(|&&c| c).count() as f64 / self.cells.len().max(1) as f64
    }
}

/// Least squares through `(x, y)` points; `None` with fewer than two
/// distinct x.
pub fn fit_line(points: &[(f64, f64)]) -> Option<Fit> {
    let n = points.len();
    if n < 2 {
        return None;
    }
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n as f64;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n as f64;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let syy: f64 = points.iter().map(|p| (p.1 - my).powi(2)).sum();
    if sxx <= 1e-12 {
        return None;
    }
    let slope = sxy / sxx;
    let r2 = if syy > 0.0 {
        sxy * sxy / (sxx * syy)
    } else {
        1.0
    };
    Some(Fit {
        slope,
        intercept: my - slope * mx,
        n,
        r2,
    })
}

/// The area-perimeter fit over clouds of at least `min_cells` cells:
/// `ln P = (D/2) ln A + c`.
pub fn area_perimeter_fit(clouds: &[Cloud], min_cells: usize) -> Option<Fit> {
    let pts: Vec<(f64, f64)> = clouds
        .iter()
        .filter(|c| c.cells >= min_cells)
        .map(|c| (c.area_m2.ln(), c.perimeter_m.ln()))
        .collect();
    fit_line(&pts)
}

/// The number density of cloud diameters in logarithmic bins
/// (`bins_per_decade`), per unit diameter and unit domain area, over clouds
/// of at least `min_cells` cells. Empty bins are left out.
pub fn size_density(
    clouds: &[Cloud],
    min_cells: usize,
    domain_area_m2: f64,
    bins_per_decade: usize,
) -> Vec<SizeBin> {
    let d: Vec<f64> = clouds
        .iter()
        .filter(|c| c.cells >= min_cells)
        .map(|c| c.diameter_m)
        .collect();
    let Some(lo) = d.iter().copied().reduce(f64::min) else {
        return Vec::new();
    };
    let hi = d.iter().copied().fold(lo, f64::max);
    let step = 1.0 / bins_per_decade.max(1) as f64;
    let nbins = (((hi / lo).log10() / step).floor() as usize) + 1;
    let mut counts = vec![0usize; nbins];
    for x in &d {
        let k = (((x / lo).log10() / step).floor() as usize).min(nbins - 1);
        counts[k] += 1;
    }
    counts
        .iter()
        .enumerate()
        .filter(|(_, c)| **c > 0)
        .map(|(k, &count)| {
            let (a, b) = (
                lo * 10f64.powf(k as f64 * step),
                lo * 10f64.powf((k + 1) as f64 * step),
            );
            SizeBin {
                diameter_m: (a * b).sqrt(),
                lo_m: a,
                hi_m: b,
                count,
                density: count as f64 / (b - a) / domain_area_m2,
            }
        })
        .collect()
}

/// The power-law fit of a size density (its slope is the exponent), and
/// the decades of diameter it spans.
pub fn size_fit(bins: &[SizeBin]) -> (Option<Fit>, f64) {
    let pts: Vec<(f64, f64)> = bins
        .iter()
        .map(|b| (b.diameter_m.ln(), b.density.ln()))
        .collect();
    let decades = match (bins.first(), bins.last()) {
        (Some(a), Some(b)) => (b.hi_m / a.lo_m).log10(),
        _ => 0.0,
    };
    (fit_line(&pts), decades)
}

/// Every statistic of `field` with cloud where the optical depth reaches
/// `tau_min`; clouds of fewer than `min_cells` cells are counted in the
/// cloud fraction but left out of the fits (their outlines are pixels).
pub fn field_stats(field: &ColumnField, tau_min: f64, min_cells: usize) -> FieldStats {
    let mask = field.mask(tau_min);
    let clouds = mask.clouds();
    let area = (field.width * field.height) as f64 * field.cell_m * field.cell_m;
    let area_perimeter = area_perimeter_fit(&clouds, min_cells);
    let sizes = size_density(&clouds, min_cells, area, 5);
    let (size_fit, size_decades) = size_fit(&sizes);
    FieldStats {
        width: field.width,
        height: field.height,
        cell_m: field.cell_m,
        tau_min,
        cloud_fraction: mask.fraction(),
        profile: field.profile.clone(),
        clouds,
        min_cells,
        dimension: area_perimeter.map(|f| 2.0 * f.slope),
        area_perimeter,
        sizes,
        size_fit,
        size_decades,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mask(w: usize, h: usize, f: impl Fn(usize, usize) -> bool) -> Mask {
        Mask::from_fn(w, h, 1.0, f)
    }

    #[test]
    fn a_square_has_its_area_and_perimeter_and_wraps_across_edges() {
        let m = mask(10, 10, |x, y| (2..5).contains(&x) && (3..7).contains(&y));
        let c = m.clouds();
        assert_eq!(c.len(), 1);
        assert_eq!((c[0].cells, c[0].perimeter_m), (12, 14.0));
        // A square cut by the periodic edge is one cloud.
        let m = mask(10, 10, |x, y| !(2..8).contains(&x) && (3..5).contains(&y));
        let c = m.clouds();
        assert_eq!(c.len(), 1, "{c:?}");
        assert_eq!((c[0].cells, c[0].perimeter_m), (8, 12.0));
    }

    #[test]
    fn fit_line_recovers_a_line() {
        let pts: Vec<(f64, f64)> = (0..10).map(|i| (i as f64, 3.0 - 0.5 * i as f64)).collect();
        let f = fit_line(&pts).expect("fit");
        assert!((f.slope + 0.5).abs() < 1e-12 && (f.intercept - 3.0).abs() < 1e-12);
        assert!((f.r2 - 1.0).abs() < 1e-12);
    }
}
