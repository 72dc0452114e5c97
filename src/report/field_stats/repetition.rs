//! Whether the sky visibly repeats: the cloud mask seen from above over
//! several periods of the map, correlated with itself shifted by one
//! period and by lags of the same length in other directions.

use super::Mask;

/// The mask's correlation at one shift.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Lag {
    /// Shift in cells, `(dx, dy)`.
    pub cells: (i64, i64),
    /// Pearson correlation of the mask with its shifted self (1: the same
    /// pattern; 0: unrelated).
    pub correlation: f64,
}

/// The correlation at the map's period against other lags of its length.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Repetition {
    /// Shifts by one period along x and along z.
    pub at_period: Vec<Lag>,
    /// Shifts of the same length in ten other directions: 15° to 165°
    /// every 15°, leaving out 90° (the other period).
    pub other: Vec<Lag>,
}

impl Repetition {
    /// The highest correlation at the period.
    pub fn period_max(&self) -> f64 {
        self.at_period
            .iter()
            .map(|l| l.correlation)
            .fold(f64::MIN, f64::max)
    }

    /// The highest correlation at the other lags.
    pub fn other_max(&self) -> f64 {
        self.other
            .iter()
            .map(|l| l.correlation)
            .fold(f64::MIN, f64::max)
    }

    /// No visible repetition: the period correlates no more than some
    /// other lag of the same length.
    pub fn hidden(&self) -> bool {
        self.period_max() <= self.other_max()
    }
}

/// Pearson correlation of `m` with `m` shifted by `(dx, dy)` cells, over
/// the cells where both are inside the mask (no wrap: the mask spans
/// several periods and is not itself periodic).
pub fn correlation(m: &Mask, dx: i64, dy: i64) -> f64 {
    let (w, h) = (m.width as i64, m.height as i64);
    let (mut n, mut sa, mut sb, mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for y in 0.max(-dy)..h.min(h - dy) {
        for x in 0.max(-dx)..w.min(w - dx) {
            let a = f64::from(u8::from(m.cells[(y * w + x) as usize]));
            let b = f64::from(u8::from(m.cells[((y + dy) * w + x + dx) as usize]));
            n += 1.0;
            sa += a;
            sb += b;
            sab += a * b;
            saa += a * a;
            sbb += b * b;
        }
    }
    if n < 1.0 {
        return 0.0;
    }
    let cov = sab / n - (sa / n) * (sb / n);
    let va = saa / n - (sa / n).powi(2);
    let vb = sbb / n - (sb / n).powi(2);
    if va <= 0.0 || vb <= 0.0 {
        return 0.0;
    }
    cov / (va * vb).sqrt()
}

/// The repetition measure of a mask whose period is `period_cells`.
pub fn repetition(m: &Mask, period_cells: usize) -> Repetition {
    let p = period_cells as f64;
    let lag = |deg: f64| {
        let (s, c) = deg.to_radians().sin_cos();
        let cells = ((p * c).round() as i64, (p * s).round() as i64);
        Lag {
            cells,
            correlation: correlation(m, cells.0, cells.1),
        }
    };
    Repetition {
        at_period: vec![lag(0.0), lag(90.0)],
        other: [
            15.0, 30.0, 45.0, 60.0, 75.0, 105.0, 120.0, 135.0, 150.0, 165.0,
        ]
        .iter()
        .map(|&d| lag(d))
        .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mask(w: usize, h: usize, f: impl Fn(usize, usize) -> bool) -> Mask {
        Mask::from_fn(w, h, 1.0, f)
    }

    /// A tiled pattern repeats at its period and nowhere else; a pattern
    /// that does not tile does not.
    #[test]
    fn a_tiled_pattern_is_seen_and_an_untiled_one_is_not() {
        let hash = |x: usize, y: usize| {
            let h = (x as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
                ^ (y as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
            (h ^ (h >> 29)).wrapping_mul(0x1656_67b1_9e37_79f9) >> 61 == 0
        };
        // Blobs 4 cells wide from a hash, tiled every 40 cells.
        let tiled = mask(160, 160, |x, y| hash((x % 40) / 4, (y % 40) / 4));
        let r = repetition(&tiled, 40);
        assert!(r.period_max() > 0.99 && !r.hidden(), "{r:?}");
        let untiled = mask(160, 160, |x, y| hash(x / 4, y / 4));
        let r = repetition(&untiled, 40);
        assert!(r.period_max() < 0.05, "{r:?}");
    }
}
