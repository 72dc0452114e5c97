//! [`GpuSettings`]: what the wgpu renderer draws and how well, and the
//! WGSL `override` constants they compile to.

use glam::Vec3;

use super::tsaa::TsaaSettings;
use crate::render::cpu::density::DensityParams;
use crate::render::cpu::frame::Quality;
use crate::render::cpu::sky::sun_direction;
use crate::render::cpu::sky_luts::SkyParams;

/// What the renderer draws and how well. Changing it with
/// [`CloudRenderer::set_settings`](super::CloudRenderer::set_settings) rebuilds only what changed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpuSettings {
    pub density: DensityParams,
    pub quality: Quality,
    pub sun_elevation_deg: f32,
    pub sun_azimuth_deg: f32,
    /// Temporal anti-aliasing (none: no jitter, no history textures, no pass).
    pub tsaa: Option<TsaaSettings>,
    /// Debug: the cloud layer's red channel holds the number of density
    /// samples each pixel took (its alpha is 0), to show that the per-pixel
    /// work does not depend on the parcel count.
    pub debug_sample_count: bool,
}

impl GpuSettings {
    /// Whether the 3D detail noise is on (its volume is uploaded and its
    /// reads compiled in).
    pub fn detail(&self) -> bool {
        self.density.detail_strength > 0.0
    }

    /// Whether the detail volume is uploaded: the detail noise reads it,
    /// and so do the land's woods ([`crate::render::cpu::land`]); with
    /// neither, a 1³ stand-in is bound.
    pub fn noise_volume(&self) -> bool {
        self.detail() || self.quality.land_fields
    }

    /// Whether the fine billows near the camera are compiled in: with the
    /// detail noise and `[render] fine_detail`.
    pub fn fine_detail(&self) -> bool {
        self.detail() && self.density.fine_detail
    }

    /// Whether the light volume exists: with multiple scattering on
    /// (`octaves > 0`), as on the CPU ([`crate::prepare::Prepared::frame`]).
    pub fn light_volume(&self) -> bool {
        self.quality.octaves > 0
            && self.quality.light_photons > 0
            && !self.quality.single_scattering
    }

    /// The physical sky's atmosphere (`None`: the analytic sky).
    pub fn sky_params(&self) -> Option<SkyParams> {
        self.quality.atmosphere.sky_params()
    }

    /// Unit vector toward the sun.
    pub fn sun_dir(&self) -> Vec3 {
        sun_direction(self.sun_elevation_deg, self.sun_azimuth_deg)
    }

    /// Values of the WGSL `override` constants (`shaders/frame.wgsl`, and
    /// `LAND_FIELDS` in `shaders/land.wgsl`) for these settings: a feature
    /// that is off is compiled out.
    pub fn constants(&self) -> Vec<(&'static str, f64)> {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let cirrus = self.quality.cirrus;
        vec![
            ("SHADOW_STEPS", self.quality.shadow_steps as f64),
            ("OCTAVES", self.quality.octaves as f64),
            ("DETAIL", flag(self.detail())),
            ("FINE_DETAIL", flag(self.fine_detail())),
            ("DEBUG_COUNT", flag(self.debug_sample_count)),
            ("SEA", flag(self.quality.sea_wind_mps.is_some())),
            ("LAND_FIELDS", flag(self.quality.land_fields)),
            (
                "AERIAL_PERSPECTIVE",
                flag(self.quality.atmosphere.aerial_perspective),
            ),
            ("LIGHT_VOLUME", flag(self.light_volume())),
            (
                "SEA_WIND_MPS",
                self.quality.sea_wind_mps.unwrap_or_default() as f64,
            ),
            (
                "SEA_WIND_TOWARD_DEG",
                self.quality.sea_wind_toward_deg as f64,
            ),
            ("CIRRUS", flag(cirrus.is_some())),
            ("CIRRUS_COVER", cirrus.map_or(0.0, |c| c.cover as f64)),
            (
                "CIRRUS_ALTITUDE_M",
                cirrus.map_or(9000.0, |c| c.altitude_m as f64),
            ),
            (
                "CIRRUS_DIRECTION_DEG",
                cirrus.map_or(60.0, |c| c.direction_deg as f64),
            ),
            (
                "CIRRUS_OPTICAL_DEPTH",
                cirrus.map_or(0.2, |c| c.optical_depth as f64),
            ),
        ]
    }
}
