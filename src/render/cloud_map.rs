//! The cloud map CM: a seeded, tileable 2D texture of cumulus cells (the
//! cloud-map paper, section 3.2.1 and Fig. 4): Worley (Voronoi) cells
//! multiplied with Perlin fBm for ragged edges, plus a coarser Worley
//! channel.
//!
//! Tiling: the `noise` crate's generators are not periodic, so the map
//! samples them in 4D on a flat torus, `(u, v) -> (R cos 2πu, R sin 2πu,
//! R cos 2πv, R sin 2πv)`: the texture is periodic in both directions by
//! construction, with no blending seam (measured in
//! `cloud_map_tiles_seamlessly`).

use noise::{
    Fbm, MultiFractal, NoiseFn, Perlin, Worley, core::worley::ReturnType,
    core::worley::distance_functions,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Parameters of the cloud map (scene table `[render.cloud_map]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CloudMapConfig {
    /// Texels per side (16..=2048). Default 256.
    pub size: usize,
    /// Seed of the noise. Default 7.
    pub seed: u32,
    /// Cumulus cells across the map (Worley frequency, 1..=64). Default 6.
    pub cells: f64,
    /// Perlin fBm features across the map (1..=256). Default 16.
    pub detail: f64,
    /// fBm octaves (1..=8). Default 4.
    pub octaves: usize,
}

impl Default for CloudMapConfig {
    fn default() -> Self {
        Self {
            size: 256,
            seed: 7,
            cells: 6.0,
            detail: 16.0,
            octaves: 4,
        }
    }
}

/// The cloud map: `size²` texels, row-major, each `[shape, coarse]` in
/// `0..=1`. `shape` is high in the middle of a cumulus cell and ragged at its
/// edge; `coarse` is a Worley field with a quarter of the cells.
#[derive(Debug, Clone, PartialEq)]
pub struct CloudMap {
    size: usize,
    texels: Vec<[f32; 2]>,
}

fn torus(u: f64, v: f64, features: f64) -> [f64; 4] {
    let r = features / std::f64::consts::TAU;
    let (a, b) = (u * std::f64::consts::TAU, v * std::f64::consts::TAU);
    [r * a.cos(), r * a.sin(), r * b.cos(), r * b.sin()]
}

impl CloudMap {
    /// Generates the map. Same configuration, same bytes.
    pub fn generate(cfg: &CloudMapConfig) -> Self {
        let n = cfg.size.max(1);
        // The generators are not Sync: each worker thread builds its own.
        let generators = || {
            let worley = |seed| {
                Worley::new(seed)
                    .set_distance_function(distance_functions::euclidean)
                    .set_return_type(ReturnType::Distance)
            };
            let fbm =
                Fbm::<Perlin>::new(cfg.seed.wrapping_add(2)).set_octaves(cfg.octaves.clamp(1, 8));
            (worley(cfg.seed), worley(cfg.seed.wrapping_add(1)), fbm)
        };
        let raw: Vec<[f64; 3]> = (0..n * n)
            .into_par_iter()
            .map_init(generators, |(cells, coarse, fbm), k| {
                let (u, v) = ((k % n) as f64 / n as f64, (k / n) as f64 / n as f64);
                [
                    cells.get(torus(u, v, cfg.cells)),
                    coarse.get(torus(u, v, cfg.cells * 0.5)),
                    fbm.get(torus(u, v, cfg.detail)),
                ]
            })
            .collect();
        // Normalise each field to 0..1 over the map (deterministic: a
        // sequential min/max).
        let mut lo = [f64::MAX; 3];
        let mut hi = [f64::MIN; 3];
        for r in &raw {
            for c in 0..3 {
                lo[c] = lo[c].min(r[c]);
                hi[c] = hi[c].max(r[c]);
            }
        }
        let norm = |x: f64, c: usize| {
            if hi[c] > lo[c] {
                (x - lo[c]) / (hi[c] - lo[c])
            } else {
                0.0
            }
        };
        let texels = raw
            .iter()
            .map(|r| {
                // Near a cell's feature point the distance is 0: invert so
                // the cell middle is 1, then sharpen the gaps between cells.
                let cell = (1.0 - norm(r[0], 0)).powf(1.5);
                let ragged = 0.55 + 0.45 * norm(r[2], 2);
                let coarse = 1.0 - norm(r[1], 1);
                [(cell * ragged) as f32, coarse as f32]
            })
            .collect();
        Self { size: n, texels }
    }

    /// Texels per side.
    pub fn size(&self) -> usize {
        self.size
    }

    /// The texel at column `x`, row `y`.
    pub fn texel(&self, x: usize, y: usize) -> [f32; 2] {
        self.texels[y * self.size + x]
    }

    /// All texels, row-major.
    pub fn texels(&self) -> &[[f32; 2]] {
        &self.texels
    }

    /// Bilinear, periodic sample at map coordinate `uv` (1 = one map).
    pub fn sample(&self, u: f32, v: f32) -> [f32; 2] {
        let n = self.size;
        let (x, y) = (u * n as f32 - 0.5, v * n as f32 - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let w = |i: f32| (i as i64).rem_euclid(n as i64) as usize;
        let (xa, xb, ya, yb) = (w(x0), w(x0 + 1.0), w(y0), w(y0 + 1.0));
        let t = |xx: usize, yy: usize| self.texels[yy * n + xx];
        let lerp =
            |a: [f32; 2], b: [f32; 2], f: f32| [a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f];
        lerp(
            lerp(t(xa, ya), t(xb, ya), fx),
            lerp(t(xa, yb), t(xb, yb), fx),
            fy,
        )
    }

    /// Texel centres of the `count` brightest cell middles (local maxima of
    /// `shape`, best first), as map coordinates: where parcels start so
    /// their footprints land on cloud cells (the paper's Alg. 1, line 2).
    pub fn cell_centres(&self, count: usize) -> Vec<(f32, f32)> {
        let n = self.size as i64;
        let at = |x: i64, y: i64| self.texels[(y.rem_euclid(n) * n + x.rem_euclid(n)) as usize][0];
        let mut peaks: Vec<(f32, i64, i64)> = Vec::new();
        for y in 0..n {
            for x in 0..n {
                let c = at(x, y);
                let is_peak = (-2..=2).all(|dy| {
                    (-2..=2).all(|dx| {
                        (dx == 0 && dy == 0)
                            || at(x + dx, y + dy) < c
                            || (at(x + dx, y + dy) == c && (y + dy, x + dx) > (y, x))
                    })
                });
                if is_peak && c > 0.05 {
                    peaks.push((c, x, y));
                }
            }
        }
        peaks.sort_by(|a, b| b.0.total_cmp(&a.0).then((a.2, a.1).cmp(&(b.2, b.1))));
        peaks
            .into_iter()
            .take(count)
            .map(|(_, x, y)| ((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> CloudMapConfig {
        CloudMapConfig {
            size: 64,
            ..CloudMapConfig::default()
        }
    }

    #[test]
    fn same_seed_same_bytes_other_seed_other_map() {
        let a = CloudMap::generate(&small());
        let b = CloudMap::generate(&small());
        assert_eq!(a, b);
        let c = CloudMap::generate(&CloudMapConfig { seed: 8, ..small() });
        assert_ne!(a, c);
        assert!(
            a.texels()
                .iter()
                .all(|t| (0.0..=1.0).contains(&t[0]) && (0.0..=1.0).contains(&t[1]))
        );
    }

    #[test]
    fn cloud_map_tiles_seamlessly() {
        // The jump across the wrap-around edge is no larger than across the
        // interior: mean |Δ| between column n-1 and column 0 against the
        // mean over all interior neighbouring columns (same for rows).
        let m = CloudMap::generate(&CloudMapConfig {
            size: 128,
            ..CloudMapConfig::default()
        });
        let n = m.size();
        let t = |x: usize, y: usize| m.texels()[y * n + x][0];
        let mut interior = 0.0;
        for y in 0..n {
            for x in 0..n - 1 {
                interior += (t(x + 1, y) - t(x, y)).abs() + (t(y, x + 1) - t(y, x)).abs();
            }
        }
        interior /= (2 * n * (n - 1)) as f32;
        let mut edge = 0.0;
        for k in 0..n {
            edge += (t(0, k) - t(n - 1, k)).abs() + (t(k, 0) - t(k, n - 1)).abs();
        }
        edge /= (2 * n) as f32;
        // 1.5x: the edge is one column of 128, so its mean is noisier than
        // the interior's; a real seam is many times larger.
        assert!(edge < 1.5 * interior, "edge {edge} vs interior {interior}");
    }

    #[test]
    fn cell_centres_are_bright_and_distinct() {
        let m = CloudMap::generate(&small());
        let c = m.cell_centres(8);
        assert!(c.len() >= 4, "{c:?}");
        for (u, v) in &c {
            assert!(m.sample(*u, *v)[0] > 0.3);
        }
    }
}
