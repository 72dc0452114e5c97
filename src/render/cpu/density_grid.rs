//! The density field the renderer marches, sampled on a regular grid
//! ([`sample`]): what `cumulus export` writes for offline renderers and
//! what the endless database stores per volume.

use glam::Vec3;
use rayon::prelude::*;

use super::density::density_at;
use super::frame::Frame;

/// The largest number of cells along one axis.
pub const MAX_CELLS: u32 = 2048;

/// The largest number of cells in all (2^28: a 1 GiB file).
pub const MAX_TOTAL_CELLS: u64 = 1 << 28;

/// A grid that cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum GridError {
    #[error("{what}: {value}, expected {expected}")]
    Bad {
        what: &'static str,
        value: String,
        expected: &'static str,
    },
}

/// A regular grid over an axis-aligned box of the world (metres; y up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Cells along x, y, z.
    pub resolution: [u32; 3],
    /// The box's lowest corner, m.
    pub min_m: Vec3,
    /// The box's highest corner, m.
    pub max_m: Vec3,
}

impl Grid {
    /// A grid over `[min_m, max_m]` of `resolution` cells, checked: each
    /// axis 1..=[`MAX_CELLS`], at most [`MAX_TOTAL_CELLS`] in all, the box
    /// finite and not flat.
    pub fn new(resolution: [u32; 3], min_m: Vec3, max_m: Vec3) -> Result<Self, GridError> {
        if resolution.iter().any(|&n| n == 0 || n > MAX_CELLS) {
            return Err(GridError::Bad {
                what: "grid resolution",
                value: format!("{resolution:?}"),
                expected: "1..=2048 cells along each axis",
            });
        }
        let total: u64 = resolution.iter().map(|&n| n as u64).product();
        if total > MAX_TOTAL_CELLS {
            return Err(GridError::Bad {
                what: "grid cells",
                value: total.to_string(),
                expected: "at most 2^28 (268,435,456) cells",
            });
        }
        if !(min_m.is_finite() && max_m.is_finite() && min_m.cmplt(max_m).all()) {
            return Err(GridError::Bad {
                what: "box",
                value: format!("{min_m} to {max_m}"),
                expected: "finite corners with min < max on every axis",
            });
        }
        Ok(Self {
            resolution,
            min_m,
            max_m,
        })
    }

    /// A grid over `[min_m, max_m]` with cells as near cubic as whole
    /// counts allow, `cells` along the box's longest side.
    pub fn cubic(cells: u32, min_m: Vec3, max_m: Vec3) -> Result<Self, GridError> {
        if cells == 0 || cells > MAX_CELLS {
            return Err(GridError::Bad {
                what: "grid resolution",
                value: format!("{cells} cells along the longest side"),
                expected: "1..=2048 cells along each axis",
            });
        }
        let size = max_m - min_m;
        let longest = size.max_element();
        if !(longest.is_finite() && longest > 0.0) {
            return Self::new([cells; 3], min_m, max_m);
        }
        let along = |s: f32| ((s / longest * cells as f32).round() as u32).max(1);
        Self::new([along(size.x), along(size.y), along(size.z)], min_m, max_m)
    }

    /// The side of a cell along each axis, m.
    pub fn cell_m(&self) -> Vec3 {
        let [x, y, z] = self.resolution;
        (self.max_m - self.min_m) / Vec3::new(x as f32, y as f32, z as f32)
    }

    /// The number of cells.
    pub fn len(&self) -> usize {
        self.resolution.iter().map(|&n| n as usize).product()
    }

    /// Whether the grid has no cells (never, for a checked grid).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The centre of cell `(i, j, k)`, m.
    pub fn centre(&self, i: u32, j: u32, k: u32) -> Vec3 {
        self.min_m + (Vec3::new(i as f32, j as f32, k as f32) + 0.5) * self.cell_m()
    }

    /// The index of cell `(i, j, k)` in the file's order (x fastest).
    pub fn index(&self, i: u32, j: u32, k: u32) -> usize {
        let [nx, ny, _] = self.resolution;
        (k as usize * ny as usize + j as usize) * nx as usize + i as usize
    }
}

/// σ_t (1/m) at every cell centre of `grid`, in the file's order: what
/// the renderer's march reads there ([`density_at`] with the detail
/// noise), at the level of detail of a footprint one cell wide (the
/// smallest side), so the grid holds the features it can resolve.
pub fn sample(frame: &Frame, grid: &Grid) -> Vec<f32> {
    let [nx, ny, nz] = grid.resolution;
    let footprint = grid.cell_m().min_element();
    let slice = nx as usize * ny as usize;
    let mut out = vec![0.0; grid.len()];
    out.par_chunks_mut(slice.max(1))
        .enumerate()
        .for_each(|(k, s)| {
            for j in 0..ny {
                for i in 0..nx {
                    let p = grid.centre(i, j, k as u32);
                    s[(j * nx + i) as usize] =
                        density_at(p, &frame.fields, &frame.density, true, footprint);
                }
            }
        });
    debug_assert_eq!(nz as usize * slice, out.len());
    out
}
