//! The endless sequence (the Video Textures idea as Iwasaki et al. use
//! it): after volume `k` comes volume `l` with probability
//! `∝ exp(-D(k+1, l) / σ)`, `D` the summed squared difference, so plain
//! playback (`l = k + 1`, `D = 0`) is the likeliest and a jump lands on a
//! volume like the one that would have come. The last volume has no
//! successor and must jump: to a volume like itself at least a quarter of
//! the database back ([`min_back`]). Without that rule the sequence fell
//! into the two-volume loop "last, the one before it" for good (Schödl et
//! al.'s dead end; their future-cost learning is the general cure). σ is
//! `similarity` times the mean distance between consecutive volumes. The sequence is
//! drawn from keyed random numbers, so it is the same for a seed, and it
//! never ends.

use serde::Serialize;

use super::Database;
use crate::sim::parcels::keyed_uniform;

/// An endless sequence over a database's volumes.
#[derive(Debug, Clone)]
pub struct Player {
    n: usize,
    /// `weights[k * n + l]`: the unnormalised odds of `l` after `k`.
    weights: Vec<f64>,
    seed: u64,
    sequence: Vec<usize>,
}

impl Player {
    /// The player of `db` with temperature `similarity` (times the mean
    /// step) and `seed`; it starts on volume 0.
    pub fn new(db: &Database, similarity: f64, seed: u64) -> Self {
        let n = db.len();
        let sigma = (similarity * db.mean_step()).max(1e-12);
        let mut weights = vec![0.0; n * n];
        for k in 0..n {
            // What would have come: k + 1, or k itself at the end.
            let like = if k + 1 < n { k + 1 } else { k };
            for l in 0..n {
                let allowed = if k + 1 < n {
                    l != k
                } else {
                    l + min_back(n) <= k
                };
                if allowed {
                    weights[k * n + l] = (-db.d(like, l) / sigma).exp();
                }
            }
        }
        Self {
            n,
            weights,
            seed,
            sequence: vec![0],
        }
    }

    /// The `step`-th volume of the sequence (drawn up to it on demand).
    pub fn volume(&mut self, step: usize) -> usize {
        while self.sequence.len() <= step {
            let k = *self.sequence.last().unwrap_or(&0);
            let row = &self.weights[k * self.n..(k + 1) * self.n];
            let total: f64 = row.iter().sum();
            let u = keyed_uniform(self.seed, self.sequence.len() as u64, 0, 0xe1d1) * total;
            let mut acc = 0.0;
            let mut next = if k + 1 < self.n { k + 1 } else { 0 };
            for (l, w) in row.iter().enumerate() {
                acc += w;
                if *w > 0.0 && u < acc {
                    next = l;
                    break;
                }
            }
            self.sequence.push(next);
        }
        self.sequence[step]
    }

    /// The pair shown at `t_s` seconds of playback and the weight of the
    /// second (the cross-dissolve across each interval).
    pub fn at(&mut self, t_s: f64, interval_s: f64) -> (usize, usize, f32) {
        let s = (t_s / interval_s).max(0.0);
        let step = s.floor() as usize;
        let (a, b) = (self.volume(step), self.volume(step + 1));
        (a, b, (s - step as f64) as f32)
    }
}

/// How far back the last volume's jump must land: a quarter of the
/// database (at least one volume).
pub fn min_back(n: usize) -> usize {
    (n / 4).max(1)
}

/// One similarity setting's playback statistics.
#[derive(Debug, Clone, Serialize)]
pub struct ThresholdRow {
    /// σ over the mean consecutive distance.
    pub similarity: f64,
    /// Steps played.
    pub steps: usize,
    /// Steps that were jumps (not `k -> k + 1`), per 100.
    pub jumps_per_100: f64,
    /// A jump's distance from what would have come, over the mean
    /// consecutive step: the mean over jumps and the largest (1: a jump
    /// is as big a change as plain playback).
    pub mean_jump: f64,
    pub max_jump: f64,
    /// Volumes the sequence ever showed, and in its second half (fewer:
    /// it has settled into a loop).
    pub distinct: usize,
    pub distinct_late: usize,
}

/// Plays `steps` steps for each similarity and measures the jumps.
pub fn threshold_sweep(
    db: &Database,
    similarities: &[f64],
    steps: usize,
    seed: u64,
) -> Vec<ThresholdRow> {
    let n = db.len();
    let mean_step = db.mean_step().max(1e-12);
    similarities
        .iter()
        .map(|&similarity| {
            let mut p = Player::new(db, similarity, seed);
            let mut seen = vec![false; n];
            let mut late = vec![false; n];
            let (mut jumps, mut sum, mut max) = (0usize, 0.0f64, 0.0f64);
            for s in 0..steps {
                let (k, l) = (p.volume(s), p.volume(s + 1));
                seen[k] = true;
                late[k] |= s >= steps / 2;
                if l != k + 1 {
                    jumps += 1;
                    let like = if k + 1 < n { k + 1 } else { k };
                    let j = db.d(like, l) / mean_step;
                    sum += j;
                    max = max.max(j);
                }
            }
            ThresholdRow {
                similarity,
                steps,
                jumps_per_100: 100.0 * jumps as f64 / steps.max(1) as f64,
                mean_jump: if jumps > 0 { sum / jumps as f64 } else { 0.0 },
                max_jump: max,
                distinct: seen.iter().filter(|x| **x).count(),
                distinct_late: late.iter().filter(|x| **x).count(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// A database of `n` one-voxel volumes of the given bytes.
    fn db_of(bytes: &[u8]) -> Database {
        let volumes: Vec<Vec<u8>> = bytes.iter().map(|b| vec![*b]).collect();
        Database {
            dims: [1, 1, 1],
            distance: super::super::distances(&volumes),
            volumes,
            interval_s: 10.0,
            origin: Vec3::ZERO,
            extent: Vec3::ONE,
            extinction_per_m: 0.1,
            build_s: 0.0,
        }
    }

    #[test]
    fn plain_playback_is_likeliest_and_the_end_jumps_to_its_like() {
        // A ramp: each volume a small step from the last; the last is
        // most like the one before it.
        let db = db_of(&[0, 10, 20, 30, 40, 50, 60, 70]);
        let mut p = Player::new(&db, 0.5, 3);
        let seq: Vec<usize> = (0..400).map(|s| p.volume(s)).collect();
        let plain = seq.windows(2).filter(|w| w[1] == w[0] + 1).count();
        assert!(plain > 200, "{plain} plain steps of 399");
        // Never stuck on one volume; the end jumps back a quarter of the
        // database (2 of 8) or more, to the nearest allowed.
        assert!(seq.windows(2).all(|w| w[0] != w[1]));
        for w in seq.windows(2).filter(|w| w[0] == 7) {
            assert!(w[1] == 5 || w[1] == 4, "from the end to {}", w[1]);
        }
    }

    #[test]
    fn a_seed_gives_one_sequence_and_the_dissolve_spans_an_interval() {
        let db = db_of(&[0, 10, 20, 30, 40]);
        let mut a = Player::new(&db, 1.0, 9);
        let mut b = Player::new(&db, 1.0, 9);
        let sa: Vec<usize> = (0..100).map(|s| a.volume(s)).collect();
        let sb: Vec<usize> = (0..100).map(|s| b.volume(s)).collect();
        assert_eq!(sa, sb);
        let mut c = Player::new(&db, 1.0, 10);
        let sc: Vec<usize> = (0..100).map(|s| c.volume(s)).collect();
        assert_ne!(sa, sc);
        let (x, y, w) = a.at(25.0, 10.0);
        assert_eq!((x, y), (sa[2], sa[3]));
        assert!((w - 0.5).abs() < 1e-6);
    }

    #[test]
    fn a_lower_temperature_jumps_less_far() {
        let db = db_of(&[0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 110]);
        let rows = threshold_sweep(&db, &[0.1, 1.0, 10.0], 2000, 5);
        assert!(rows[0].jumps_per_100 < rows[1].jumps_per_100, "{rows:?}");
        assert!(rows[1].jumps_per_100 < rows[2].jumps_per_100, "{rows:?}");
        assert!(rows[0].max_jump < rows[2].max_jump, "{rows:?}");
        // Too cold, the end's forced jump (3 back, to 8) is the only one:
        // the sequence settles into the loop 8..=11.
        assert_eq!(rows[0].distinct_late, 4, "{rows:?}");
        assert!((rows[0].max_jump - 9.0).abs() < 1e-9, "{rows:?}");
        assert_eq!(rows[2].distinct_late, 12, "{rows:?}");
    }
}
