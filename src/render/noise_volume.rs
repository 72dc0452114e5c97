//! The tileable 3D noise volume that erodes the clouds' edges into
//! billows: generated once from the seed, uploaded to the GPU as a 3D
//! texture, and sampled texel for texel, with the same trilinear
//! filtering, by the CPU twin.
//!
//! Two channels, each ranked to a uniform histogram (so the density's
//! threshold means the same share whatever the channel's raw shape):
//! - **base**: Perlin-Worley (Schneider 2015, after the Nubis clouds):
//!   tileable Perlin fBm whose low values are cut away by inverted Worley
//!   fBm, so it has Perlin's connected shapes with Worley's round, billowed
//!   borders;
//! - **billows**: inverted Worley fBm, round cells at three scales (the
//!   cauliflower of a cumulus' surface).
//!
//! Both channels hold 4 features across the tile at their coarsest
//! octave, 16 at their finest (4 texels per finest feature at 64³), and
//! tile in all three axes.

use glam::Vec3;
use rayon::prelude::*;

/// Texels per side.
pub const SIZE: usize = 64;

/// Features across the tile in each channel's coarsest octave.
pub const BASE_CELLS: u32 = 4;

/// The volume: `SIZE³` texels `[base, billows]`, x fastest, then y, then
/// z, each an 8-bit value (`value / 255` in `0..=1`, as the GPU's
/// `Rg8Unorm` reads it), and its mip chain down to 1³ (each level the
/// 2x2x2 mean of the one before, ranked to a uniform histogram again),
/// which both renderers read far away, where a pixel spans several
/// texels.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseVolume {
    /// Level 0 first.
    levels: Vec<Vec<[u8; 2]>>,
}

/// The rounded 2x2x2 mean of an `n³` level.
fn halve(level: &[[u8; 2]], n: usize) -> Vec<[u8; 2]> {
    let h = n / 2;
    let mut out = vec![[0; 2]; h * h * h];
    for z in 0..h {
        for y in 0..h {
            for x in 0..h {
                let mut sum = [0_u32; 2];
                for d in 0..8 {
                    let (dx, dy, dz) = (d & 1, (d >> 1) & 1, d >> 2);
                    let t = level[((2 * z + dz) * n + 2 * y + dy) * n + 2 * x + dx];
                    sum[0] += t[0] as u32;
                    sum[1] += t[1] as u32;
                }
                out[(z * h + y) * h + x] = sum.map(|s| ((s + 4) / 8) as u8);
            }
        }
    }
    out
}

/// A 32-bit hash of a lattice point and a seed.
#[inline]
fn hash(x: u32, y: u32, z: u32, seed: u32) -> u32 {
    let mut h = x.wrapping_mul(0x8da6_b343)
        ^ y.wrapping_mul(0xd816_3841)
        ^ z.wrapping_mul(0xcb1a_b31f)
        ^ seed.wrapping_mul(0x9e37_79b9);
    h ^= h >> 13;
    h = h.wrapping_mul(0x5bd1_e995);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2c1b_3c6d);
    h ^ (h >> 12)
}

#[inline]
fn unit(h: u32) -> f64 {
    (h >> 8) as f64 / 16_777_216.0
}

/// Tileable gradient noise (Perlin 2002's quintic fade) at `q`, with
/// `period` lattice cells per tile, in about `-1..1`.
fn perlin(q: [f64; 3], period: u32, seed: u32) -> f64 {
    let f = q.map(f64::floor);
    let t = [q[0] - f[0], q[1] - f[1], q[2] - f[2]];
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let w = t.map(fade);
    let cell = |c: f64, d: u32| ((c as i64 + d as i64).rem_euclid(period as i64)) as u32;
    let mut acc = [[[0.0; 2]; 2]; 2];
    for (dz, plane) in acc.iter_mut().enumerate() {
        for (dy, row) in plane.iter_mut().enumerate() {
            for (dx, v) in row.iter_mut().enumerate() {
                let h = hash(
                    cell(f[0], dx as u32),
                    cell(f[1], dy as u32),
                    cell(f[2], dz as u32),
                    seed,
                );
                // One of the 12 edge directions of a cube (Perlin 2002).
                let g = match h % 12 {
                    0 => [1.0, 1.0, 0.0],
                    1 => [-1.0, 1.0, 0.0],
                    2 => [1.0, -1.0, 0.0],
                    3 => [-1.0, -1.0, 0.0],
                    4 => [1.0, 0.0, 1.0],
                    5 => [-1.0, 0.0, 1.0],
                    6 => [1.0, 0.0, -1.0],
                    7 => [-1.0, 0.0, -1.0],
                    8 => [0.0, 1.0, 1.0],
                    9 => [0.0, -1.0, 1.0],
                    10 => [0.0, 1.0, -1.0],
                    _ => [0.0, -1.0, -1.0],
                };
                let d = [t[0] - dx as f64, t[1] - dy as f64, t[2] - dz as f64];
                *v = g[0] * d[0] + g[1] * d[1] + g[2] * d[2];
            }
        }
    }
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    let x00 = lerp(acc[0][0][0], acc[0][0][1], w[0]);
    let x10 = lerp(acc[0][1][0], acc[0][1][1], w[0]);
    let x01 = lerp(acc[1][0][0], acc[1][0][1], w[0]);
    let x11 = lerp(acc[1][1][0], acc[1][1][1], w[0]);
    lerp(lerp(x00, x10, w[1]), lerp(x01, x11, w[1]), w[2])
}

/// Tileable Worley noise at `q`: the distance to the nearest of one
/// random feature point per lattice cell (`period` cells per tile), in
/// cell units, clamped to 1.
fn worley(q: [f64; 3], period: u32, seed: u32) -> f64 {
    let f = q.map(f64::floor);
    let mut best = f64::INFINITY;
    for dz in -1..=1_i64 {
        for dy in -1..=1_i64 {
            for dx in -1..=1_i64 {
                let c = [f[0] as i64 + dx, f[1] as i64 + dy, f[2] as i64 + dz];
                let w = c.map(|c| c.rem_euclid(period as i64) as u32);
                let h = hash(w[0], w[1], w[2], seed ^ 0x5851_f42d);
                let p = [
                    c[0] as f64 + unit(h),
                    c[1] as f64 + unit(hash(h, 1, 0, seed)),
                    c[2] as f64 + unit(hash(h, 2, 0, seed)),
                ];
                let d2 = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
                best = best.min(d2);
            }
        }
    }
    best.sqrt().min(1.0)
}

/// Inverted Worley fBm at tile coordinate `u` (0..1 per axis): three
/// octaves from [`BASE_CELLS`], weights 0.625, 0.25, 0.125; 1 at feature
/// points.
fn worley_fbm(u: [f64; 3], seed: u32) -> f64 {
    let at =
        |cells: u32, k: u32| 1.0 - worley(u.map(|x| x * cells as f64), cells, seed.wrapping_add(k));
    0.625 * at(BASE_CELLS, 0) + 0.25 * at(BASE_CELLS * 2, 1) + 0.125 * at(BASE_CELLS * 4, 2)
}

/// Perlin fBm at tile coordinate `u`: three octaves from [`BASE_CELLS`],
/// persistence 0.5, mapped to about `0..1`.
fn perlin_fbm(u: [f64; 3], seed: u32) -> f64 {
    let mut sum = 0.0;
    let mut amp = 1.0;
    let mut cells = BASE_CELLS;
    for k in 0..3 {
        sum += amp
            * perlin(
                u.map(|x| x * cells as f64),
                cells,
                seed.wrapping_add(10 + k),
            );
        amp *= 0.5;
        cells *= 2;
    }
    (0.5 + 0.5 * sum / 1.75).clamp(0.0, 1.0)
}

#[inline]
fn lerp2(a: [f32; 2], b: [f32; 2], t: f32) -> [f32; 2] {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
}

/// `value` mapped from `[lo, hi]` to `[0, 1]`.
fn remap(value: f64, lo: f64, hi: f64) -> f64 {
    (value - lo) / (hi - lo).max(1e-9)
}

/// Ranks of `values` mapped to 8 bits with a uniform histogram.
fn rank_to_u8(values: &[f64]) -> Vec<u8> {
    rank_uniform(values.iter().copied())
        .into_iter()
        .map(|r| (r * 255.0).round() as u8)
        .collect()
}

impl NoiseVolume {
    /// Generates the volume for `seed`. Same seed, same bytes (about 0.2 s
    /// on two cores).
    pub fn generate(seed: u32) -> Self {
        let n = SIZE;
        let raw: Vec<[f64; 2]> = (0..n * n * n)
            .into_par_iter()
            .map(|k| {
                let u = [
                    (k % n) as f64 / n as f64,
                    ((k / n) % n) as f64 / n as f64,
                    (k / (n * n)) as f64 / n as f64,
                ];
                let w = worley_fbm(u, seed);
                let p = perlin_fbm(u, seed);
                // Perlin's low values cut away by the Worley cells.
                let base = remap(p, w - 1.0, 1.0);
                let billows = worley_fbm(u.map(|x| x + 0.37), seed.wrapping_add(101));
                [base, billows]
            })
            .collect();
        let base = rank_to_u8(&raw.iter().map(|r| r[0]).collect::<Vec<_>>());
        let billows = rank_to_u8(&raw.iter().map(|r| r[1]).collect::<Vec<_>>());
        let mut levels: Vec<Vec<[u8; 2]>> =
            vec![base.into_iter().zip(billows).map(|(a, b)| [a, b]).collect()];
        let mut side = SIZE;
        while side > 1 {
            let next = halve(&levels[levels.len() - 1], side);
            // Ranked again, so every level has level 0's uniform spread:
            // far away the erosion keeps its strength (and the clouds
            // their cover) at the coarser level's larger features.
            let a = rank_to_u8(&next.iter().map(|t| t[0] as f64).collect::<Vec<_>>());
            let b = rank_to_u8(&next.iter().map(|t| t[1] as f64).collect::<Vec<_>>());
            levels.push(a.into_iter().zip(b).map(|(a, b)| [a, b]).collect());
            side /= 2;
        }
        Self { levels }
    }

    /// Levels in the mip chain (`SIZE` down to 1).
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// Level `k`'s texels, x fastest (the GPU upload's order); its side is
    /// `SIZE >> k`.
    pub fn level(&self, k: usize) -> &[[u8; 2]] {
        &self.levels[k]
    }

    /// The texel of level `k` at integer coordinates (wrapped).
    #[inline]
    fn texel(&self, k: usize, x: i64, y: i64, z: i64) -> [f32; 2] {
        let n = (SIZE >> k) as i64;
        let i = ((z.rem_euclid(n) * n + y.rem_euclid(n)) * n + x.rem_euclid(n)) as usize;
        let [a, b] = self.levels[k][i];
        [a as f32 / 255.0, b as f32 / 255.0]
    }

    /// Trilinear, periodic sample of level `k` at tile coordinate `q` (1 =
    /// one tile), texel centres at `(i + 0.5) / side`, as a GPU sampler
    /// with linear filtering and repeat addressing reads it.
    fn trilinear(&self, k: usize, q: Vec3) -> [f32; 2] {
        let s = q * (SIZE >> k) as f32 - Vec3::splat(0.5);
        let f = s.floor();
        let t = s - f;
        let (x, y, z) = (f.x as i64, f.y as i64, f.z as i64);
        let row = |y: i64, z: i64| lerp2(self.texel(k, x, y, z), self.texel(k, x + 1, y, z), t.x);
        let plane = |z: i64| lerp2(row(y, z), row(y + 1, z), t.y);
        lerp2(plane(z), plane(z + 1), t.z)
    }

    /// `[base, billows]` at tile coordinate `q`, level 0.
    pub fn sample(&self, q: Vec3) -> [f32; 2] {
        self.trilinear(0, q)
    }

    /// `[base, billows]` at tile coordinate `q` and mip level `lod`
    /// (clamped to the chain): trilinear in the two levels around it,
    /// blended by its fraction (linear mip filtering).
    pub fn sample_level(&self, q: Vec3, lod: f32) -> [f32; 2] {
        let lod = lod.clamp(0.0, (self.levels.len() - 1) as f32);
        let k = lod.floor();
        let f = lod - k;
        let a = self.trilinear(k as usize, q);
        if f <= 0.0 {
            return a;
        }
        lerp2(a, self.trilinear(k as usize + 1, q), f)
    }
}

/// The rank of each value among all, mapped to `(0, 1)`: a field with a
/// uniform histogram, so a threshold at `1 - f` leaves the fraction `f`
/// of the map above it. Ties are broken by index (deterministic).
pub(super) fn rank_uniform(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let v: Vec<f64> = values.collect();
    let mut order: Vec<usize> = (0..v.len()).collect();
    order.sort_by(|&a, &b| v[a].total_cmp(&v[b]).then(a.cmp(&b)));
    let mut out = vec![0.0; v.len()];
    let n = v.len().max(1) as f64;
    for (rank, &i) in order.iter().enumerate() {
        out[i] = (rank as f64 + 0.5) / n;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::OnceLock;

    fn volume() -> &'static NoiseVolume {
        static V: OnceLock<NoiseVolume> = OnceLock::new();
        V.get_or_init(|| NoiseVolume::generate(7))
    }

    #[test]
    fn tiles_in_every_axis() {
        let v = volume();
        for k in 0..300 {
            let q = Vec3::new(
                k as f32 * 0.0731,
                k as f32 * 0.0377 + 0.1,
                k as f32 * 0.0119,
            );
            let a = v.sample(q);
            for shift in [Vec3::X, Vec3::NEG_Y * 2.0, Vec3::Z * 3.0] {
                let b = v.sample(q + shift);
                assert!((a[0] - b[0]).abs() < 1e-4 && (a[1] - b[1]).abs() < 1e-4);
            }
        }
    }

    /// The raw noises are continuous across the tile's faces, so the
    /// texels at opposite faces differ like any neighbours.
    #[test]
    fn no_seam_at_the_tile_faces() {
        let v = volume();
        let (mut seam, mut inner) = (0.0, 0.0);
        let n = SIZE as i64;
        for z in 0..n {
            for y in 0..n {
                let d = |a: i64, b: i64, c: usize| {
                    (v.texel(0, a, y, z)[c] - v.texel(0, b, y, z)[c]).abs() as f64
                };
                seam += d(n - 1, n, 0) + d(n - 1, n, 1);
                inner += d(n / 2 - 1, n / 2, 0) + d(n / 2 - 1, n / 2, 1);
            }
        }
        assert!(seam < 1.3 * inner, "seam {seam} vs inner {inner}");
    }

    #[test]
    fn histograms_are_uniform_and_seeds_differ() {
        let v = volume();
        for c in 0..2 {
            let mean: f64 =
                v.level(0).iter().map(|t| t[c] as f64).sum::<f64>() / v.level(0).len() as f64;
            assert!((mean - 127.5).abs() < 0.6, "channel {c} mean {mean}");
        }
        assert_eq!(NoiseVolume::generate(7), *v);
        let other = NoiseVolume::generate(8);
        let same = other
            .level(0)
            .iter()
            .zip(v.level(0))
            .filter(|(a, b)| a == b)
            .count();
        assert!(same < v.level(0).len() / 20, "{same} texels equal");
    }

    /// Sampling between texel centres interpolates; at a centre it is the
    /// texel.
    #[test]
    fn sample_at_a_centre_is_the_texel() {
        let v = volume();
        let q = Vec3::new(3.5, 10.5, 60.5) / SIZE as f32;
        assert_eq!(v.sample(q), v.texel(0, 3, 10, 60));
        // The last level is the mean of all: about 0.5.
        let top = v.sample_level(q, 99.0);
        assert!(
            (top[0] - 0.5).abs() < 0.02 && (top[1] - 0.5).abs() < 0.02,
            "{top:?}"
        );
        // Half-way between levels 1 and 2 is the mean of the two.
        let (a, b) = (v.sample_level(q, 1.0), v.sample_level(q, 2.0));
        let m = v.sample_level(q, 1.5);
        assert!((m[0] - 0.5 * (a[0] + b[0])).abs() < 1e-6);
    }
}
