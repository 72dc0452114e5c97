//! SPH smoothing kernels (Müller, Charypar & Gross, "Particle-based fluid
//! simulation for interactive applications", SCA 2003), each in its own
//! file: [`Poly6`] for density, [`Spiky`] for the pressure gradient,
//! [`Viscosity`] for the viscosity Laplacian. All have compact support `h`.

mod poly6;
mod spiky;
mod viscosity;

pub use poly6::Poly6;
pub use spiky::Spiky;
pub use viscosity::Viscosity;

use glam::DVec3;

/// A radially symmetric smoothing kernel with support radius `h`.
pub trait Kernel {
    /// Kernel value `W(r, h)`, 1/m³.
    fn w(r: f64, h: f64) -> f64;
    /// Gradient of `W` with respect to `x_i` for `r_vec = x_i - x_j`
    /// (`r = |r_vec|`), 1/m⁴. Zero at `r = 0` (no direction).
    fn grad_w(r_vec: DVec3, r: f64, h: f64) -> DVec3;
    /// Laplacian of `W`, 1/m⁵.
    fn laplacian(r: f64, h: f64) -> f64;
}

#[cfg(test)]
pub(crate) mod test_support {
    /// `∫ f(r) 4π r² dr` over `[0, h]` by composite Simpson's rule.
    pub fn radial_integral(f: impl Fn(f64) -> f64, h: f64) -> f64 {
        let n = 20_000;
        let dr = h / n as f64;
        let g = |r: f64| f(r) * 4.0 * std::f64::consts::PI * r * r;
        let mut s = g(0.0) + g(h);
        for i in 1..n {
            s += g(i as f64 * dr) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        s * dr / 3.0
    }
}
