//! [`GpuSettings`]: what the wgpu renderer draws and how well, and the
//! WGSL `override` constants they compile to.

use super::tsaa::TsaaSettings;
use crate::render::cpu::density::DensityParams;
use crate::render::cpu::renderer::Quality;

/// What the renderer draws and how well. Changing it with
/// [`CloudRenderer::set_settings`] rebuilds only what changed.
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

    /// Values of the WGSL `override` constants (`shaders/clouds.wgsl`) for
    /// these settings: a feature that is off is compiled out.
    pub fn constants(&self) -> Vec<(&'static str, f64)> {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        vec![
            ("SHADOW_STEPS", self.quality.shadow_steps as f64),
            ("OCTAVES", self.quality.octaves as f64),
            ("DETAIL", flag(self.detail())),
            ("DEBUG_COUNT", flag(self.debug_sample_count)),
            ("SEA", flag(self.quality.sea_wind_mps.is_some())),
            (
                "SEA_WIND_MPS",
                self.quality.sea_wind_mps.unwrap_or_default() as f64,
            ),
        ]
    }
}
