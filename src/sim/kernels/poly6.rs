use std::f64::consts::PI;

use glam::DVec3;

use super::Kernel;

/// Poly6 kernel, `W = 315 / (64 π h⁹) (h² - r²)³` for `r <= h` (Müller 2003,
/// Eq. 20). Smooth at 0, used for the density estimate.
pub struct Poly6;

impl Kernel for Poly6 {
    #[inline]
    fn w(r: f64, h: f64) -> f64 {
        if r >= h {
            return 0.0;
        }
        let d = h * h - r * r;
        315.0 / (64.0 * PI * h.powi(9)) * d * d * d
    }

    #[inline]
    fn grad_w(r_vec: DVec3, r: f64, h: f64) -> DVec3 {
        if r >= h {
            return DVec3::ZERO;
        }
        let d = h * h - r * r;
        r_vec * (-945.0 / (32.0 * PI * h.powi(9)) * d * d)
    }

    #[inline]
    fn laplacian(r: f64, h: f64) -> f64 {
        if r >= h {
            return 0.0;
        }
        let (h2, r2) = (h * h, r * r);
        -945.0 / (32.0 * PI * h.powi(9)) * (h2 - r2) * (3.0 * h2 - 7.0 * r2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::kernels::test_support::radial_integral;

    #[test]
    fn poly6_integrates_to_one() {
        for h in [1.0, 250.0, 1200.0] {
            let i = radial_integral(|r| Poly6::w(r, h), h);
            assert!((i - 1.0).abs() < 1e-9, "h={h}: {i}");
        }
    }
}
