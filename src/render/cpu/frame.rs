//! The values a frame shares between the CPU renderer's parts: the scene's
//! quality and look ([`Quality`]), everything one frame reads ([`Frame`])
//! and the march's early exit. The twin of `shaders/frame.wgsl`.

use glam::Vec3;

use super::cirrus::CirrusLayer;
use super::density::{DensityParams, Fields};
use super::light_volume::LightVolume;
use super::lighting::LightGains;
use super::sky::{AtmosphereConfig, SkyLight, ground_cloud_light, sun_direction};
use super::sky_luts::SkyLuts;
use crate::render::camera::View;
use crate::render::terrain::Heightfield;

/// Quality and look (scene table `[render]` keys that are not camera,
/// sun or cloud map).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quality {
    /// Primary march samples across the band segment.
    pub steps: u32,
    /// Secondary march samples toward the sun (0: no self-shadowing).
    pub shadow_steps: u32,
    /// Extra multiple-scattering octaves, 0..=3.
    pub octaves: u32,
    /// Photons the light volume traces per column of its cells
    /// (`render.light_photons`; 0: no light volume).
    pub light_photons: u32,
    /// Distance at which the analytic model's aerial perspective has
    /// faded a cloud to 1/e, m.
    pub haze_distance_m: f32,
    /// Rays stop after this distance, m.
    pub max_distance_m: f32,
    /// Exposure multiplier before tone mapping.
    pub exposure: f32,
    /// The strength of the sun's glare in tone-mapped pictures
    /// (`render.sun_glare`; [`super::glare`]): 1 the CIE's eye, 0 none.
    pub sun_glare: f32,
    /// The sea below the horizon with this wind speed, m/s (`None`:
    /// land; [`super::sky::background_radiance`]).
    pub sea_wind_mps: Option<f32>,
    /// The direction the sea's wind blows toward, degrees clockwise from
    /// north: the waves run along it ([`super::waves::sea_waves`]).
    pub sea_wind_toward_deg: f32,
    /// The sea's clock, s: where its waves are in their travel
    /// ([`super::waves::sea_waves`]). The CLI's stills take
    /// `render.time_s`; the GPU renderer's
    /// [`crate::render::gpu::CloudRenderer::set_sea_time`] moves it per frame.
    pub sea_time_s: f32,
    /// The land drawn as fields and woods
    /// ([`super::land::land_albedo`]); off: one colour,
    /// [`super::sky::LAND_ALBEDO`]. Off under the sea.
    pub land_fields: bool,
    /// The sky model and aerial perspective (`[render.atmosphere]`).
    pub atmosphere: AtmosphereConfig,
    /// The cirrus layer above the clouds (`[render.cirrus]`;
    /// [`super::cirrus`]), when drawn.
    pub cirrus: Option<CirrusLayer>,
    /// Only the sun's light scattered once: no octaves, no sky or ground
    /// light in the clouds, nothing behind them (black) and no haze in
    /// front; what a path tracer limited to one scattering renders
    /// (`cumulus render --single-scattering`, docs/ground_truth). Scenes
    /// never set it.
    pub single_scattering: bool,
}

/// Transmittance below which the march stops (opacity early exit).
pub const MIN_TRANSMITTANCE: f32 = 0.01;

/// Everything a frame needs.
#[derive(Clone, Copy)]
pub struct Frame<'a> {
    /// The camera (a scene's [`crate::render::camera::Camera`] made a view
    /// with the image's aspect, or an application's matrices).
    pub view: View,
    pub sun_elevation_deg: f32,
    pub sun_azimuth_deg: f32,
    pub fields: Fields<'a>,
    pub density: DensityParams,
    pub quality: Quality,
    /// The terrain, when the scene has one (none: nothing is marched).
    pub terrain: Option<&'a Heightfield>,
    /// The physical sky's tables for this frame's sun and camera altitude
    /// (`quality.atmosphere.sky_params()`; none: the analytic sky).
    pub sky: Option<&'a SkyLuts>,
    /// The share of the ground under cloud, 0..1 (P's covered fraction,
    /// [`crate::sim::ProjectedField::covered_fraction`]): how much
    /// sunlight the clouds scatter down onto the land
    /// ([`super::sky::ground_cloud_light`]).
    pub cloud_cover: f32,
    /// The sunlight scattered more than once through the clouds
    /// ([`LightVolume`], built for this frame's field, density and sun;
    /// none: the term is left out, as with no octaves, and the light
    /// takes the gains of a renderer without one,
    /// [`super::lighting::LightGains::ALONE`]).
    pub light: Option<&'a LightVolume>,
}

impl Frame<'_> {
    /// What the sky functions read of this frame
    /// ([`super::sky::SkyLight`]).
    pub fn sky_light(&self) -> SkyLight<'_> {
        let mut sky = SkyLight {
            luts: self.sky,
            aerial_perspective: self.quality.atmosphere.aerial_perspective,
            haze_distance_m: self.quality.haze_distance_m,
            camera_altitude_m: self.view.eye().y,
            ground_cloud_light: Vec3::ZERO,
        };
        let sun_dir = sun_direction(self.sun_elevation_deg, self.sun_azimuth_deg);
        let middle = 0.5 * (self.density.band_bottom_m + self.density.band_top_m);
        sky.ground_cloud_light = ground_cloud_light(&sky, sun_dir, self.cloud_cover, middle);
        sky
    }
}

/// The light volume's transported sunlight at `p` scattered toward the
/// eye (`to_eye`, against the ray), per unit scattering coefficient and
/// sun irradiance ([`super::light_volume::LightVolume::light_toward`] times the transport's
/// gain, [`super::lighting::FLUENCE_GAIN`]): 0 without one or without multiple scattering
/// (`octaves` 0).
#[inline]
pub fn diffused_light(p: Vec3, to_eye: Vec3, octaves: u32, fr: &Frame) -> f32 {
    match fr.light {
        Some(v) if octaves > 0 => {
            LightGains::TRANSPORT.fluence * v.light_toward(p, to_eye, fr.density.map_extent_m)
        }
        _ => 0.0,
    }
}
