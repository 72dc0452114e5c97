//! The atmosphere itself: its parameters, the medium at an altitude, the
//! phase functions, and the geometry of rays over a spherical planet (km).

use std::f32::consts::PI;

use glam::Vec3;

/// The atmosphere (defaults: Hillaire 2020's Earth, Bruneton 2017's ozone).
/// RGB channels stand for 680, 550 and 440 nm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyParams {
    /// Planet (ground) radius, km. Domain > 0. Default 6360.
    pub ground_radius_km: f32,
    /// Radius of the top of the atmosphere, km. Domain > ground. Default 6460.
    pub top_radius_km: f32,
    /// Rayleigh scattering at the ground, 1/km. Domain >= 0.
    /// Default (5.802, 13.558, 33.1)e-3.
    pub rayleigh_scattering: Vec3,
    /// Rayleigh scale height, km. Domain > 0. Default 8.
    pub rayleigh_scale_height_km: f32,
    /// Mie scattering at the ground, 1/km. Domain >= 0. Default 3.996e-3.
    pub mie_scattering: f32,
    /// Mie extinction at the ground, 1/km. Domain >= mie_scattering.
    /// Default 4.40e-3.
    pub mie_extinction: f32,
    /// Mie scale height, km. Domain > 0. Default 1.2.
    pub mie_scale_height_km: f32,
    /// Cornette-Shanks asymmetry of Mie scattering. Domain (-1, 1). Default 0.8.
    pub mie_g: f32,
    /// Ozone absorption at the layer's peak, 1/km. Domain >= 0.
    /// Default (0.650, 1.881, 0.085)e-3.
    pub ozone_absorption: Vec3,
    /// Altitude of the ozone tent's peak, km. Domain >= 0. Default 25.
    pub ozone_center_km: f32,
    /// Full width of the ozone tent, km (zero outside centre ± width/2).
    /// Domain > 0. Default 30.
    pub ozone_width_km: f32,
    /// Lambertian ground albedo. Domain 0..=1. Default 0.3 (grey).
    pub ground_albedo: Vec3,
    /// Solar irradiance at the top of the atmosphere, relative units.
    /// Domain >= 0. Default 8 (the renderer's `SUN_INTENSITY`).
    pub sun_irradiance: Vec3,
    /// Angular radius of the sun disk, degrees. Domain > 0. Default 0.2678.
    pub sun_angular_radius_deg: f32,
}

impl Default for SkyParams {
    fn default() -> Self {
        Self {
            ground_radius_km: 6360.0,
            top_radius_km: 6460.0,
            rayleigh_scattering: Vec3::new(5.802, 13.558, 33.1) * 1e-3,
            rayleigh_scale_height_km: 8.0,
            mie_scattering: 3.996e-3,
            mie_extinction: 4.40e-3,
            mie_scale_height_km: 1.2,
            mie_g: 0.8,
            ozone_absorption: Vec3::new(0.650, 1.881, 0.085) * 1e-3,
            ozone_center_km: 25.0,
            ozone_width_km: 30.0,
            ground_albedo: Vec3::splat(0.3),
            sun_irradiance: Vec3::splat(8.0),
            sun_angular_radius_deg: 0.2678,
        }
    }
}

/// The air at one altitude, 1/km.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Medium {
    /// Rayleigh scattering.
    pub rayleigh_scattering: Vec3,
    /// Mie scattering (grey).
    pub mie_scattering: f32,
    /// Extinction: Rayleigh scattering, Mie extinction, ozone absorption.
    pub extinction: Vec3,
}

impl Medium {
    /// Total scattering, Rayleigh plus Mie.
    #[inline]
    pub fn scattering(&self) -> Vec3 {
        self.rayleigh_scattering + Vec3::splat(self.mie_scattering)
    }
}

/// The medium at `altitude_km` above the ground (clamped at 0).
#[inline]
pub fn medium_at(altitude_km: f32, p: &SkyParams) -> Medium {
    let h = altitude_km.max(0.0);
    let rayleigh = (-h / p.rayleigh_scale_height_km).exp();
    let mie = (-h / p.mie_scale_height_km).exp();
    let ozone = (1.0 - (h - p.ozone_center_km).abs() / (0.5 * p.ozone_width_km)).max(0.0);
    let rayleigh_scattering = p.rayleigh_scattering * rayleigh;
    Medium {
        rayleigh_scattering,
        mie_scattering: p.mie_scattering * mie,
        extinction: rayleigh_scattering
            + Vec3::splat(p.mie_extinction * mie)
            + p.ozone_absorption * ozone,
    }
}

/// Rayleigh phase function, 1/sr: 3/(16π)(1 + ν²).
#[inline]
pub fn phase_rayleigh(cos_theta: f32) -> f32 {
    3.0 / (16.0 * PI) * (1.0 + cos_theta * cos_theta)
}

/// Cornette-Shanks phase function, 1/sr:
/// 3/(8π) (1 - g²)(1 + ν²) / ((2 + g²)(1 + g² - 2gν)^{3/2}).
#[inline]
pub fn phase_cornette_shanks(cos_theta: f32, g: f32) -> f32 {
    let g2 = g * g;
    let denom = (2.0 + g2) * (1.0 + g2 - 2.0 * g * cos_theta).max(1e-6).powf(1.5);
    3.0 / (8.0 * PI) * (1.0 - g2) * (1.0 + cos_theta * cos_theta) / denom
}

/// Radius (km) at `t` km along a ray from radius `r` with cos zenith `mu`.
#[inline]
pub fn radius_along(r: f32, mu: f32, t: f32) -> f32 {
    (t * t + 2.0 * r * mu * t + r * r).max(0.0).sqrt()
}

/// Distance (km) from radius `r <= top` along cos zenith `mu` to the top.
#[inline]
pub fn distance_to_top(r: f32, mu: f32, top: f32) -> f32 {
    let disc = r * r * mu * mu + (top - r) * (top + r);
    (-r * mu + disc.max(0.0).sqrt()).max(0.0)
}

/// Whether the ray from `r` along `mu` meets the ground.
#[inline]
pub fn ray_hits_ground(r: f32, mu: f32, bottom: f32) -> bool {
    mu < 0.0 && r * r * mu * mu - (r - bottom) * (r + bottom) >= 0.0
}

/// Distance (km) to the ground of a ray that meets it (conjugate form:
/// exact for a camera just above the ground).
#[inline]
pub fn distance_to_ground(r: f32, mu: f32, bottom: f32) -> f32 {
    let c = (r - bottom) * (r + bottom);
    let disc = (r * r * mu * mu - c).max(0.0);
    (c / (-r * mu + disc.sqrt()).max(1e-9)).max(0.0)
}

/// Distance (km) to where the ray leaves the atmosphere: the ground or the top.
#[inline]
pub fn distance_to_boundary(r: f32, mu: f32, p: &SkyParams) -> f32 {
    if ray_hits_ground(r, mu, p.ground_radius_km) {
        distance_to_ground(r, mu, p.ground_radius_km)
    } else {
        distance_to_top(r, mu, p.top_radius_km)
    }
}

/// Radius (km) of a world altitude in metres, clamped into the atmosphere.
#[inline]
pub fn radius_at_altitude(altitude_m: f32, p: &SkyParams) -> f32 {
    (p.ground_radius_km + altitude_m * 1e-3).clamp(p.ground_radius_km, p.top_radius_km)
}

/// The fraction of the sun disk above the horizon seen from radius `r`,
/// a smoothstep across the disk's angular size (Bruneton 2017).
#[inline]
pub fn sun_visible_fraction(r: f32, mu_s: f32, p: &SkyParams) -> f32 {
    let sin_h = (p.ground_radius_km / r).min(1.0);
    let cos_h = -(1.0 - sin_h * sin_h).max(0.0).sqrt();
    let half = sin_h * p.sun_angular_radius_deg.to_radians();
    let x = ((mu_s - cos_h + half) / (2.0 * half)).clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// The golden angle π(3 - √5), rad: the azimuth step of
/// [`fibonacci_direction`].
pub const GOLDEN_ANGLE: f32 = 2.399_963;

/// The `i`th of `n` spherical Fibonacci directions (y up): equal areas.
#[inline]
pub fn fibonacci_direction(i: u32, n: u32) -> Vec3 {
    let y = 1.0 - (2.0 * i as f32 + 1.0) / n as f32;
    let ring = (1.0 - y * y).max(0.0).sqrt();
    let phi = i as f32 * GOLDEN_ANGLE;
    Vec3::new(ring * phi.cos(), y, ring * phi.sin())
}

/// A ray in the atmosphere: radius `r` km, cos zenith `mu`, and the sun's
/// cos zenith `mu_s` and cosine `nu` to the ray, all at the ray's origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyRay {
    pub r: f32,
    pub mu: f32,
    pub mu_s: f32,
    pub nu: f32,
}

/// Radius (km) and sun cos zenith at `t` km along `ray`.
#[inline]
pub fn sky_ray_at(ray: SkyRay, t: f32) -> (f32, f32) {
    let r_t = radius_along(ray.r, ray.mu, t);
    (
        r_t,
        ((ray.r * ray.mu_s + t * ray.nu) / r_t).clamp(-1.0, 1.0),
    )
}

/// The ray from `altitude_m` along world `dir` under the sun at `sun_dir`.
#[inline]
pub fn sky_ray(altitude_m: f32, dir: Vec3, sun_dir: Vec3, p: &SkyParams) -> SkyRay {
    SkyRay {
        r: radius_at_altitude(altitude_m, p),
        mu: dir.y,
        mu_s: sun_dir.y,
        nu: dir.dot(sun_dir),
    }
}

/// Bounds (km) of step `k` of `steps` over `t_max`, quadratically spaced
/// (short steps near the origin, where the air is densest along most rays).
#[inline]
pub fn step_bounds(k: u32, steps: u32, t_max: f32) -> (f32, f32) {
    let (a, b) = (k as f32 / steps as f32, (k + 1) as f32 / steps as f32);
    (t_max * a * a, t_max * b * b)
}

/// ∫₀^dt e^{-σt} dt for one channel (its series below σ·dt = 1e-3, where
/// f32 would cancel).
#[inline]
pub fn step_integral_1(extinction: f32, dt: f32) -> f32 {
    if extinction * dt < 1e-3 {
        dt * (1.0 - 0.5 * extinction * dt)
    } else {
        (1.0 - (-extinction * dt).exp()) / extinction
    }
}

/// ∫₀^dt e^{-σt} dt per channel: the energy-conserving step (Hillaire 2016).
#[inline]
pub fn step_integral(extinction: Vec3, dt: f32) -> Vec3 {
    Vec3::new(
        step_integral_1(extinction.x, dt),
        step_integral_1(extinction.y, dt),
        step_integral_1(extinction.z, dt),
    )
}

/// Zenith angle (rad) of the horizon seen from radius `r`: π/2 plus the dip.
#[inline]
pub fn horizon_zenith_angle(r: f32, p: &SkyParams) -> f32 {
    let bottom = p.ground_radius_km;
    PI - (((r - bottom) * (r + bottom)).max(0.0).sqrt() / r).acos()
}

/// Azimuth (rad, [0, π]) of world `dir` from the sun's, about the y axis.
#[inline]
pub fn azimuth_from_sun(dir: Vec3, sun_dir: Vec3) -> f32 {
    let cross = dir.z * sun_dir.x - dir.x * sun_dir.z;
    let dot = dir.x * sun_dir.x + dir.z * sun_dir.z;
    cross.abs().atan2(dot)
}
