use std::f64::consts::PI;

use glam::DVec3;

use super::Kernel;

/// Spiky kernel, `W = 15 / (π h⁶) (h - r)³` for `r <= h` (Müller 2003,
/// Eq. 21; Desbrun & Gascuel 1996). Its gradient does not vanish as `r -> 0`,
/// so close parcels keep repelling: used for the pressure force.
pub struct Spiky;

impl Kernel for Spiky {
    #[inline]
    fn w(r: f64, h: f64) -> f64 {
        if r >= h {
            return 0.0;
        }
        let d = h - r;
        15.0 / (PI * h.powi(6)) * d * d * d
    }

    #[inline]
    fn grad_w(r_vec: DVec3, r: f64, h: f64) -> DVec3 {
        if r >= h || r <= 0.0 {
            return DVec3::ZERO;
        }
        let d = h - r;
        r_vec * (-45.0 / (PI * h.powi(6)) * d * d / r)
    }

    #[inline]
    fn laplacian(r: f64, h: f64) -> f64 {
        if r >= h || r <= 0.0 {
            return 0.0;
        }
        -90.0 / (PI * h.powi(6)) * (h - r) * (h - 2.0 * r) / r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::kernels::test_support::radial_integral;

    #[test]
    fn spiky_integrates_to_one() {
        for h in [1.0, 600.0] {
            let i = radial_integral(|r| Spiky::w(r, h), h);
            assert!((i - 1.0).abs() < 1e-9, "h={h}: {i}");
        }
    }

    #[test]
    fn spiky_gradient_matches_finite_difference() {
        let h = 10.0;
        let x = DVec3::new(3.0, 1.0, -2.0);
        let g = Spiky::grad_w(x, x.length(), h);
        let eps = 1e-6;
        let fd = (Spiky::w((x + DVec3::X * eps).length(), h)
            - Spiky::w((x - DVec3::X * eps).length(), h))
            / (2.0 * eps);
        assert!(
            (g.x - fd).abs() < 1e-9 * fd.abs().max(1e-12) + 1e-12,
            "{} vs {fd}",
            g.x
        );
    }
}
