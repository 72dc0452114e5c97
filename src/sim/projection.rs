//! Projection of the parcels into the 2D texture P: per texel the tuple
//! `<coverage, normalised height, fill density>` (the cloud-map paper,
//! section 3.2). The renderer reads only this.
//!
//! Each condensed parcel covers a disc of its radius in the periodic plane,
//! with a soft edge one texel wide (anti-aliasing). Where discs overlap,
//! height and fill are the coverage-weighted average of the parcels there
//! ("overlapping regions ... are given the average values"), and coverage
//! is the largest of them. Parcels without condensate project nothing.

use super::parcels::Parcels;

/// The projected field P: `width * height` texels, row-major, `y` down the
/// rows, each `[coverage, height, fill]` in `0..=1`.
#[derive(Debug, Clone, PartialEq)]
pub struct ProjectedField {
    width: usize,
    height: usize,
    texels: Vec<[f32; 3]>,
    weight: Vec<f32>,
}

/// The vertical band that normalised height refers to, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Band {
    /// Cloud base, m.
    pub bottom_m: f64,
    /// Cloud top, m (> bottom).
    pub top_m: f64,
}

impl ProjectedField {
    /// An empty (cloudless) field.
    pub fn new(width: usize, height: usize) -> Self {
        let n = width * height;
        Self {
            width,
            height,
            texels: vec![[0.0; 3]; n],
            weight: vec![0.0; n],
        }
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The texels, row-major.
    pub fn texels(&self) -> &[[f32; 3]] {
        &self.texels
    }

    /// Texel at column `x`, row `y`.
    pub fn at(&self, x: usize, y: usize) -> [f32; 3] {
        self.texels[y * self.width + x]
    }

    /// Bilinear, periodic sample at field coordinate `(u, v)` (1 = the whole
    /// field; `u` along the width, `v` along the height).
    pub fn sample(&self, u: f32, v: f32) -> [f32; 3] {
        let (w, h) = (self.width as i64, self.height as i64);
        if w == 0 || h == 0 {
            return [0.0; 3];
        }
        let (x, y) = (u * w as f32 - 0.5, v * h as f32 - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (xa, xb) = (
            (x0 as i64).rem_euclid(w) as usize,
            (x0 as i64 + 1).rem_euclid(w) as usize,
        );
        let (ya, yb) = (
            (y0 as i64).rem_euclid(h) as usize,
            (y0 as i64 + 1).rem_euclid(h) as usize,
        );
        let t = |xx: usize, yy: usize| self.texels[yy * self.width + xx];
        let lerp = |a: [f32; 3], b: [f32; 3], f: f32| {
            [
                a[0] + (b[0] - a[0]) * f,
                a[1] + (b[1] - a[1]) * f,
                a[2] + (b[2] - a[2]) * f,
            ]
        };
        lerp(
            lerp(t(xa, ya), t(xb, ya), fx),
            lerp(t(xa, yb), t(xb, yb), fx),
            fy,
        )
    }

    /// A field from `width x height` texels (row-major); `None` when the
    /// count does not match.
    pub fn from_texels(width: usize, height: usize, texels: Vec<[f32; 3]>) -> Option<Self> {
        if texels.len() != width * height {
            return None;
        }
        let mut f = Self::new(width, height);
        f.texels = texels;
        Some(f)
    }

    /// A field filled with one texel value (for tests and tools).
    pub fn uniform(width: usize, height: usize, texel: [f32; 3]) -> Self {
        let mut f = Self::new(width, height);
        f.texels.fill(texel);
        f
    }

    /// Fraction of texels with any coverage.
    pub fn covered_fraction(&self) -> f64 {
        if self.texels.is_empty() {
            return 0.0;
        }
        self.texels.iter().filter(|t| t[0] > 0.0).count() as f64 / self.texels.len() as f64
    }

    /// Re-projects `parcels` (positions in a periodic square of side
    /// `domain_m`) into the field.
    pub fn project(
        &mut self,
        parcels: &Parcels,
        domain_m: f64,
        band: Band,
        fill_full_condensed_fraction: f64,
    ) {
        self.texels.fill([0.0; 3]);
        self.weight.fill(0.0);
        if self.texels.is_empty() || domain_m.is_nan() || domain_m <= 0.0 {
            return;
        }
        let (w, h) = (self.width as i64, self.height as i64);
        let sx = self.width as f64 / domain_m;
        let sy = self.height as f64 / domain_m;
        let span = (band.top_m - band.bottom_m).max(1e-6);
        let full = fill_full_condensed_fraction.max(1e-12);
        for i in 0..parcels.len() {
            let d = &parcels.diag[i];
            if d.qc.is_nan() || d.qc <= 0.0 || !parcels.life[i].released() {
                continue;
            }
            let p = parcels.pos[i];
            let zn = ((p.z - band.bottom_m) / span).clamp(0.0, 1.0) as f32;
            let qt = parcels.qt[i];
            let fill = if qt > 0.0 {
                (d.qc / qt / full).clamp(0.0, 1.0)
            } else {
                0.0
            } as f32;
            // Texel centres at (k + 0.5) / scale.
            let (cx, cy) = (p.x * sx - 0.5, p.y * sy - 0.5);
            let (rx, ry) = (parcels.life[i].radius_m * sx, parcels.life[i].radius_m * sy);
            // Coverage is positive while dist < 1 + 0.5 / min(rx, ry).
            let reach = 1.0 + 0.5 / rx.min(ry);
            let x0 = (cx - rx * reach).floor() as i64;
            let x1 = (cx + rx * reach).ceil() as i64;
            let y0 = (cy - ry * reach).floor() as i64;
            let y1 = (cy + ry * reach).ceil() as i64;
            // A footprint wider than the field wraps onto itself: visit each
            // texel once.
            let (x1, y1) = (x1.min(x0 + w - 1), y1.min(y0 + h - 1));
            for ty in y0..=y1 {
                let dy = (ty as f64 - cy) / ry;
                let row = ty.rem_euclid(h) as usize * self.width;
                for tx in x0..=x1 {
                    let dx = (tx as f64 - cx) / rx;
                    // Distance to the rim in texels (elliptic if sx != sy).
                    let dist = (dx * dx + dy * dy).sqrt();
                    let edge_texels = (1.0 - dist) * rx.min(ry);
                    let cov = (edge_texels + 0.5).clamp(0.0, 1.0) as f32;
                    if cov <= 0.0 {
                        continue;
                    }
                    let k = row + tx.rem_euclid(w) as usize;
                    let t = &mut self.texels[k];
                    t[0] = t[0].max(cov);
                    t[1] += cov * zn;
                    t[2] += cov * fill;
                    self.weight[k] += cov;
                }
            }
        }
        for (t, &wt) in self.texels.iter_mut().zip(&self.weight) {
            if wt > 0.0 {
                t[1] /= wt;
                t[2] /= wt;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::parcels::{Diag, Life};
    use glam::DVec3;

    fn parcels(list: &[(f64, f64, f64, f64, f64)]) -> Parcels {
        // (x, y, z, radius, qc) with qt = 0.016.
        let mut p = Parcels::default();
        for &(x, y, z, r, qc) in list {
            p.pos.push(DVec3::new(x, y, z));
            p.vel.push(DVec3::ZERO);
            p.theta_l.push(300.0);
            p.qt.push(0.016);
            p.diag.push(Diag {
                qc,
                ..Diag::default()
            });
            p.life.push(Life {
                radius_m: r,
                ..Life::default()
            });
        }
        p
    }

    const BAND: Band = Band {
        bottom_m: 500.0,
        top_m: 1500.0,
    };

    #[test]
    fn disc_area_matches_parcel_footprint() {
        let mut f = ProjectedField::new(200, 200);
        f.project(
            &parcels(&[(500.0, 500.0, 1000.0, 200.0, 0.001)]),
            1000.0,
            BAND,
            0.08,
        );
        let area: f64 = f.texels().iter().map(|t| t[0] as f64).sum::<f64>() * 25.0; // 5 m texels
        let want = std::f64::consts::PI * 200.0 * 200.0;
        // The soft edge integrates to the disc area to within a texel ring.
        assert!((area - want).abs() / want < 0.02, "{area} vs {want}");
        let c = f.at(100, 100);
        assert_eq!(c[0], 1.0);
        assert!((c[1] - 0.5).abs() < 1e-6);
        assert!((c[2] - (0.001 / 0.016 / 0.08) as f32).abs() < 1e-6);
    }

    #[test]
    fn overlaps_are_averaged() {
        let mut f = ProjectedField::new(100, 100);
        f.project(
            &parcels(&[
                (500.0, 500.0, 500.0, 300.0, 0.001),
                (520.0, 500.0, 1500.0, 300.0, 0.001),
            ]),
            1000.0,
            BAND,
            0.08,
        );
        assert!((f.at(51, 50)[1] - 0.5).abs() < 1e-6, "{:?}", f.at(51, 50));
    }

    #[test]
    fn uncondensed_parcels_project_nothing_and_edges_wrap() {
        let mut f = ProjectedField::new(64, 64);
        f.project(
            &parcels(&[(500.0, 500.0, 900.0, 200.0, 0.0)]),
            1000.0,
            BAND,
            0.08,
        );
        assert_eq!(f.covered_fraction(), 0.0);
        f.project(
            &parcels(&[(0.0, 0.0, 900.0, 100.0, 0.001)]),
            1000.0,
            BAND,
            0.08,
        );
        assert_eq!(f.at(0, 0)[0], 1.0);
        assert_eq!(f.at(63, 63)[0], 1.0);
        assert_eq!(f.at(32, 32)[0], 0.0);
    }
}
