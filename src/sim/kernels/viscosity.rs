use std::f64::consts::PI;

use glam::DVec3;

use super::Kernel;

/// Viscosity kernel, `W = 15/(2π h³) (-r³/(2h³) + r²/h² + h/(2r) - 1)`
/// (Müller 2003, Eq. 22), whose Laplacian `45 / (π h⁶) (h - r)` is positive
/// everywhere, so viscosity only ever damps relative motion.
pub struct Viscosity;

impl Kernel for Viscosity {
    #[inline]
    fn w(r: f64, h: f64) -> f64 {
        if r >= h || r <= 0.0 {
            return 0.0;
        }
        let q = r / h;
        15.0 / (2.0 * PI * h.powi(3)) * (-0.5 * q * q * q + q * q + 0.5 / q - 1.0)
    }

    #[inline]
    fn grad_w(r_vec: DVec3, r: f64, h: f64) -> DVec3 {
        if r >= h || r <= 0.0 {
            return DVec3::ZERO;
        }
        let dw_dr = 15.0 / (2.0 * PI * h.powi(3))
            * (-1.5 * r * r / h.powi(3) + 2.0 * r / (h * h) - 0.5 * h / (r * r));
        r_vec * (dw_dr / r)
    }

    #[inline]
    fn laplacian(r: f64, h: f64) -> f64 {
        if r >= h {
            return 0.0;
        }
        45.0 / (PI * h.powi(6)) * (h - r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::kernels::test_support::radial_integral;

    #[test]
    fn viscosity_kernel_integrates_to_one() {
        // The 1/r singularity is integrable (r² dr cancels it).
        let i = radial_integral(|r| Viscosity::w(r.max(1e-12), 5.0), 5.0);
        assert!((i - 1.0).abs() < 1e-6, "{i}");
    }

    #[test]
    fn viscosity_laplacian_is_positive_inside_support() {
        for r in [0.0, 0.5, 2.0, 4.99] {
            assert!(Viscosity::laplacian(r, 5.0) > 0.0);
        }
        assert_eq!(Viscosity::laplacian(5.0, 5.0), 0.0);
    }
}
