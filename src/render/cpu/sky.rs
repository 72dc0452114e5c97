//! An analytic sky: a blue gradient that pales toward the horizon, a
//! forward-scattering glow and a disk around the sun, reddened when the sun
//! is low; below the horizon the land, lit by the sun and the sky, or the
//! sea. Not a physical sky model (`sky_luts` holds the tables of one, not
//! yet read by the renderers), but smooth, cheap and the same on the GPU.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::lighting::phase_hg;
use super::renderer::SUN_INTENSITY;

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
        return land_radiance(dir, sun_dir, 1.0);
    }
    let zenith = Vec3::new(0.16, 0.32, 0.75);
    let horizon = Vec3::new(0.62, 0.72, 0.86);
    let f = (1.0 - dir.y).powi(4);
    let base = zenith.lerp(horizon, f) * day * sun.lerp(Vec3::ONE, 0.6);
    let cos = dir.dot(sun_dir);
    let glow = sun * (phase_hg(cos, 0.76) * 0.35);
    base + glow
}

/// The flat land's albedo (inlined in WGSL's `land_radiance`): a muted
/// green-brown of fields, woods and soil seen from afar, greyer than the
/// terrain's grass (0.07 / 0.11 / 0.04 on level ground), which lit at
/// full sun read as a lawn from the air.
pub const LAND_ALBEDO: Vec3 = Vec3::new(0.08, 0.10, 0.06);

/// The flat land seen along `dir` (pointing down) through the haze: a
/// Lambertian [`LAND_ALBEDO`] lit as the terrain's level ground is, by the
/// sun (its irradiance `SUN_INTENSITY · sun_color · sin(elevation)`,
/// dimmed by the clouds' `shadow`, the transmittance toward the sun, 1:
/// in the sun) and by the sky (the zenith's radiance standing for the
/// sky's irradiance over π).
#[inline]
pub fn land_radiance(dir: Vec3, sun_dir: Vec3, shadow: f32) -> Vec3 {
    let sun = sun_color(sun_dir) * SUN_INTENSITY;
    let lit =
        sun * (sun_dir.y.max(0.0) * shadow / std::f32::consts::PI) + sky_radiance(Vec3::Y, sun_dir);
    let ground = LAND_ALBEDO * lit;
    let horizon = sky_radiance(Vec3::new(dir.x, 0.0, dir.z).normalize_or(Vec3::X), sun_dir);
    let f = (-(-dir.y) * 40.0).exp();
    ground.lerp(horizon, f)
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

/// What lies below the horizon where there is no terrain.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Surface {
    /// Land: a dim green-grey, lit by the sun and the sky.
    #[default]
    Land,
    /// The sea: the sky reflected with Fresnel, the sun's glint and the
    /// water's own blue ([`sea_radiance`]).
    Sea,
}

/// The ground under the sky (scene table `[render.ground]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GroundConfig {
    /// `"land"` or `"sea"`. Default land.
    pub surface: Surface,
    /// Wind speed over the sea, m/s (0..=30): the roughness of its waves,
    /// so the width of the sun's glint. Default 7.
    pub wind_speed_mps: f32,
}

impl Default for GroundConfig {
    fn default() -> Self {
        Self {
            surface: Surface::Land,
            wind_speed_mps: 7.0,
        }
    }
}

impl GroundConfig {
    /// The sea's wind speed when the ground is sea, else `None`.
    pub fn sea_wind_mps(&self) -> Option<f32> {
        (self.surface == Surface::Sea).then_some(self.wind_speed_mps)
    }
}

/// Water's reflectance at normal incidence, `((n - 1) / (n + 1))²` for a
/// refractive index of 1.333.
pub const WATER_F0: f32 = 0.0204;

/// Schlick's approximation of water's Fresnel reflectance at an angle of
/// incidence of cosine `cos_i`: 2 % looking straight down, all of it at
/// grazing incidence.
#[inline]
pub fn fresnel_water(cos_i: f32) -> f32 {
    let c = 1.0 - cos_i.clamp(0.0, 1.0);
    WATER_F0 + (1.0 - WATER_F0) * c * c * c * c * c
}

/// Radiance of a wind-roughened sea seen along `dir` (pointing down):
/// - the sky reflected by the mean flat surface, weighted by
///   [`fresnel_water`] (so the sea darkens looking down and mirrors the
///   pale horizon sky toward the horizon);
/// - the sun's glint: a microfacet reflection whose facet slopes have the
///   variance Cox and Munk (1954) measured, `0.003 + 0.00512·U` for a wind
///   of `U` m/s, as a Beckmann distribution, `E F D / (4 cos θ_v)`;
/// - the water's own light: a deep-blue albedo (0.004, 0.012, 0.02) lit
///   by the sun and the zenith sky, through the surface (1 - F);
///
/// then faded into the horizon's haze as the land is ([`land_radiance`]).
/// The clouds' `shadow` (transmittance toward the sun) dims the glint and
/// the sunlit part of the water; clouds are not reflected.
#[inline]
pub fn sea_radiance(dir: Vec3, sun_dir: Vec3, wind_mps: f32, shadow: f32) -> Vec3 {
    let mu = (-dir.y).max(1e-3);
    let f = fresnel_water(mu);
    let reflected = sky_radiance(Vec3::new(dir.x, mu, dir.z).normalize_or(Vec3::Y), sun_dir);
    let sun = sun_color(sun_dir) * SUN_INTENSITY * shadow;
    let variance = 0.003 + 0.00512 * wind_mps.max(0.0);
    let h = (sun_dir - dir).normalize_or(Vec3::Y);
    let cos_b = h.y.max(1e-3);
    let cos2 = cos_b * cos_b;
    let d =
        (-(1.0 - cos2) / (cos2 * variance)).exp() / (std::f32::consts::PI * variance * cos2 * cos2);
    let glint = if sun_dir.y > 0.0 {
        sun * (fresnel_water(h.dot(sun_dir)) * d / (4.0 * mu))
    } else {
        Vec3::ZERO
    };
    let water = Vec3::new(0.004, 0.012, 0.02)
        * (sun * (sun_dir.y.max(0.0) / std::f32::consts::PI) + sky_radiance(Vec3::Y, sun_dir));
    let surface = reflected * f + glint + water * (1.0 - f);
    let horizon = sky_radiance(Vec3::new(dir.x, 0.0, dir.z).normalize_or(Vec3::X), sun_dir);
    surface.lerp(horizon, (-mu * 40.0).exp())
}

/// What a ray that meets no terrain sees along `dir`: the sky and the sun
/// disk, or below the horizon the land ([`land_radiance`]) or, with
/// `sea_wind_mps`, the sea ([`sea_radiance`]), in the clouds' `shadow`
/// where the ray meets them.
#[inline]
pub fn background_radiance(
    dir: Vec3,
    sun_dir: Vec3,
    sea_wind_mps: Option<f32>,
    shadow: f32,
) -> Vec3 {
    if dir.y >= 0.0 {
        return sky_radiance(dir, sun_dir) + sun_disk(dir, sun_dir);
    }
    match sea_wind_mps {
        Some(wind) => sea_radiance(dir, sun_dir, wind, shadow),
        None => land_radiance(dir, sun_dir, shadow),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_goes_from_two_percent_to_all() {
        assert!((fresnel_water(1.0) - 0.0204).abs() < 1e-6);
        assert!((fresnel_water(0.0) - 1.0).abs() < 1e-6);
        let mut last = 1.0;
        for i in 0..=100 {
            let f = fresnel_water(i as f32 / 100.0);
            assert!(f <= last + 1e-7);
            last = f;
        }
    }

    /// Looking down the sea is darker than the sky it mirrors, near the
    /// horizon it is nearly the horizon sky, and the brightest point is
    /// the glint where the sun's mirror image lies; a stronger wind
    /// spreads the glint wider and dimmer.
    #[test]
    fn the_sea_mirrors_the_sky_and_glints_under_the_sun() {
        let sun = sun_direction(30.0, 180.0);
        let lum = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
        let at = |elev_deg: f32, az_deg: f32, wind: f32| {
            let d = -sun_direction(elev_deg, az_deg) * Vec3::new(-1.0, 1.0, -1.0);
            sea_radiance(d.normalize(), sun, wind, 1.0)
        };
        // Away from the sun (azimuth 0), straight down and near the horizon.
        let down = lum(at(80.0, 0.0, 7.0));
        let sky_up = lum(sky_radiance(Vec3::Y, sun));
        assert!(down < 0.2 * sky_up, "{down} {sky_up}");
        let near = at(0.5, 0.0, 7.0);
        let horizon = sky_radiance(Vec3::new(0.0, 0.0, 1.0), sun);
        assert!((lum(near) - lum(horizon)).abs() < 0.1 * lum(horizon));
        // The mirror image of the sun: 30° below the horizon toward it.
        let glint = lum(at(30.0, 180.0, 7.0));
        let beside = lum(at(30.0, 140.0, 7.0));
        assert!(
            glint > 10.0 * beside && glint > 5.0 * sky_up,
            "{glint} {beside}"
        );
        let rough = lum(at(30.0, 180.0, 20.0));
        assert!(rough < glint && lum(at(30.0, 160.0, 20.0)) > lum(at(30.0, 160.0, 7.0)));
        // The background picks the sea below the horizon only, and a
        // cloud's shadow dims the glint.
        let up = Vec3::new(0.0, 0.5, 0.866);
        assert_eq!(
            background_radiance(up, sun, Some(7.0), 0.0),
            background_radiance(up, sun, None, 1.0)
        );
        let d = Vec3::new(0.0, -0.5, 0.866);
        assert_ne!(
            background_radiance(d, sun, Some(7.0), 1.0),
            background_radiance(d, sun, None, 1.0)
        );
        let g = -sun * Vec3::new(-1.0, 1.0, -1.0);
        let shaded = lum(sea_radiance(g, sun, 7.0, 0.1));
        assert!(shaded < 0.2 * glint, "{shaded} {glint}");
        // The land in a cloud's shadow is darker by the sun's part, and
        // keeps the sky's: on a clear day the sky gives 10-30 % of the
        // irradiance on level ground at a 30° sun.
        let (lit, dark) = (land_radiance(d, sun, 1.0), land_radiance(d, sun, 0.0));
        let ratio = lum(dark) / lum(lit);
        assert!((0.1..0.3).contains(&ratio), "{ratio}");
    }
}
