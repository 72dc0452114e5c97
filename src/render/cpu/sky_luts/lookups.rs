//! What a renderer reads: the sky's radiance through the sky-view table or
//! marched, aerial perspective, the sun's transmitted irradiance and its
//! limb-darkened disk.

use std::f32::consts::PI;

use glam::Vec3;

use super::atmosphere::{azimuth_from_sun, distance_to_boundary, radius_at_altitude, sky_ray};
use super::tables::{
    SKY_VIEW_STEPS, SkyLuts, integrate_scattering, sky_view_texel_coords, transmittance_to_sun,
};

/// Steps of [`aerial_perspective`]'s march.
pub const AERIAL_PERSPECTIVE_STEPS: u32 = 10;
/// Linear limb-darkening coefficient of the sun disk, `I(μ) = 1 - u(1 - μ)`
/// (the visible-band solar value, Eddington's grey atmosphere: 0.6).
pub const LIMB_DARKENING_U: f32 = 0.6;

/// The sky's radiance along unit world `dir` from the table's camera (no
/// sun disk); `sun_dir` must be the sun the table was built for (its
/// azimuth is read here, its elevation was baked in).
#[inline]
pub fn sky_view_radiance(luts: &SkyLuts, dir: Vec3, sun_dir: Vec3) -> Vec3 {
    let r = radius_at_altitude(luts.camera_altitude_m, &luts.params);
    let (fx, fy, lo, hi) =
        sky_view_texel_coords(dir.y, azimuth_from_sun(dir, sun_dir), r, &luts.params);
    luts.sky_view.sample_texels(fx, fy, lo, hi)
}

/// The same radiance marched directly (no sky-view table), from `altitude_m`.
pub fn sky_radiance_marched(luts: &SkyLuts, altitude_m: f32, dir: Vec3, sun_dir: Vec3) -> Vec3 {
    let p = &luts.params;
    let ray = sky_ray(altitude_m, dir, sun_dir, p);
    let t_max = distance_to_boundary(ray.r, ray.mu, p);
    let (t, ms) = (&luts.transmittance, &luts.multi_scattering);
    integrate_scattering(ray, t_max, SKY_VIEW_STEPS, p, t, ms).0 * p.sun_irradiance
}

/// Aerial perspective over `distance_m` from `altitude_m` along world `dir`
/// (clamped to where the ray leaves the atmosphere): (inscattered radiance,
/// transmittance). Cost: [`AERIAL_PERSPECTIVE_STEPS`] steps, each two
/// table reads (8 texel loads) and 9 exp (medium, step, step integral):
/// 80 loads and ~90 exp per call, 1.5 µs on one CPU core.
pub fn aerial_perspective(
    luts: &SkyLuts,
    altitude_m: f32,
    dir: Vec3,
    distance_m: f32,
    sun_dir: Vec3,
) -> (Vec3, Vec3) {
    let p = &luts.params;
    let ray = sky_ray(altitude_m, dir, sun_dir, p);
    let t_max = (distance_m * 1e-3).clamp(0.0, distance_to_boundary(ray.r, ray.mu, p));
    let (t, ms) = (&luts.transmittance, &luts.multi_scattering);
    let (inscatter, view) = integrate_scattering(ray, t_max, AERIAL_PERSPECTIVE_STEPS, p, t, ms);
    (inscatter * p.sun_irradiance, view)
}

/// The sun's irradiance reaching `altitude_m` (0 once the disk has set).
#[inline]
pub fn sun_radiance_at(luts: &SkyLuts, altitude_m: f32, sun_dir: Vec3) -> Vec3 {
    let p = &luts.params;
    let r = radius_at_altitude(altitude_m, p);
    transmittance_to_sun(&luts.transmittance, r, sun_dir.y, p) * p.sun_irradiance
}

/// The sun disk's radiance along `dir` (0 off the disk) for a transmitted
/// `irradiance` ([`sun_radiance_at`]), limb-darkened by the linear law
/// [`LIMB_DARKENING_U`], normalised so its integral over the disk is
/// `irradiance`. With x² = (1 - cos θ)/(1 - cos α) (exactly the fraction of
/// the disk's solid angle Ω inside θ) and μ = sqrt(1 - x²), the mean of
/// 1 - u(1 - μ) over the disk is 1 - u/3.
#[inline]
pub fn sun_disk_radiance(
    dir: Vec3,
    sun_dir: Vec3,
    irradiance: Vec3,
    angular_radius_rad: f32,
) -> Vec3 {
    let one_minus_cos = 0.5 * (dir - sun_dir).length_squared();
    let half = (0.5 * angular_radius_rad).sin();
    let cap = 2.0 * half * half;
    if one_minus_cos >= cap {
        return Vec3::ZERO;
    }
    let mu = (1.0 - one_minus_cos / cap).sqrt();
    let solid_angle = 2.0 * PI * cap;
    irradiance * (1.0 - LIMB_DARKENING_U * (1.0 - mu))
        / (solid_angle * (1.0 - LIMB_DARKENING_U / 3.0))
}
