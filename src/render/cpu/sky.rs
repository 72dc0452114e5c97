//! The sky a frame is lit by, and the ground under it. Two models behind
//! one set of functions (each the twin of the WGSL function of the same
//! name; the GPU appends `shaders/sky_analytic.wgsl` or
//! `shaders/sky_physical.wgsl`, so a scene's model is the only one
//! compiled):
//! - **physical** (the default): Hillaire 2020's atmosphere tables
//!   ([`super::sky_luts`]): the sky's radiance from the sky-view table, the
//!   sun's light through the transmittance table at the altitude it
//!   reaches, aerial perspective marched through the tables, the
//!   limb-darkened sun disk;
//! - **analytic**: a blue gradient that pales toward the horizon, a glow
//!   and a disk around the sun reddened by a fixed air mass, and an
//!   exponential haze of `haze_distance_m`. Cheap, not physical.
//!
//! Below the horizon lies the land (lit by the sun through the clouds'
//! shadow and by the sky) or the sea.

use std::f32::consts::PI;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::lighting::phase_hg;
use super::sky_luts::{
    SkyLuts, SkyParams, aerial_perspective, sky_view_radiance, sun_disk_radiance, sun_radiance_at,
};
use super::waves::wave_normal;
use super::waves::{reflected_elevation, reflected_ray};

/// Relative sun irradiance: sunlight is about five times the sky's
/// illuminance on a clear day, so a sunlit cloud is brighter than the sky.
pub const SUN_INTENSITY: f32 = 8.0;

/// Cosine of the analytic sun disk's angular radius (0.27°).
pub const SUN_DISK_COS: f32 = 0.999_989;

/// Which sky model lights the scene (`[render.atmosphere] model`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SkyModel {
    /// Hillaire 2020's tables: Rayleigh, Mie and ozone over a spherical
    /// planet.
    #[default]
    Physical,
    /// The analytic gradient and exponential haze.
    Analytic,
}

/// The scene table `[render.atmosphere]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AtmosphereConfig {
    /// `"physical"` or `"analytic"`. Default physical.
    pub model: SkyModel,
    /// Fade clouds and ground with distance (the physical model's march
    /// through the air, or the analytic model's `haze_distance_m`).
    /// Default true; off, the clouds are seen as in a vacuum (what the
    /// path-traced comparison renders).
    pub aerial_perspective: bool,
    /// The aerosols' vertical optical depth at 550 nm (0..=3): 0.05 very
    /// clean, 0.1-0.2 a clear continental or maritime day, 0.5 hazy, 1+
    /// polluted. Their extinction falls off with Hillaire's Mie scale
    /// height (1.2 km) and 0.91 of it scatters. The physical model only.
    /// Default 0.15: a boundary layer that grows cumulus is seldom clean
    /// (Hillaire's Earth has 0.005, a sky too deep a blue over ground too
    /// dark).
    pub aerosol_optical_depth: f32,
}

impl Default for AtmosphereConfig {
    fn default() -> Self {
        Self {
            model: SkyModel::Physical,
            aerial_perspective: true,
            aerosol_optical_depth: 0.15,
        }
    }
}

impl AtmosphereConfig {
    /// The physical model's atmosphere, `None` for the analytic model.
    pub fn sky_params(&self) -> Option<SkyParams> {
        (self.model == SkyModel::Physical).then(|| {
            let base = SkyParams::default();
            let extinction = self.aerosol_optical_depth / base.mie_scale_height_km;
            let albedo = base.mie_scattering / base.mie_extinction;
            SkyParams {
                mie_scattering: extinction * albedo,
                mie_extinction: extinction,
                // The ground the sky's multiple scattering sees: the
                // land's mean albedo.
                ground_albedo: LAND_ALBEDO,
                ..base
            }
        })
    }
}

/// What the sky functions need of a frame: the model (the physical
/// model's tables, built for this frame's sun and camera altitude) and the
/// haze settings.
#[derive(Debug, Clone, Copy)]
pub struct SkyLight<'a> {
    /// The physical model's tables; `None`: the analytic model.
    pub luts: Option<&'a SkyLuts>,
    /// Whether distance fades (`[render.atmosphere] aerial_perspective`).
    pub aerial_perspective: bool,
    /// The analytic model's haze distance, m.
    pub haze_distance_m: f32,
    /// The camera's altitude, m (where the physical model's aerial
    /// perspective starts).
    pub camera_altitude_m: f32,
    /// The sunlight the clouds scatter down onto the land the camera sees,
    /// as the land's irradiance over π ([`ground_cloud_light`]; zero: the
    /// clear sky's land).
    pub ground_cloud_light: Vec3,
}

impl SkyLight<'static> {
    /// The analytic model with its haze at `haze_distance_m`.
    pub fn analytic(haze_distance_m: f32) -> Self {
        Self {
            luts: None,
            aerial_perspective: true,
            haze_distance_m,
            camera_altitude_m: 0.0,
            ground_cloud_light: Vec3::ZERO,
        }
    }
}

/// Colour of sunlight after the analytic model's air mass for a sun at
/// `sun_dir` (relative, ~1 at noon).
#[inline]
pub fn sun_color(sun_dir: Vec3) -> Vec3 {
    let air_mass = 1.0 / sun_dir.y.max(0.035);
    let tau = Vec3::new(0.018, 0.04, 0.09) * air_mass;
    Vec3::new((-tau.x).exp(), (-tau.y).exp(), (-tau.z).exp())
}

/// The sun's irradiance (on a surface facing it) at `altitude_m`: the
/// analytic model's `sun_color · SUN_INTENSITY` at any altitude, or the
/// physical model's top-of-atmosphere irradiance through the
/// transmittance table (0 once the sun has set at that altitude).
#[inline]
pub fn sun_light_at(sky: &SkyLight, altitude_m: f32, sun_dir: Vec3) -> Vec3 {
    match sky.luts {
        Some(luts) => sun_radiance_at(luts, altitude_m.max(0.0), sun_dir),
        None => sun_color(sun_dir) * SUN_INTENSITY,
    }
}

/// The analytic sky's radiance along `dir` (above the horizon).
#[inline]
pub fn analytic_sky(dir: Vec3, sun_dir: Vec3) -> Vec3 {
    let sun = sun_color(sun_dir);
    let day = sun_dir.y.clamp(0.0, 1.0).sqrt().max(0.15);
    let zenith = Vec3::new(0.16, 0.32, 0.75);
    let horizon = Vec3::new(0.62, 0.72, 0.86);
    let f = (1.0 - dir.y).powi(4);
    let base = zenith.lerp(horizon, f) * day * sun.lerp(Vec3::ONE, 0.6);
    let cos = dir.dot(sun_dir);
    let glow = sun * (phase_hg(cos, 0.76) * 0.35);
    base + glow
}

/// The sky's radiance along `dir` at or above the horizon, without the
/// sun disk: the analytic gradient, or the physical sky-view table.
#[inline]
pub fn sky_above(sky: &SkyLight, dir: Vec3, sun_dir: Vec3) -> Vec3 {
    match sky.luts {
        Some(luts) => sky_view_radiance(luts, dir, sun_dir),
        None => analytic_sky(dir, sun_dir),
    }
}

/// The sky's light on a surface or into a cloud, as a radiance: what
/// times π is the irradiance of level ground (the land's and terrain's
/// sky light) and times 1/4 the cloud's isotropically scattered sky light
/// at its top. Analytic: the zenith's radiance (its sky is nearly uniform;
/// the ambient gain was fitted on it). Physical: the sky's mean radiance
/// over the upper hemisphere, the sky-ambient table built with the sky
/// view ([`super::sky_luts::sky_ambient_texel`]), for its horizon is
/// several times brighter than its zenith.
#[inline]
pub fn sky_ambient(sky: &SkyLight, sun_dir: Vec3) -> Vec3 {
    match sky.luts {
        Some(luts) => luts.sky_ambient.texel(0, 0),
        None => sky_above(sky, Vec3::Y, sun_dir),
    }
}

/// Sky radiance seen along `dir`, without the sun disk; below the horizon
/// the sunlit land.
#[inline]
pub fn sky_radiance(sky: &SkyLight, dir: Vec3, sun_dir: Vec3) -> Vec3 {
    if dir.y < 0.0 {
        return land_radiance(sky, dir, sun_dir, 1.0, LAND_ALBEDO);
    }
    sky_above(sky, dir, sun_dir)
}

/// The horizon's sky in the azimuth of `dir`.
#[inline]
fn horizon_sky(sky: &SkyLight, dir: Vec3, sun_dir: Vec3) -> Vec3 {
    sky_above(
        sky,
        Vec3::new(dir.x, 0.0, dir.z).normalize_or(Vec3::X),
        sun_dir,
    )
}

/// The air between the camera and something `distance_m` away along
/// `dir`: (the light it scatters toward the camera, its transmittance).
/// Analytic: `exp(-distance / haze_distance)` of the sky at the horizon
/// (at `dir`'s elevation when above it) in place of what it hides;
/// physical: [`aerial_perspective`]'s march from the camera's altitude.
/// `(0, 1)` with aerial perspective off.
#[inline]
pub fn aerial(sky: &SkyLight, dir: Vec3, distance_m: f32, sun_dir: Vec3) -> (Vec3, Vec3) {
    if !sky.aerial_perspective {
        return (Vec3::ZERO, Vec3::ONE);
    }
    match sky.luts {
        Some(luts) => aerial_perspective(luts, sky.camera_altitude_m, dir, distance_m, sun_dir),
        None => {
            let haze = (-distance_m / sky.haze_distance_m.max(1.0)).exp();
            let up = Vec3::new(dir.x, dir.y.max(0.0), dir.z).normalize_or(Vec3::Y);
            (analytic_sky(up, sun_dir) * (1.0 - haze), Vec3::splat(haze))
        }
    }
}

/// The flat ground's `surface` radiance seen along `dir` (pointing down)
/// through the air: analytic, faded into the horizon's sky within a few
/// degrees of it; physical, [`aerial`] over the distance from the camera
/// down to the ground (`camera_altitude_m / -dir.y`, so at grazing angles
/// the air's own light).
#[inline]
pub fn ground_haze(sky: &SkyLight, surface: Vec3, dir: Vec3, sun_dir: Vec3) -> Vec3 {
    let mu = (-dir.y).max(1e-4);
    match sky.luts {
        Some(_) => {
            let (inscatter, t) = aerial(sky, dir, sky.camera_altitude_m.max(1.0) / mu, sun_dir);
            surface * t + inscatter
        }
        None => surface.lerp(horizon_sky(sky, dir, sun_dir), (-mu * 40.0).exp()),
    }
}

/// What of the ground's own light along `dir` (pointing down) comes
/// through the air to the eye, per channel: the factor on `surface` in
/// [`ground_haze`], which is affine in it.
#[inline]
pub fn ground_haze_transmittance(sky: &SkyLight, dir: Vec3, sun_dir: Vec3) -> Vec3 {
    let mu = (-dir.y).max(1e-4);
    match sky.luts {
        Some(_) => aerial(sky, dir, sky.camera_altitude_m.max(1.0) / mu, sun_dir).1,
        None => Vec3::splat(1.0 - (-mu * 40.0).exp()),
    }
}

/// The flat land's albedo (`LAND_ALBEDO` in WGSL), the plain land's and
/// the fields' mean ([`super::land`]): a muted
/// green-brown of fields, woods and soil seen from afar, greyer than the
/// terrain's grass (0.07 / 0.11 / 0.04 on level ground), which lit at
/// full sun read as a lawn from the air.
pub const LAND_ALBEDO: Vec3 = Vec3::new(0.08, 0.10, 0.06);

/// The flat land's own radiance (no haze): Lambertian of `albedo`
/// ([`LAND_ALBEDO`], or the fields' [`super::land::land_albedo`]) lit by
/// the sun at the ground ([`sun_light_at`] times `sin(elevation)`, dimmed
/// by the clouds' `shadow`, their transmittance toward the sun, 1: in the
/// sun) and by the sky (the zenith's radiance standing for the sky's
/// irradiance over π).
#[inline]
pub fn land_surface(sky: &SkyLight, sun_dir: Vec3, shadow: f32, albedo: Vec3) -> Vec3 {
    let sun = sun_light_at(sky, 0.0, sun_dir);
    let lit = sun * (sun_dir.y.max(0.0) * shadow / PI) + sky_ambient(sky, sun_dir);
    albedo * lit
}

/// The flat land of `albedo` seen along `dir` (pointing down):
/// [`land_surface`] and the clouds' light on it (`sky.ground_cloud_light`) through the air
/// ([`ground_haze`]).
#[inline]
pub fn land_radiance(sky: &SkyLight, dir: Vec3, sun_dir: Vec3, shadow: f32, albedo: Vec3) -> Vec3 {
    let surface = land_surface(sky, sun_dir, shadow, albedo) + albedo * sky.ground_cloud_light;
    ground_haze(sky, surface, dir, sun_dir)
}

/// The share of the sun's horizontal irradiance at the cloud band that a
/// cloud layer covering the whole sky would send down onto the land as
/// diffuse light ([`ground_cloud_light`]). Fitted to Mitsuba's path
/// tracer over a Lambertian plane under the fair-weather clouds (P 34 %
/// covered; docs/ground_truth/ground_shadow.py, figures in
/// docs/renderer.md, "The land under the clouds"): its diffuse
/// light beyond the clear sky's asks for 0.54 and 0.44 (suns 60° and 30°
/// high) in the deepest shade and 0.59 and 0.62 averaged over all the
/// land; 0.53 keeps both within 7 % at both suns.
pub const GROUND_CLOUD_LIGHT: f32 = 0.53;

/// The sunlight the clouds scatter down onto the land, as its irradiance
/// over π, per unit albedo: [`GROUND_CLOUD_LIGHT`] times the share
/// `cover` of the ground under cloud (P's covered fraction) times the
/// sun's horizontal irradiance at the band's middle height
/// `band_middle_m`, over π. The land in the clouds' shade gets the sky's
/// light and this, which is the sun's colour, nearly white: without it
/// the shade has half the path tracer's light and its blue.
#[inline]
pub fn ground_cloud_light(sky: &SkyLight, sun_dir: Vec3, cover: f32, band_middle_m: f32) -> Vec3 {
    sun_light_at(sky, band_middle_m, sun_dir)
        * (GROUND_CLOUD_LIGHT * cover.clamp(0.0, 1.0) * sun_dir.y.max(0.0) / PI)
}

/// The sun disk's radiance along `dir` (0 off the disk): analytic, a flat
/// disk of 60 times the sun's colour; physical, the limb-darkened disk
/// whose integral is the sun's irradiance at the camera
/// ([`sun_disk_radiance`]).
#[inline]
pub fn sun_disk(sky: &SkyLight, dir: Vec3, sun_dir: Vec3) -> Vec3 {
    match sky.luts {
        Some(luts) => sun_disk_radiance(
            dir,
            sun_dir,
            sun_light_at(sky, sky.camera_altitude_m, sun_dir),
            luts.params.sun_angular_radius_deg.to_radians(),
        ),
        None if dir.dot(sun_dir) > SUN_DISK_COS => sun_color(sun_dir) * 60.0,
        None => Vec3::ZERO,
    }
}

/// The sun disk's irradiance at the camera, its [`sun_disk`] radiance
/// integrated over the disk (`sun_disk_irradiance` in WGSL): physical,
/// the sun's light at the camera's altitude; analytic, its flat disk of
/// 60 times the sun's colour over the disk's solid angle. The source of
/// the sun's glare ([`super::glare`]).
#[inline]
pub fn sun_disk_irradiance(sky: &SkyLight, sun_dir: Vec3) -> Vec3 {
    match sky.luts {
        Some(_) => sun_light_at(sky, sky.camera_altitude_m, sun_dir),
        None => sun_color(sun_dir) * (60.0 * 2.0 * PI * (1.0 - SUN_DISK_COS)),
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

/// What the land looks like from the air (`[render.ground] land`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Land {
    /// A patchwork of fields in rows with woods across it
    /// ([`super::land::land_albedo`]), its mean [`LAND_ALBEDO`].
    #[default]
    Fields,
    /// One colour, [`LAND_ALBEDO`] (the path-traced comparisons' ground).
    Plain,
}

/// The ground under the sky (scene table `[render.ground]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GroundConfig {
    /// `"land"` or `"sea"`. Default land.
    pub surface: Surface,
    /// The land's look, `"fields"` or `"plain"`. Default fields.
    pub land: Land,
    /// Wind speed over the sea, m/s (0..=30): the roughness of its waves,
    /// so the width of the sun's glint. Default 7.
    pub wind_speed_mps: f32,
    /// The direction the sea's wind blows toward, degrees clockwise from
    /// north (+z), as `[physics.wind] direction_deg`: the waves run
    /// along it ([`super::waves::sea_waves`]). Default 90 (east).
    pub wind_direction_deg: f32,
}

impl Default for GroundConfig {
    fn default() -> Self {
        Self {
            surface: Surface::Land,
            land: Land::Fields,
            wind_speed_mps: 7.0,
            wind_direction_deg: 90.0,
        }
    }
}

impl GroundConfig {
    /// The sea's wind speed when the ground is sea, else `None`.
    pub fn sea_wind_mps(&self) -> Option<f32> {
        (self.surface == Surface::Sea).then_some(self.wind_speed_mps)
    }

    /// Whether the land (flat or terrain) is drawn as fields and woods:
    /// the ground is land and its look is [`Land::Fields`].
    pub fn land_fields(&self) -> bool {
        self.surface == Surface::Land && self.land == Land::Fields
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

/// The water's own light (inlined in WGSL): a deep-blue albedo lit by
/// the sun and the zenith sky, seen through the surface.
#[inline]
fn water_light(sky: &SkyLight, sun: Vec3, sun_dir: Vec3) -> Vec3 {
    Vec3::new(0.004, 0.012, 0.02) * (sun * (sun_dir.y.max(0.0) / PI) + sky_ambient(sky, sun_dir))
}

/// The ray the sea sends up where `dir` (pointing down) meets it, tilted
/// by the resolved `waves` ([`super::waves::sea_waves`]): the mirror
/// image of `dir` about [`wave_normal`], at least 1e-3 up (a facet that
/// would send it down sends it into the next wave, which sends it up).
/// The flat sea's mirror ray with no slope.
#[inline]
pub fn sea_mirror(dir: Vec3, waves: Vec3) -> Vec3 {
    let n = wave_normal(waves);
    let r = dir - n * (2.0 * dir.dot(n));
    Vec3::new(r.x, r.y.max(1e-3), r.z).normalize_or(Vec3::Y)
}

/// The Fresnel reflectance of the sea seen along `dir` under the resolved
/// `waves`: [`fresnel_water`] at the angle to [`wave_normal`].
#[inline]
pub fn sea_fresnel(dir: Vec3, waves: Vec3) -> f32 {
    fresnel_water((-dir.dot(wave_normal(waves))).max(1e-3))
}

/// The strata of the slopes a pixel does not resolve over which the sea's
/// mirrored sky is averaged ([`mirrored_sky`]; `SKY_MIRROR_RAYS` in WGSL).
pub const SKY_MIRROR_RAYS: u32 = 8;

/// The sky the sea mirrors along `dir` (pointing down), under `waves`:
/// the mean of the sky along [`SKY_MIRROR_RAYS`] rays about the resolved
/// waves' mirror ray ([`sea_mirror`]), one at the middle of each stratum
/// of the slopes the pixel does not resolve
/// ([`super::waves::reflected_elevation`]; turned up or down, not
/// sideways, since the sky changes little in azimuth). A flat mirror
/// would show the far sea as bright as the sky at the horizon, where its
/// rough waves send the reflected rays on average 10-15° up, to a deeper
/// sky, and the waves drawn near the camera, which do, would meet it in a
/// visible step.
#[inline]
pub fn mirrored_sky(sky: &SkyLight, dir: Vec3, waves: Vec3, sun_dir: Vec3) -> Vec3 {
    let r0 = sea_mirror(dir, waves);
    let across = Vec3::new(r0.x, 0.0, r0.z).normalize_or(Vec3::Z);
    let mirror = r0.y.clamp(-1.0, 1.0).asin();
    let mut sum = Vec3::ZERO;
    for k in 0..SKY_MIRROR_RAYS {
        let u = (k as f32 + 0.5) / SKY_MIRROR_RAYS as f32;
        let e = reflected_elevation(mirror, waves.z, u);
        sum += sky_above(sky, reflected_ray(across, mirror, e, 0.0), sun_dir);
    }
    sum / SKY_MIRROR_RAYS as f32
}

/// Radiance of a wind-roughened sea seen along `dir` (pointing down),
/// under `waves` (`(slope x, slope z, variance)`:
/// [`super::waves::sea_waves`], the slope a pixel resolves and the
/// variance it does not; [`super::waves::flat_sea`] far away):
/// - the sky mirrored about the resolved waves' normal
///   ([`mirrored_sky`]), weighted by the Fresnel factor at it
///   ([`sea_fresnel`]; so the sea darkens looking down and mirrors the
///   pale horizon sky toward the horizon, and near the camera the waves'
///   faces turned up or away show as darker or paler);
/// - the sun's glint: a microfacet reflection whose facet slopes spread
///   about the resolved slope with the unresolved variance (in all, Cox
///   and Munk's 1954 `0.003 + 0.00512·U` for a wind of `U` m/s), as a
///   Beckmann distribution in slope space, `E F D / (4 cos θ_v)`: a
///   broad glint far away, glitter on the waves near the camera;
/// - the water's own light: a deep-blue albedo (0.004, 0.012, 0.02) lit
///   by the sun and the zenith sky, through the surface (1 - F);
///
/// then seen through the air as the land is ([`ground_haze`]). The
/// clouds' `shadow` (transmittance toward the sun) dims the glint and the
/// sunlit part of the water. `reflection` is the clouds the waves
/// mirror (their premultiplied light and transmittance,
/// `sea::sea_reflection`; `(0, 1)`: none), in front of the mirrored
/// sky.
#[inline]
pub fn sea_radiance(
    sky: &SkyLight,
    dir: Vec3,
    sun_dir: Vec3,
    waves: Vec3,
    shadow: f32,
    reflection: (Vec3, f32),
) -> Vec3 {
    let mu = (-dir.y).max(1e-3);
    let f = sea_fresnel(dir, waves);
    let reflected = reflection.0 + mirrored_sky(sky, dir, waves, sun_dir) * reflection.1;
    let sun = sun_light_at(sky, 0.0, sun_dir) * shadow;
    let variance = waves.z;
    let h = (sun_dir - dir).normalize_or(Vec3::Y);
    let cos_b = h.y.max(1e-3);
    // The half vector's facet slope less the resolved slope, in the
    // exponent; the slope space's Jacobian, 1 / cos⁴, is the half
    // vector's own (to the vertical).
    let tan2 = (h.x / cos_b + waves.x).powi(2) + (h.z / cos_b + waves.y).powi(2);
    let cos2 = cos_b * cos_b;
    let d = (-tan2 / variance).exp() / (PI * variance * cos2 * cos2);
    let glint = if sun_dir.y > 0.0 {
        sun * (fresnel_water(h.dot(sun_dir)) * d / (4.0 * mu))
    } else {
        Vec3::ZERO
    };
    let surface = reflected * f + glint + water_light(sky, sun, sun_dir) * (1.0 - f);
    ground_haze(sky, surface, dir, sun_dir)
}

/// The light that rises from the flat ground straight up, without the
/// clouds' shadows (the sky irradiance of a cloud's underside that comes
/// from below): the land's [`land_surface`], or the sea's reflected
/// zenith and its own light (its glint is not seen from above).
#[inline]
pub fn ground_up(sky: &SkyLight, sun_dir: Vec3, sea: bool) -> Vec3 {
    if sea {
        let sun = sun_light_at(sky, 0.0, sun_dir);
        let f = WATER_F0;
        return sky_above(sky, Vec3::Y, sun_dir) * f + water_light(sky, sun, sun_dir) * (1.0 - f);
    }
    land_surface(sky, sun_dir, 1.0, LAND_ALBEDO)
}

/// What a ray that meets no terrain sees along `dir`: the sky and the sun
/// disk, or below the horizon the land ([`land_radiance`]) or, with
/// `sea` (its waves there, [`super::waves::sea_waves`]), the sea
/// ([`sea_radiance`], mirroring the clouds of `reflection`), in the
/// clouds' `shadow` where the ray meets them; the land of albedo `land`
/// there ([`LAND_ALBEDO`], or the fields'
/// [`super::land::flat_ground_albedo`]).
#[inline]
pub fn background_radiance(
    sky: &SkyLight,
    dir: Vec3,
    sun_dir: Vec3,
    sea: Option<Vec3>,
    shadow: f32,
    land: Vec3,
    reflection: (Vec3, f32),
) -> Vec3 {
    if dir.y >= 0.0 {
        return sky_above(sky, dir, sun_dir) + sun_disk(sky, dir, sun_dir);
    }
    match sea {
        Some(waves) => sea_radiance(sky, dir, sun_dir, waves, shadow, reflection),
        None => land_radiance(sky, dir, sun_dir, shadow, land),
    }
}

#[cfg(test)]
#[path = "sky_tests.rs"]
mod tests;
