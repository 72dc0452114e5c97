//! The cloud map CM: a seeded, tileable 2D texture of multi-scale
//! fractal noise, the horizontal pattern the clouds take where the parcels
//! are (the cloud-map paper's section 3.2.1 uses Worley cells times
//! Perlin noise; one cell size makes every cloud the same size).
//!
//! Channel 0 is Perlin fBm over `octaves` octaves from `cells` features
//! across the map, each octave `roughness` times the last: level sets of
//! such a field are fractal (the rougher, the higher their dimension) and
//! its islands above a threshold have a power-law size distribution, as
//! real cumulus fields do. Its values are replaced by their ranks, so the
//! field is uniform on `0..1` and a threshold at `1 - f` leaves the
//! fraction `f` of the map above it. Parcels are born at channel 0's
//! highest local maxima. Channel 1 is the same noise's first two octaves,
//! ranked likewise: the large-scale pattern, which raises the local cloud
//! top.
//!
//! Tiling: the `noise` crate's generators are not periodic, so the map
//! samples them in 4D on a flat torus, `(u, v) -> (R cos 2πu, R sin 2πu,
//! R cos 2πv, R sin 2πv)`: the texture is periodic in both directions by
//! construction, with no blending seam (measured in
//! `cloud_map_tiles_seamlessly`).

use std::sync::{Arc, Mutex};

use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use rayon::prelude::*;

use super::noise_volume::{NoiseVolume, rank_uniform};
use serde::{Deserialize, Serialize};

/// Parameters of the cloud map (scene table `[render.cloud_map]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CloudMapConfig {
    /// Texels per side (16..=2048). Default 256.
    pub size: usize,
    /// Seed of the noise. Default 7.
    pub seed: u32,
    /// Features of the largest scale across the map (1..=64). Default 4.
    pub cells: f64,
    /// fBm octaves (1..=10). Default 4.
    pub octaves: usize,
    /// Amplitude of each octave relative to the one before (0.3..=0.95).
    /// Default 0.8: rough outlines (with the 3D detail noise, an
    /// area-perimeter dimension near the 1.35 of real cloud fields).
    pub roughness: f64,
}

impl Default for CloudMapConfig {
    fn default() -> Self {
        Self {
            size: 256,
            seed: 7,
            cells: 4.0,
            octaves: 4,
            roughness: 0.8,
        }
    }
}

/// The cloud map: `size²` texels, row-major, each `[shape, large]` in
/// `0..1`, each uniformly distributed over the map: `shape` the
/// multi-scale noise, `large` its two largest octaves; its mip chain (the
/// level of detail of distant lookups); and the 3D detail volume made
/// from the same seed. Both renderers read all three.
#[derive(Debug, Clone, PartialEq)]
pub struct CloudMap {
    size: usize,
    texels: Vec<[f32; 2]>,
    /// Levels 1.. of the mip chain, each the 2x2 box mean of the one
    /// before, ranked to a uniform histogram again, while the size halves
    /// evenly.
    mips: Vec<Vec<[f32; 2]>>,
    noise: Arc<NoiseVolume>,
}

/// The detail volume of `seed`, made once per process and shared (every
/// map of one seed has the same volume; tests and the demo make many).
fn noise_volume(seed: u32) -> Arc<NoiseVolume> {
    static MADE: Mutex<Vec<(u32, Arc<NoiseVolume>)>> = Mutex::new(Vec::new());
    let mut made = MADE.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, v)) = made.iter().find(|(s, _)| *s == seed) {
        return v.clone();
    }
    let v = Arc::new(NoiseVolume::generate(seed));
    if made.len() >= 8 {
        made.remove(0);
    }
    made.push((seed, v.clone()));
    v
}

/// A mip level with each channel replaced by its ranks (uniform on
/// `0..1`, like level 0): the box mean narrows the values' spread, and a
/// threshold on the narrowed field would leave less cloud the farther
/// away (measured: from above at 48x48 pixels the cover fell from 0.3 to
/// 0.08); ranked, every level leaves the same fraction above a threshold,
/// with the coarser level's smoother shapes.
fn rank_level(level: &[[f32; 2]]) -> Vec<[f32; 2]> {
    let a = rank_uniform(level.iter().map(|t| t[0] as f64));
    let b = rank_uniform(level.iter().map(|t| t[1] as f64));
    a.into_iter()
        .zip(b)
        .map(|(a, b)| [a as f32, b as f32])
        .collect()
}

/// The 2x2 box mean of a `n x n` level (`n` even).
fn halve(level: &[[f32; 2]], n: usize) -> Vec<[f32; 2]> {
    let h = n / 2;
    let mut out = vec![[0.0; 2]; h * h];
    for y in 0..h {
        for x in 0..h {
            let t = |dx: usize, dy: usize| level[(2 * y + dy) * n + 2 * x + dx];
            let (a, b, c, d) = (t(0, 0), t(1, 0), t(0, 1), t(1, 1));
            out[y * h + x] = [
                0.25 * (a[0] + b[0] + c[0] + d[0]),
                0.25 * (a[1] + b[1] + c[1] + d[1]),
            ];
        }
    }
    out
}

/// Bilinear, periodic sample of an `n x n` level at `(u, v)`.
fn bilinear(texels: &[[f32; 2]], n: usize, u: f32, v: f32) -> [f32; 2] {
    let (x, y) = (u * n as f32 - 0.5, v * n as f32 - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let w = |i: f32| (i as i64).rem_euclid(n as i64) as usize;
    let (xa, xb, ya, yb) = (w(x0), w(x0 + 1.0), w(y0), w(y0 + 1.0));
    let t = |xx: usize, yy: usize| texels[yy * n + xx];
    let lerp =
        |a: [f32; 2], b: [f32; 2], f: f32| [a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f];
    lerp(
        lerp(t(xa, ya), t(xb, ya), fx),
        lerp(t(xa, yb), t(xb, yb), fx),
        fy,
    )
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
            let fbm = |octaves: usize| {
                Fbm::<Perlin>::new(cfg.seed.wrapping_add(2))
                    .set_octaves(octaves.clamp(1, 10))
                    .set_persistence(cfg.roughness)
            };
            (fbm(cfg.octaves), fbm(2))
        };
        let raw: Vec<[f64; 2]> = (0..n * n)
            .into_par_iter()
            .map_init(generators, |(fine, large), k| {
                let (u, v) = ((k % n) as f64 / n as f64, (k / n) as f64 / n as f64);
                let t = torus(u, v, cfg.cells);
                [fine.get(t), large.get(t)]
            })
            .collect();
        let a = rank_uniform(raw.iter().map(|r| r[0]));
        let b = rank_uniform(raw.iter().map(|r| r[1]));
        let texels = a
            .into_iter()
            .zip(b)
            .map(|(a, b)| [a as f32, b as f32])
            .collect::<Vec<_>>();
        let mut mips: Vec<Vec<[f32; 2]>> = Vec::new();
        let mut side = n;
        while side.is_multiple_of(2) && side > 1 {
            let next = halve(mips.last().unwrap_or(&texels), side);
            mips.push(rank_level(&next));
            side /= 2;
        }
        Self {
            size: n,
            texels,
            mips,
            noise: noise_volume(cfg.seed),
        }
    }

    /// Levels in the mip chain (level 0 is the map itself).
    pub fn levels(&self) -> usize {
        1 + self.mips.len()
    }

    /// Level `k` (`< levels()`): its side and texels, row-major.
    pub fn level(&self, k: usize) -> (usize, &[[f32; 2]]) {
        match k {
            0 => (self.size, &self.texels),
            _ => (self.size >> k, &self.mips[k - 1]),
        }
    }

    /// The 3D detail volume of the map's seed.
    pub fn noise(&self) -> &NoiseVolume {
        &self.noise
    }

    /// The detail volume, shared (a renderer keeps it to upload when the
    /// detail is switched on).
    pub fn noise_shared(&self) -> Arc<NoiseVolume> {
        self.noise.clone()
    }

    /// Trilinear sample at map coordinate `uv` and mip level `lod`
    /// (clamped to the chain): bilinear in the two levels around it,
    /// blended by its fraction, as a sampler with linear mip filtering
    /// reads it.
    pub fn sample_level(&self, u: f32, v: f32, lod: f32) -> [f32; 2] {
        let top = (self.levels() - 1) as f32;
        let lod = lod.clamp(0.0, top);
        let k = lod.floor();
        let f = lod - k;
        let at = |k: usize| {
            let (n, t) = self.level(k);
            bilinear(t, n, u, v)
        };
        let a = at(k as usize);
        if f <= 0.0 {
            return a;
        }
        let b = at(k as usize + 1);
        [a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f]
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
        bilinear(&self.texels, self.size, u, v)
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
