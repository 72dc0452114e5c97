//! The coarse max-coverage mask of P: one cell per `cell x cell` texels of
//! P, set where any texel within the cell, grown by a dilation, has
//! coverage. Where a cell is clear, the density is zero for every point
//! whose lookup into P lands there (bilinear filtering reaches one texel),
//! so the GPU march skips the detail noise and the texture reads there.
//! It is only an
//! early exit: the image is the same with or without it (tested against
//! the CPU `density_at`).

use crate::sim::ProjectedField;

/// Coverage at or below which P's texel counts as empty (the density's own
/// threshold, `footprint`).
pub const EMPTY_COVERAGE: f32 = crate::render::cpu::density::P_COVERAGE_MIN;

/// P texels per mask cell along each axis.
pub const CELL: usize = 8;

/// The mask: `width x height` cells, row-major, 1 where cloud may be.
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageMask {
    pub width: usize,
    pub height: usize,
    pub cell: usize,
    pub cells: Vec<u8>,
}

impl CoverageMask {
    /// Builds the mask of `p`.
    pub fn build(p: &ProjectedField) -> Self {
        let (pw, ph) = (p.width().max(1), p.height().max(1));
        let (w, h) = (pw.div_ceil(CELL), ph.div_ceil(CELL));
        // Bilinear filtering reaches one texel.
        let (rx, ry) = (1.min(pw as i64), 1.min(ph as i64));
        // Covered texels, dilated by (rx, ry) with wrap-around: first along
        // x, then along y (separable max).
        let covered: Vec<bool> = (0..pw * ph)
            .map(|k| p.texels().get(k).is_some_and(|t| t[0] > EMPTY_COVERAGE))
            .collect();
        let dilate = |src: &[bool], along_x: bool| -> Vec<bool> {
            let (r, n) = if along_x { (rx, pw) } else { (ry, ph) };
            (0..pw * ph)
                .map(|k| {
                    let (x, y) = ((k % pw) as i64, (k / pw) as i64);
                    (-r..=r).any(|d| {
                        let (xx, yy) = if along_x {
                            ((x + d).rem_euclid(n as i64), y)
                        } else {
                            (x, (y + d).rem_euclid(n as i64))
                        };
                        src[yy as usize * pw + xx as usize]
                    })
                })
                .collect()
        };
        let grown = dilate(&dilate(&covered, true), false);
        let mut cells = vec![0u8; w * h];
        for (k, &g) in grown.iter().enumerate() {
            if g {
                cells[(k / pw / CELL) * w + (k % pw) / CELL] = 1;
            }
        }
        Self {
            width: w,
            height: h,
            cell: CELL,
            cells,
        }
    }

    /// Whether the cell holding map coordinate `(u, v)` is clear (the
    /// shader's `coarse_empty`).
    pub fn is_empty_at(&self, u: f32, v: f32, p_width: usize, p_height: usize) -> bool {
        let (fu, fv) = (u - u.floor(), v - v.floor());
        let mx = ((fu * p_width as f32 / self.cell as f32) as usize).min(self.width - 1);
        let my = ((fv * p_height as f32 / self.cell as f32) as usize).min(self.height - 1);
        self.cells[my * self.width + mx] == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::cloud_map::{CloudMap, CloudMapConfig};
    use crate::render::cpu::density::{DensityParams, Fields, density_at, warped_lookup};
    use glam::Vec3;

    /// Wherever the mask is clear, the CPU density is zero: the GPU's early
    /// exit changes no pixel. Checked over a patchy P with the detail warp
    /// on, at many points of the band (fails without the dilation).
    #[test]
    fn a_clear_cell_has_no_density_with_the_detail_warp() {
        let (w, h) = (96, 80);
        let texels = (0..w * h)
            .map(|k| {
                let (x, y) = ((k % w) as i64, (k / w) as i64);
                // A few blobs and a line along the wrap edge.
                let blob = (x - 30).pow(2) + (y - 20).pow(2) < 36
                    || (x - 70).pow(2) + (y - 60).pow(2) < 9
                    || x == w as i64 - 1;
                if blob { [1.0, 0.8, 0.7] } else { [0.0; 3] }
            })
            .collect();
        let p = ProjectedField::from_texels(w, h, texels).expect("size");
        let cm = CloudMap::generate(&CloudMapConfig {
            size: 64,
            ..Default::default()
        });
        let d = DensityParams {
            band_bottom_m: 600.0,
            band_top_m: 1600.0,
            coverage: 1.0,
            extinction_per_m: 0.04,
            map_extent_m: 10_000.0,
            detail_strength: 0.8,
            detail_scale_m: 400.0,
            fine_detail: true,
        };
        let mask = CoverageMask::build(&p);
        let f = Fields {
            p: &p,
            cloud_map: &cm,
        };
        let (mut clear, mut dense) = (0, 0);
        for i in 0..40_000 {
            let r = |k: u32| {
                let h = (i as u32).wrapping_mul(0x9e37_79b9) ^ k.wrapping_mul(0x85eb_ca6b);
                let h = (h ^ (h >> 15)).wrapping_mul(0x2c1b_3c6d);
                ((h ^ (h >> 12)) >> 8) as f32 / 16_777_216.0
            };
            let q = Vec3::new(r(1) * 10_000.0, 600.0 + r(2) * 1000.0, r(3) * 10_000.0);
            let sigma = density_at(q, &f, &d, true, (i % 7) as f32 * 20.0);
            dense += (sigma > 0.0) as u32;
            // The density looks P up through the domain warp.
            let (u, v, _) = warped_lookup(q.x, q.z, d.map_extent_m);
            if mask.is_empty_at(u, v, w, h) {
                clear += 1;
                assert_eq!(sigma, 0.0, "density {sigma} in a clear cell at {q}");
            }
        }
        assert!(
            clear > 20_000 && dense > 100,
            "clear {clear}, dense {dense}"
        );
    }
}
