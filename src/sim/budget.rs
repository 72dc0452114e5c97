//! The water budget: every kilogram of water a parcel takes from or gives
//! to the environment is counted, with compensated (Neumaier) sums so that
//! the books close to round-off over a day of simulated time.

/// A Neumaier compensated sum.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CompensatedSum {
    sum: f64,
    carry: f64,
}

impl CompensatedSum {
    /// Adds `x`.
    #[inline]
    pub fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if self.sum.abs() >= x.abs() {
            self.carry += (self.sum - t) + x;
        } else {
            self.carry += (x - t) + self.sum;
        }
        self.sum = t;
    }

    /// Adds another compensated sum.
    #[inline]
    pub fn merge(&mut self, other: &Self) {
        self.add(other.sum);
        self.add(other.carry);
    }

    /// The sum.
    #[inline]
    pub fn value(&self) -> f64 {
        self.sum + self.carry
    }
}

/// Water in and out of the parcels since the start, kg.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaterBudget {
    /// Water (vapour + condensate) the parcels held at the start, kg.
    pub initial_kg: f64,
    /// Water the parcels hold now, kg.
    pub parcels_kg: f64,
    /// Water taken from the environment (entrainment, re-birth), kg.
    pub entrained_kg: f64,
    /// Water given to the environment (detrainment, spent parcels), kg.
    pub detrained_kg: f64,
}

impl WaterBudget {
    /// `initial + entrained - detrained - now`, kg: zero when the books close.
    pub fn residual_kg(&self) -> f64 {
        let mut s = CompensatedSum::default();
        s.add(self.initial_kg);
        s.add(self.entrained_kg);
        s.add(-self.detrained_kg);
        s.add(-self.parcels_kg);
        s.value()
    }

    /// The residual relative to all water that passed through the parcels
    /// (initial + entrained); 0 when there is no water at all.
    pub fn relative_residual(&self) -> f64 {
        let scale = self.initial_kg.abs() + self.entrained_kg.abs() + self.detrained_kg.abs();
        if scale > 0.0 {
            self.residual_kg().abs() / scale
        } else {
            self.residual_kg().abs()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compensated_sum_keeps_small_terms() {
        let mut s = CompensatedSum::default();
        s.add(1e16);
        for _ in 0..1000 {
            s.add(1.0);
        }
        s.add(-1e16);
        assert_eq!(s.value(), 1000.0);
    }
}
