//! Where the rays sample: the per-pixel blue-noise dither of the march
//! samples, the per-frame golden-ratio offset added to it, and the TSAA
//! sub-pixel jitter (both renderers use these; the CPU's converged oracle
//! averages the same frames the GPU's TSAA accumulates).
//!
//! The offsets are the ranks of a void-and-cluster ordering (Ulichney
//! 1993) of a 64x64 torus: every prefix of the ordering is an evenly spread
//! point set, so the offsets of neighbouring pixels differ as much as they
//! can and their error has no low frequencies. A fixed per-pixel pattern
//! with structure (an interleaved gradient noise, say) leaves a 2x2
//! checker and moire on cloud surfaces; this pattern's error looks like
//! fine grain, which TSAA's neighbourhood filter and history remove.
//!
//! Each frame adds the golden-ratio offset of its index to every pixel's
//! value ([`frame_offset`]), so a pixel's offsets over frames are an
//! evenly spread sequence of its own, and the pattern never stands still.

use std::sync::OnceLock;

/// Pixels per side of the tile.
pub const SIZE: usize = 64;

/// Width (pixels) of the Gaussian that measures clustering; 1.5 is the
/// usual choice (narrower gives a noisier, wider a more regular pattern).
const SIGMA: f64 = 1.5;

/// Share of the tile in the initial random pattern.
const INITIAL_FRACTION: f64 = 0.1;

/// The 64x64 tile of dither offsets in `(0, 1)`, row-major: `(rank +
/// 0.5) / 4096` of each pixel's rank in the void-and-cluster ordering.
/// Built once per process (about 30 ms); the same bytes every time.
pub fn tile() -> &'static [f32] {
    static TILE: OnceLock<Vec<f32>> = OnceLock::new();
    TILE.get_or_init(|| {
        let n = (SIZE * SIZE) as f32;
        void_and_cluster_ranks()
            .into_iter()
            .map(|r| (r as f32 + 0.5) / n)
            .collect()
    })
}

/// The dither offset of pixel `(x, y)`, in `(0, 1)`; the tile repeats.
#[inline]
pub fn at(x: u32, y: u32) -> f32 {
    tile()[(y as usize % SIZE) * SIZE + x as usize % SIZE]
}

/// `1/φ`: consecutive multiples of it modulo 1 are the most evenly
/// spread sequence in `[0, 1)` (each new one falls in the largest gap).
pub const GOLDEN: f32 = 0.618_034;

/// The dither offset of frame `n`: `frac(n / φ)`.
#[inline]
pub fn frame_offset(n: u32) -> f32 {
    let x = n as f64 * GOLDEN as f64;
    (x - x.floor()) as f32
}

/// The radical inverse of `index` in `base` (Halton 1964), in `[0, 1)`.
pub fn halton(mut index: u32, base: u32) -> f32 {
    let (mut f, mut r) = (1.0_f32, 0.0_f32);
    while index > 0 {
        f /= base as f32;
        r += f * (index % base) as f32;
        index /= base;
    }
    r
}

/// Frames in the jitter cycle.
pub const JITTER_CYCLE: u32 = 16;

/// The jitter of frame `n`: a sub-pixel ray offset in `[-0.5, 0.5)²`
/// pixels from Halton(2, 3), and the march-dither offset
/// [`frame_offset`], cycling every [`JITTER_CYCLE`] frames.
pub fn jitter(n: u32) -> [f32; 3] {
    let k = n % JITTER_CYCLE;
    let i = k + 1;
    [halton(i, 2) - 0.5, halton(i, 3) - 0.5, frame_offset(k)]
}

/// The Gaussian energy weights of every torus offset `(dx, dy)`.
fn energy_kernel() -> Vec<f64> {
    let mut k = vec![0.0; SIZE * SIZE];
    for dy in 0..SIZE {
        for dx in 0..SIZE {
            let wrap = |d: usize| d.min(SIZE - d) as f64;
            let r2 = wrap(dx).powi(2) + wrap(dy).powi(2);
            k[dy * SIZE + dx] = (-r2 / (2.0 * SIGMA * SIGMA)).exp();
        }
    }
    k
}

/// The energy field of a point set, kept up to date as points come and go.
struct Energy {
    kernel: Vec<f64>,
    field: Vec<f64>,
}

impl Energy {
    fn new() -> Self {
        Self {
            kernel: energy_kernel(),
            field: vec![0.0; SIZE * SIZE],
        }
    }

    /// Adds (`sign` 1) or removes (`sign` -1) a point at index `p`.
    fn splat(&mut self, p: usize, sign: f64) {
        let (px, py) = (p % SIZE, p / SIZE);
        for y in 0..SIZE {
            let dy = (y + SIZE - py) % SIZE;
            for x in 0..SIZE {
                let dx = (x + SIZE - px) % SIZE;
                self.field[y * SIZE + x] += sign * self.kernel[dy * SIZE + dx];
            }
        }
    }

    /// The index where `set[i] == want` with the highest (`highest`) or
    /// lowest energy; ties go to the lowest index (deterministic).
    fn extreme(&self, set: &[bool], want: bool, highest: bool) -> usize {
        let mut best = usize::MAX;
        for (i, (&e, &s)) in self.field.iter().zip(set).enumerate() {
            if s != want {
                continue;
            }
            if best == usize::MAX
                || (highest && e > self.field[best])
                || (!highest && e < self.field[best])
            {
                best = i;
            }
        }
        best
    }
}

/// Each pixel's rank in the void-and-cluster ordering of the tile.
fn void_and_cluster_ranks() -> Vec<u32> {
    let n = SIZE * SIZE;
    let mut set = vec![false; n];
    let mut energy = Energy::new();
    // A fixed-seed random start (xorshift), so the tile is the same bytes
    // on every machine.
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let initial = (n as f64 * INITIAL_FRACTION) as usize;
    let mut placed = 0;
    while placed < initial {
        let p = (next() % n as u64) as usize;
        if !set[p] {
            set[p] = true;
            energy.splat(p, 1.0);
            placed += 1;
        }
    }
    // Move the tightest cluster's point into the largest void until the
    // two coincide: the initial pattern is then evenly spread.
    loop {
        let cluster = energy.extreme(&set, true, true);
        set[cluster] = false;
        energy.splat(cluster, -1.0);
        let void = energy.extreme(&set, false, false);
        set[void] = true;
        energy.splat(void, 1.0);
        if void == cluster {
            break;
        }
    }
    let mut rank = vec![0_u32; n];
    // Rank the initial points by taking away the tightest cluster first.
    let mut prototype = set.clone();
    let mut proto_energy = Energy {
        kernel: energy.kernel.clone(),
        field: energy.field.clone(),
    };
    for r in (0..initial).rev() {
        let cluster = proto_energy.extreme(&prototype, true, true);
        prototype[cluster] = false;
        proto_energy.splat(cluster, -1.0);
        rank[cluster] = r as u32;
    }
    // The rest, by filling the largest void first (for a Gaussian
    // measure, the void of the ones is the cluster of the zeros).
    for r in initial..n {
        let void = energy.extreme(&set, false, false);
        set[void] = true;
        energy.splat(void, 1.0);
        rank[void] = r as u32;
    }
    rank
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ranks_are_a_permutation() {
        let mut seen = vec![false; SIZE * SIZE];
        for &v in tile() {
            let r = (v * (SIZE * SIZE) as f32 - 0.5).round() as usize;
            assert!(!seen[r], "rank {r} twice");
            seen[r] = true;
        }
    }

    /// Blue noise has little energy at low frequencies: averaged over 4x4
    /// blocks its values vary far less than white noise's would (white:
    /// the variance of a uniform over 16, 1/192).
    #[test]
    fn block_means_vary_far_less_than_white_noise() {
        let t = tile();
        let mut var = 0.0;
        let blocks = (SIZE / 4) * (SIZE / 4);
        for by in 0..SIZE / 4 {
            for bx in 0..SIZE / 4 {
                let mut m = 0.0;
                for y in 0..4 {
                    for x in 0..4 {
                        m += t[(by * 4 + y) * SIZE + bx * 4 + x] as f64 / 16.0;
                    }
                }
                var += (m - 0.5).powi(2) / blocks as f64;
            }
        }
        let white = 1.0 / 12.0 / 16.0;
        assert!(var < 0.2 * white, "block variance {var} vs white {white}");
    }

    /// Neighbours differ: the mean absolute difference of horizontal
    /// neighbours is above white noise's 1/3.
    #[test]
    fn neighbours_are_far_apart() {
        let t = tile();
        let mut sum = 0.0;
        for y in 0..SIZE {
            for x in 0..SIZE {
                sum += (t[y * SIZE + x] - t[y * SIZE + (x + 1) % SIZE]).abs() as f64;
            }
        }
        let mean = sum / (SIZE * SIZE) as f64;
        assert!(mean > 0.36, "mean neighbour difference {mean}");
    }

    /// The largest |correlation| of a 64x64 tile with itself, shifted by
    /// any lag of 2 to 8 pixels (torus).
    fn pattern(t: &[f32]) -> f64 {
        let m = t.iter().map(|&v| v as f64).sum::<f64>() / t.len() as f64;
        let var = t.iter().map(|&v| (v as f64 - m).powi(2)).sum::<f64>();
        let mut best: f64 = 0.0;
        for dy in 0..=8_usize {
            for dx in 0..=8_usize {
                if dx.max(dy) < 2 {
                    continue;
                }
                for sx in [1_i64, -1] {
                    let mut c = 0.0;
                    for y in 0..SIZE {
                        for x in 0..SIZE {
                            let x2 = (x as i64 + sx * dx as i64).rem_euclid(SIZE as i64) as usize;
                            let y2 = (y + dy) % SIZE;
                            c += (t[y * SIZE + x] as f64 - m) * (t[y2 * SIZE + x2] as f64 - m);
                        }
                    }
                    best = best.max((c / var).abs());
                }
            }
        }
        best
    }

    /// The dither has no structure beyond its nearest neighbours, unlike
    /// an interleaved gradient noise, whose values repeat along lines
    /// (they draw a checker and moire on cloud surfaces).
    #[test]
    fn the_dither_has_no_pattern_at_any_lag() {
        let blue = pattern(tile());
        let f = |v: f32| v - v.floor();
        let ign: Vec<f32> = (0..SIZE * SIZE)
            .map(|k| {
                let (x, y) = ((k % SIZE) as f32, (k / SIZE) as f32);
                f(52.982_918 * f(0.067_110_56 * x + 0.005_837_15 * y))
            })
            .collect();
        let old = pattern(&ign);
        eprintln!("largest correlation at lags 2-8: blue noise {blue:.3}, gradient noise {old:.3}");
        // Measured: blue noise 0.093, the gradient noise 0.852.
        assert!(blue < 0.15, "blue noise correlates {blue} at some lag");
        assert!(old > 0.5, "the old pattern correlates {old}");
    }

    #[test]
    fn frame_offsets_fill_the_unit_interval_evenly() {
        let mut v: Vec<f32> = (0..16).map(frame_offset).collect();
        v.sort_by(f32::total_cmp);
        let largest_gap = v
            .windows(2)
            .map(|w| w[1] - w[0])
            .chain([1.0 - v[15] + v[0]])
            .fold(0.0, f32::max);
        // 16 golden-ratio points leave no gap above about 2.6 / 16.
        assert!(largest_gap < 2.7 / 16.0, "largest gap {largest_gap}");
    }
}
