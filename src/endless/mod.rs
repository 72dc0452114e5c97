//! Endless animation from precomputed volumes (Iwasaki, Nishino & Dobashi
//! 2011, papers 000 and 002): the scene's parcels are simulated ahead and
//! the density the cloud-map renderer marches is sampled into a database
//! of volumes `interval_s` apart (`render::cpu::density_grid::sample`, the
//! volume export's own sampler); the distance between every two volumes
//! is measured; at run time [`Player`] plays an endless sequence, jumping
//! from volume `k` to a volume like `k + 1` (the Video Textures idea) and
//! blending each pair of neighbours in the sequence over one interval
//! (the cross-dissolve). `render::gpu::volume_pass` draws it from one 3D
//! texture holding every volume; `render::cpu::volume` is its twin.
//! `[simulation] method = "endless"` chooses it; docs/methods.md
//! compares it with live physics.

mod file;
mod player;

use glam::Vec3;

pub use file::{DatabaseFileError, fingerprint};
pub use player::{Player, ThresholdRow, threshold_sweep};

/// What went wrong building, reading or writing a database.
#[derive(Debug, thiserror::Error)]
pub enum EndlessError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    File(#[from] DatabaseFileError),
}

/// Where a database came from.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// Built in memory (no `database` key).
    Built,
    /// Read from this file.
    Read(std::path::PathBuf),
    /// Built and written to this file (none there, or made for other
    /// settings).
    Written(std::path::PathBuf),
}

use crate::prepare::Prepared;
use crate::render::cpu::density_grid::{Grid, sample};
use crate::render::cpu::volume::{VolumeParams, VolumeStack};
use crate::render::gpu::GpuSettings;
use crate::scene::{EndlessConfig, RenderSettings, Scene, SceneError};
use crate::sim::Band;

/// The database: the volumes, their distances, and where they lie.
#[derive(Debug, Clone)]
pub struct Database {
    /// Voxels of one volume along x, y (up), z.
    pub dims: [usize; 3],
    /// Each volume's densities as bytes (`σ / extinction · 255`), x
    /// fastest, then y, then z.
    pub volumes: Vec<Vec<u8>>,
    /// `distance[k * n + l]`: the summed squared difference of volumes
    /// `k` and `l` (densities in 0..1), the paper's `D_kl`.
    pub distance: Vec<f64>,
    /// Sky seconds between stored volumes.
    pub interval_s: f64,
    /// The box: lowest corner and size, m.
    pub origin: Vec3,
    pub extent: Vec3,
    /// Extinction of a full byte, 1/m.
    pub extinction_per_m: f32,
    /// CPU wall time of the build, s (simulation and sampling).
    pub build_s: f64,
}

impl Database {
    /// Simulates `scene` and samples `cfg.volumes` volumes over its
    /// domain and band (`progress` after each physics frame and volume,
    /// then after each volume compared with the others: `cfg.volumes`
    /// more).
    pub fn build(
        scene: &Scene,
        cfg: &EndlessConfig,
        mut progress: impl FnMut(),
    ) -> Result<Self, SceneError> {
        let start = std::time::Instant::now();
        let r = &scene.render;
        let mut volumes = Vec::with_capacity(cfg.volumes);
        let mut placed: Option<(Vec3, Vec3, f32)> = None;
        let [nx, ny, nz] = cfg.cells;
        let mut grid_error = None;
        let mut progress_cell = || progress();
        Prepared::snapshots(
            scene,
            cfg.interval_s,
            cfg.volumes,
            |_, p| {
                let l = p.map_extent_m as f32;
                let min = Vec3::new(0.0, p.band.bottom_m as f32, 0.0);
                let max = Vec3::new(l, p.band.top_m as f32, l);
                let grid = match Grid::new([nx, ny, nz], min, max) {
                    Ok(g) => g,
                    Err(e) => {
                        grid_error = Some(e.to_string());
                        return;
                    }
                };
                let frame = p.density_frame(r, r.quality());
                let full = frame.density.extinction_per_m.max(1e-9);
                let values = sample(&frame, &grid);
                volumes.push(
                    values
                        .iter()
                        .map(|v| (v / full * 255.0).round().clamp(0.0, 255.0) as u8)
                        .collect::<Vec<u8>>(),
                );
                placed = Some((min, max - min, full));
            },
            &mut progress_cell,
        )?;
        if let Some(e) = grid_error {
            return Err(scene.invalid("simulation.endless.cells", e));
        }
        let (origin, extent, full) = placed.unwrap_or((Vec3::ZERO, Vec3::ONE, 0.0));
        let distance = distances_with(&volumes, &mut progress_cell);
        Ok(Self {
            dims: [nx as usize, ny as usize, nz as usize],
            volumes,
            distance,
            interval_s: cfg.interval_s,
            origin,
            extent,
            extinction_per_m: full,
            build_s: start.elapsed().as_secs_f64(),
        })
    }

    /// The scene's database: read from `cfg.database` when that file was
    /// made for these settings, else built (and written there).
    pub fn load_or_build(
        scene: &Scene,
        cfg: &EndlessConfig,
        progress: impl FnMut(),
    ) -> Result<(Self, Source), EndlessError> {
        let Some(path) = cfg.database_path(scene.source.as_deref()) else {
            return Ok((Self::build(scene, cfg, progress)?, Source::Built));
        };
        if path.is_dir() {
            return Err(EndlessError::Scene(scene.invalid(
                "simulation.endless.database",
                format!(
                    "names {}, a folder: expected a file to keep the volumes in",
                    path.display()
                ),
            )));
        }
        let print = fingerprint(scene, cfg);
        if path.exists()
            && let Some(db) = Self::load(&path, print)?
        {
            return Ok((db, Source::Read(path)));
        }
        let db = Self::build(scene, cfg, progress)?;
        db.save(&path, print)?;
        Ok((db, Source::Written(path)))
    }

    /// The volume renderer's settings for `r`: its band and extent are
    /// the database's box.
    pub fn gpu_settings(&self, r: &RenderSettings) -> GpuSettings {
        let band = Band {
            bottom_m: self.origin.y as f64,
            top_m: (self.origin.y + self.extent.y) as f64,
        };
        r.gpu_settings_at(band, self.extent.x as f64, r.quality())
    }

    /// Volumes stored.
    pub fn len(&self) -> usize {
        self.volumes.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.volumes.is_empty()
    }

    /// Bytes of the volumes (what the GPU keeps resident).
    pub fn bytes(&self) -> usize {
        self.volumes.iter().map(Vec::len).sum()
    }

    /// The distance `D_kl`.
    pub fn d(&self, k: usize, l: usize) -> f64 {
        self.distance[k * self.len() + l]
    }

    /// The mean distance between consecutive volumes (the step that
    /// plain playback makes).
    pub fn mean_step(&self) -> f64 {
        let n = self.len();
        if n < 2 {
            return 0.0;
        }
        (0..n - 1).map(|k| self.d(k, k + 1)).sum::<f64>() / (n - 1) as f64
    }

    /// The volumes stacked for the 3D texture, and their placement with
    /// the pair `(a, b, w)` picked.
    pub fn stack(&self, pick: (usize, usize, f32)) -> (VolumeStack, VolumeParams) {
        let stack = VolumeStack::new(self.dims, &self.volumes);
        let [nx, ny, nz] = self.dims;
        let params = VolumeParams {
            origin: [self.origin.x, self.origin.y, self.origin.z, 0.0],
            extent: [
                self.extent.x,
                self.extent.y,
                self.extent.z,
                self.extinction_per_m,
            ],
            dims: [nx as u32, ny as u32, nz as u32, self.len() as u32],
            pick: [pick.0 as f32, pick.1 as f32, pick.2, 0.0],
        };
        (stack, params)
    }
}

/// Every pair's summed squared difference (densities as bytes / 255).
pub fn distances(volumes: &[Vec<u8>]) -> Vec<f64> {
    distances_with(volumes, || {})
}

/// [`distances`], calling `progress` after each volume's row. Each pair
/// is compared once (the matrix is symmetric) in integers, exact, and
/// scaled once: 256 volumes of 512x8x512 took 199 s in doubles, both
/// ways round, with no word after the progress bar's 100 %.
pub fn distances_with(volumes: &[Vec<u8>], mut progress: impl FnMut()) -> Vec<f64> {
    use rayon::prelude::*;
    let n = volumes.len();
    let mut d = vec![0.0; n * n];
    for k in 0..n {
        let row: Vec<f64> = (k + 1..n)
            .into_par_iter()
            .map(|l| squared_difference(&volumes[k], &volumes[l]) as f64 / (255.0 * 255.0))
            .collect();
        for (l, v) in (k + 1..n).zip(row) {
            d[k * n + l] = v;
            d[l * n + k] = v;
        }
        progress();
    }
    d
}

/// `Σ (a - b)²` over two volumes' bytes, exact: in blocks whose sums fit
/// a `u32` (4096 · 255² < 2³²), which the compiler vectorises.
fn squared_difference(a: &[u8], b: &[u8]) -> u64 {
    a.chunks(4096)
        .zip(b.chunks(4096))
        .map(|(x, y)| {
            x.iter()
                .zip(y)
                .map(|(p, q)| {
                    let t = u32::from(p.abs_diff(*q));
                    t * t
                })
                .sum::<u32>() as u64
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_are_each_pairs_squared_difference_once() {
        // Volumes long enough for several of the sum's 4096-byte blocks,
        // full of every byte's extremes.
        let volumes: Vec<Vec<u8>> = (0..5u32)
            .map(|v| {
                (0..10_000u32)
                    .map(|i| ((i.wrapping_mul(2_654_435_761) ^ v.wrapping_mul(40_503)) >> 7) as u8)
                    .collect()
            })
            .collect();
        let mut rows = 0;
        let d = distances_with(&volumes, || rows += 1);
        assert_eq!(rows, 5);
        let n = volumes.len();
        for k in 0..n {
            assert_eq!(d[k * n + k], 0.0);
            for l in 0..n {
                let direct: f64 = volumes[k]
                    .iter()
                    .zip(&volumes[l])
                    .map(|(a, b)| ((*a as f64 - *b as f64) / 255.0).powi(2))
                    .sum();
                assert!(
                    (d[k * n + l] - direct).abs() <= 1e-9 * direct.max(1.0),
                    "{k} {l}"
                );
                assert_eq!(d[k * n + l], d[l * n + k]);
            }
        }
        // All 0 against all 255: 255² per byte, exact past a u32's range.
        let big = [vec![0u8; 70_000], vec![255u8; 70_000]];
        assert_eq!(distances(&big)[1], 70_000.0);
    }
}
