//! Light: phase functions, sun transmittance by a secondary march,
//! multiple-scattering octaves and the energy-conserving step
//! (README, "The renderer").

use std::f32::consts::PI;

use glam::Vec3;

use super::density::{DensityParams, Fields, density_at, height_fraction};

/// Henyey-Greenstein phase function, 1/sr; integrates to 1 over the sphere.
#[inline]
pub fn phase_hg(cos_theta: f32, g: f32) -> f32 {
    let g2 = g * g;
    (1.0 - g2) / (4.0 * PI * (1.0 + g2 - 2.0 * g * cos_theta).max(1e-6).powf(1.5))
}

/// Dual-lobe HG: a strong forward lobe (silver lining) and a weak back lobe.
#[inline]
pub fn phase_dual(cos_theta: f32, eccentricity: f32) -> f32 {
    0.75 * phase_hg(cos_theta, 0.8 * eccentricity) + 0.25 * phase_hg(cos_theta, -0.3 * eccentricity)
}

/// The longest shadow ray toward the sun, m (`SHADOW_RAY_M` in WGSL).
pub const SHADOW_RAY_M: f32 = 2000.0;

/// The length of the shadow ray from `p` toward the sun: to the band's
/// top, at most [`SHADOW_RAY_M`] (along a sun at or below the horizon,
/// that).
#[inline]
pub fn shadow_ray_length(p: Vec3, sun_dir: Vec3, d: &DensityParams) -> f32 {
    let to_top = if sun_dir.y > 1e-3 {
        (d.band_top_m - p.y).max(0.0) / sun_dir.y
    } else {
        SHADOW_RAY_M
    };
    to_top.min(SHADOW_RAY_M)
}

/// The sum of the shadow ray's step weights, `Σ_{k=1..steps} √k`: step
/// `i` (from 0) is `√(i + 1) / shadow_parts(steps)` of the ray.
#[inline]
pub fn shadow_parts(steps: u32) -> f32 {
    let mut parts = 0.0;
    for k in 1..=steps {
        parts += (k as f32).sqrt();
    }
    parts
}

/// Optical depth (dimensionless) from `p` toward the sun through the band,
/// by `steps` samples whose lengths grow as `√1, √2, √3, ...` parts
/// ([`shadow_parts`]) over at most [`SHADOW_RAY_M`]: fine near `p`, where
/// a cloud's own edge decides its light, without the long far steps of a
/// linear growth, which step over small wisps. Reading the density as the primary march
/// does (the detail noise included, at the level of detail of
/// `footprint_m`, the primary sample's). The path tracer measured what
/// leaving the detail out costs (docs/ground_truth): its mean stands in
/// for the noise, small eroded wisps vanish from the shadow, and backlit
/// clouds glowed 7 times too bright. Few long steps leak the same way
/// (they step over the wisps): the default is 20 (`render.shadow_steps`).
#[inline]
pub fn sun_optical_depth(
    p: Vec3,
    sun_dir: Vec3,
    steps: u32,
    footprint_m: f32,
    f: &Fields,
    d: &DensityParams,
) -> f32 {
    if steps == 0 {
        return 0.0;
    }
    let length = shadow_ray_length(p, sun_dir, d);
    let parts = shadow_parts(steps);
    let mut t = 0.0;
    let mut tau = 0.0;
    for i in 0..steps {
        let dt = length * ((i + 1) as f32).sqrt() / parts;
        let q = p + sun_dir * (t + 0.5 * dt);
        if height_fraction(q.y, d) > 1.0 {
            break;
        }
        tau += density_at(q, f, d, true, footprint_m) * dt;
        t += dt;
    }
    tau
}

/// Transmittance toward the sun, in `[0, 1]`.
#[inline]
pub fn sun_transmittance(
    p: Vec3,
    sun_dir: Vec3,
    steps: u32,
    footprint_m: f32,
    f: &Fields,
    d: &DensityParams,
) -> f32 {
    (-sun_optical_depth(p, sun_dir, steps, footprint_m, f, d)).exp()
}

/// Per octave of multiple scattering, the factor on the scattered light
/// (Wrenninge 2013's `a`; `OCTAVE_SCATTERING` in WGSL).
pub const OCTAVE_SCATTERING: f32 = 0.67;
/// Per octave, the factor on the optical depth toward the sun (`b`): the
/// light of later octaves has diffused around what blocks the direct beam.
pub const OCTAVE_EXTINCTION: f32 = 0.32;
/// Per octave, the factor on the phase function's eccentricity (`c`):
/// multiply scattered light forgets the sun's direction.
pub const OCTAVE_ECCENTRICITY: f32 = 0.55;
/// The multiple-scattering octaves' gain at a sun in the zenith.
pub const MULTIPLE_GAIN: f32 = 1.1;
/// The octaves scale with the sun's height as `sin(elevation)^MULTIPLE_SUN_POWER`:
/// the light that a layer of cloud takes in, and so diffuses, is the sun's
/// flux through its horizontal extent, which falls with the sun.
pub const MULTIPLE_SUN_POWER: f32 = 0.4;

/// Sun light scattered toward the eye per unit scattering coefficient:
/// single scattering (`phase_dual` through the optical depth `tau_sun`)
/// and `octaves` octaves of multiple scattering (Wrenninge 2013: octave
/// `i` scatters `a^i` of the light through `b^i` of the optical depth with
/// `c^i` of the eccentricity), the octaves weighted by [`MULTIPLE_GAIN`]
/// and the sun's height `mu_sun` (`sin` of its elevation) to the power
/// [`MULTIPLE_SUN_POWER`].
///
/// The five constants were fitted to Mitsuba 3's volumetric path tracer
/// (all orders of scattering) on three views, a high sun, a low sun and a
/// backlit view, with the ambient's [`super::renderer::AMBIENT_GAIN`]
/// (docs/ground_truth). With Wrenninge's halving (`a = b = c = 0.5`)
/// deep cloud under a high sun was half as bright as the path tracer's.
#[inline]
pub fn sun_scattering(tau_sun: f32, cos_theta: f32, mu_sun: f32, octaves: u32) -> f32 {
    let mut sum = phase_dual(cos_theta, 1.0) * (-tau_sun).exp();
    let gain = MULTIPLE_GAIN * mu_sun.max(0.0).powf(MULTIPLE_SUN_POWER);
    let (mut a, mut b, mut c) = (1.0, 1.0, 1.0);
    for _ in 0..octaves {
        a *= OCTAVE_SCATTERING;
        b *= OCTAVE_EXTINCTION;
        c *= OCTAVE_ECCENTRICITY;
        sum += gain * a * phase_dual(cos_theta, c) * (-b * tau_sun).exp();
    }
    sum
}

/// Energy-conserving integral of in-scattered light `s` over a step of
/// length `dt` with extinction `sigma_t` (Hillaire 2016):
/// `(s - s e^{-σ Δ}) / σ`; tends to `s Δ` as σ -> 0.
#[inline]
pub fn integrate_step(s: Vec3, sigma_t: f32, dt: f32) -> Vec3 {
    if sigma_t * dt < 1e-5 {
        return s * dt;
    }
    (s - s * (-sigma_t * dt).exp()) / sigma_t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hg_phase_integrates_to_one() {
        for g in [-0.5, 0.0, 0.3, 0.8, 0.95] {
            let n = 200_000;
            // ∫ p(cos θ) 2π d(cos θ) over [-1, 1], midpoint rule.
            let s: f64 = (0..n)
                .map(|i| {
                    let mu = -1.0 + (i as f64 + 0.5) * 2.0 / n as f64;
                    phase_hg(mu as f32, g) as f64 * 2.0 * std::f64::consts::PI * 2.0 / n as f64
                })
                .sum();
            assert!((s - 1.0).abs() < 2e-3, "g={g}: {s}");
        }
    }

    #[test]
    fn integrate_step_conserves_energy() {
        // Emitted light over a thick step saturates at s/σ, never more.
        let s = Vec3::splat(2.0);
        let i = integrate_step(s, 0.5, 1000.0);
        assert!((i.x - 4.0).abs() < 1e-5);
        let small = integrate_step(s, 1e-9, 3.0);
        assert!((small.x - 6.0).abs() < 1e-4);
    }
}
