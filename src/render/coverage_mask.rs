//! The coarse max-coverage mask of P: one cell per `cell x cell` texels of
//! P, set where any texel within the cell, grown by a dilation, has
//! coverage. Where a cell is clear, the density is zero for every point
//! whose map lookup can land there (bilinear filtering reaches one texel,
//! the detail warp `detail_scale_m * detail_strength` further), so the GPU
//! march skips the detail noise and the texture reads there. It is only an
//! early exit: the image is the same with or without it (tested against
//! the CPU `density_at`).

use crate::sim::ProjectedField;

/// Coverage at or below which P's texel counts as empty (the density's own
/// threshold, `footprint`).
pub const EMPTY_COVERAGE: f32 = 1e-3;

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
    /// Builds the mask of `p` for a map extent of `map_extent_m` and a
    /// detail warp of at most `warp_m`.
    pub fn build(p: &ProjectedField, map_extent_m: f32, warp_m: f32) -> Self {
        let (pw, ph) = (p.width().max(1), p.height().max(1));
        let (w, h) = (pw.div_ceil(CELL), ph.div_ceil(CELL));
        let reach = |n: usize| 1 + (warp_m.max(0.0) / (map_extent_m / n as f32)).ceil() as i64;
        let (rx, ry) = (reach(pw).min(pw as i64), reach(ph).min(ph as i64));
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
