//! An analytic sky: a blue gradient that pales toward the horizon, a
//! forward-scattering glow and a disk around the sun, reddened when the sun
//! is low; a dim ground below the horizon. Not a physical sky model (a
//! Preetham or single-scattering atmosphere would replace it), but smooth,
//! cheap and the same on the GPU.

use glam::Vec3;

use super::lighting::phase_hg;

/// Cosine of the sun disk's angular radius (0.27°).
pub const SUN_DISK_COS: f32 = 0.999_989;

/// Colour of sunlight after the air mass for a sun at `sun_dir` (relative,
/// ~1 at noon).
#[inline]
pub fn sun_color(sun_dir: Vec3) -> Vec3 {
    let air_mass = 1.0 / sun_dir.y.max(0.035);
    let tau = Vec3::new(0.018, 0.04, 0.09) * air_mass;
    Vec3::new((-tau.x).exp(), (-tau.y).exp(), (-tau.z).exp())
}

/// Sky radiance seen along `dir`, without the sun disk.
#[inline]
pub fn sky_radiance(dir: Vec3, sun_dir: Vec3) -> Vec3 {
    let sun = sun_color(sun_dir);
    let day = sun_dir.y.clamp(0.0, 1.0).sqrt().max(0.15);
    if dir.y < 0.0 {
        // Ground seen through haze.
        let ground = Vec3::new(0.10, 0.12, 0.10) * day * (0.4 + 0.6 * sun);
        let horizon = sky_radiance(Vec3::new(dir.x, 0.0, dir.z).normalize_or(Vec3::X), sun_dir);
        let f = (-(-dir.y) * 40.0).exp();
        return ground.lerp(horizon, f);
    }
    let zenith = Vec3::new(0.16, 0.32, 0.75);
    let horizon = Vec3::new(0.62, 0.72, 0.86);
    let f = (1.0 - dir.y).powi(4);
    let base = zenith.lerp(horizon, f) * day * sun.lerp(Vec3::ONE, 0.6);
    let cos = dir.dot(sun_dir);
    let glow = sun * (phase_hg(cos, 0.76) * 0.35);
    base + glow
}

/// The sun disk's radiance along `dir` (0 off the disk).
#[inline]
pub fn sun_disk(dir: Vec3, sun_dir: Vec3) -> Vec3 {
    if dir.dot(sun_dir) > SUN_DISK_COS {
        sun_color(sun_dir) * 60.0
    } else {
        Vec3::ZERO
    }
}

/// Unit vector toward a sun at `elevation_deg` above the horizon and
/// `azimuth_deg` clockwise from north (+z).
pub fn sun_direction(elevation_deg: f32, azimuth_deg: f32) -> Vec3 {
    let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    Vec3::new(e.cos() * a.sin(), e.sin(), e.cos() * a.cos())
}
