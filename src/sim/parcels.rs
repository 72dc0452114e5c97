//! Parcel state as a struct of arrays, and the seeded, order-independent
//! random draws that place and re-birth parcels.

use glam::DVec3;

use super::budget::CompensatedSum;

/// Diagnosed thermodynamics of a parcel (recomputed from `θ_l`, `q_t` and
/// height after every sub-step).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Diag {
    /// Temperature, K.
    pub t_k: f64,
    /// Vapour mixing ratio, kg/kg.
    pub qv: f64,
    /// Condensate mixing ratio, kg/kg.
    pub qc: f64,
    /// Virtual potential temperature of the parcel, K.
    pub theta_v: f64,
    /// Virtual potential temperature of the environment at the parcel, K.
    pub theta_v_env: f64,
    /// Buoyancy `g (θ_v - θ_v,env) / θ_v,env`, m/s².
    pub buoyancy: f64,
}

/// Life-cycle bookkeeping of a parcel.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Life {
    /// Radius, m.
    pub radius_m: f64,
    /// Mass of air, kg (constant through a life).
    pub mass_kg: f64,
    /// Time since release, s; negative while waiting to be released.
    pub age_s: f64,
    /// Largest condensate of this life, kg/kg.
    pub peak_qc: f64,
    /// How many times this parcel was re-born.
    pub generation: u32,
    /// Water taken from the environment during this life, kg.
    pub entrained_kg: CompensatedSum,
    /// Water given to the environment during this life, kg.
    pub detrained_kg: CompensatedSum,
}

impl Life {
    /// Released: taking part in the physics.
    #[inline]
    pub fn released(&self) -> bool {
        self.age_s >= 0.0
    }
}

/// All parcels, one array per quantity (struct of arrays).
#[derive(Debug, Clone, Default)]
pub struct Parcels {
    /// Positions, m: `x, y` in `[0, domain)` (periodic), `z` above ground.
    pub pos: Vec<DVec3>,
    /// Velocities, m/s.
    pub vel: Vec<DVec3>,
    /// Liquid-water potential temperature, K (conserved by motion).
    pub theta_l: Vec<f64>,
    /// Total water, kg/kg (conserved by motion).
    pub qt: Vec<f64>,
    /// Diagnosed thermodynamics.
    pub diag: Vec<Diag>,
    /// Life cycle.
    pub life: Vec<Life>,
}

impl Parcels {
    /// Number of parcels.
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    /// No parcels.
    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    /// Water held by all parcels, kg (compensated sum).
    pub fn water_kg(&self) -> f64 {
        let mut s = CompensatedSum::default();
        for (q, l) in self.qt.iter().zip(&self.life) {
            s.add(q * l.mass_kg);
        }
        s.value()
    }
}

/// A uniform draw in `[0, 1)` keyed by `(seed, parcel, generation, stream)`:
/// SplitMix64 finalisers over the key. Keyed rather than sequential, so a
/// parcel's draws do not depend on the order in which parcels are visited or
/// on the thread count (determinism for a given seed).
pub fn keyed_uniform(seed: u64, parcel: u64, generation: u32, stream: u32) -> f64 {
    let mut x = seed ^ 0x9E37_79B9_7F4A_7C15;
    for k in [parcel, u64::from(generation), u64::from(stream)] {
        x = splitmix(x ^ splitmix(k.wrapping_add(0x632B_E59B_D9B4_E019)));
    }
    (x >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

fn splitmix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keyed_uniform_is_uniform_and_keyed() {
        let n = 20_000;
        let mean = (0..n).map(|i| keyed_uniform(7, i, 0, 0)).sum::<f64>() / n as f64;
        // Standard error of the mean of U(0,1) over 20k draws is 0.002.
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
        assert_ne!(keyed_uniform(7, 1, 0, 0), keyed_uniform(7, 1, 1, 0));
        assert_ne!(keyed_uniform(7, 1, 0, 0), keyed_uniform(8, 1, 0, 0));
        assert_eq!(keyed_uniform(7, 1, 2, 3), keyed_uniform(7, 1, 2, 3));
    }
}
