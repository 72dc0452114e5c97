//! What the sky demo's control panel edits (`examples/sky`), as plain data
//! in the panel's units, and its mapping to and from a [`Scene`]: the
//! panel saves to and loads from scene files, so a tuned sky is a scene
//! like any other. (Kept in the library, without egui, so the round trip
//! is tested.)

use crate::render::cpu::sky::{Land, SkyModel};
use crate::scene::Scene;
use crate::sim::Band;

/// The panel's scene-backed controls. Run-time controls (simulation
/// speed, pause, debug views) are not part of a scene and not here.
#[derive(Debug, Clone, PartialEq)]
pub struct PanelState {
    /// Fraction of each covered cloud-map cell that becomes cloud, 0..=1.
    pub coverage: f32,
    /// Number of parcels.
    pub parcels: usize,
    /// Wind at the ground, m/s.
    pub wind_speed_mps: f64,
    /// Direction the wind blows toward, degrees clockwise from north.
    pub wind_direction_deg: f64,
    /// Sun elevation, degrees.
    pub sun_elevation_deg: f32,
    /// Sun azimuth, degrees clockwise from north.
    pub sun_azimuth_deg: f32,
    /// Cloud band bottom, m.
    pub band_bottom_m: f64,
    /// Cloud band top, m.
    pub band_top_m: f64,
    /// Temporal anti-aliasing.
    pub tsaa: bool,
    /// Primary ray-march steps.
    pub steps: u32,
    /// Shadow-ray steps (0: no self-shadowing).
    pub shadow_steps: u32,
    /// Multiple-scattering octaves, 0..=3.
    pub octaves: u32,
    /// The terrain.
    pub terrain: bool,
    /// The land as fields and woods (off: plain; `[render.ground] land`).
    pub fields: bool,
    /// The fine billows near the camera (`[render] fine_detail`).
    pub fine_detail: bool,
    /// The physical sky (off: the analytic one).
    pub physical_sky: bool,
    /// The physical sky's aerosol optical depth, 0..=3.
    pub aerosol_optical_depth: f32,
    /// Exposure before the tone map (`[render] exposure`).
    pub exposure: f32,
    /// The exposure opened below a 5° sun (`[render] auto_exposure`).
    pub auto_exposure: bool,
    /// The sun's glare, 0 off (`[render] sun_glare`).
    pub sun_glare: f32,
}

impl PanelState {
    /// The panel showing `scene`, whose cloud band resolves to `band`.
    pub fn from_scene(scene: &Scene, band: Band) -> Self {
        let r = &scene.render;
        Self {
            coverage: r.coverage,
            parcels: scene.physics.parcels,
            wind_speed_mps: scene.physics.wind.speed_mps,
            wind_direction_deg: scene.physics.wind.direction_deg,
            sun_elevation_deg: r.sun_elevation_deg,
            sun_azimuth_deg: r.sun_azimuth_deg,
            band_bottom_m: band.bottom_m,
            band_top_m: band.top_m,
            tsaa: r.tsaa,
            steps: r.steps,
            shadow_steps: r.shadow_steps,
            octaves: r.octaves,
            terrain: r.terrain.enabled,
            fields: r.ground.land == Land::Fields,
            fine_detail: r.fine_detail,
            physical_sky: r.atmosphere.model == SkyModel::Physical,
            aerosol_optical_depth: r.atmosphere.aerosol_optical_depth,
            exposure: r.exposure,
            auto_exposure: r.auto_exposure,
            sun_glare: r.sun_glare,
        }
    }

    /// Writes the panel's values into `scene` (the band becomes explicit).
    pub fn apply(&self, scene: &mut Scene) {
        let r = &mut scene.render;
        r.coverage = self.coverage;
        r.sun_elevation_deg = self.sun_elevation_deg;
        r.sun_azimuth_deg = self.sun_azimuth_deg;
        r.tsaa = self.tsaa;
        r.steps = self.steps;
        r.shadow_steps = self.shadow_steps;
        r.octaves = self.octaves;
        r.terrain.enabled = self.terrain;
        r.fine_detail = self.fine_detail;
        r.ground.land = if self.fields {
            Land::Fields
        } else {
            Land::Plain
        };
        r.atmosphere.model = if self.physical_sky {
            SkyModel::Physical
        } else {
            SkyModel::Analytic
        };
        r.atmosphere.aerosol_optical_depth = self.aerosol_optical_depth;
        r.exposure = self.exposure;
        r.auto_exposure = self.auto_exposure;
        r.sun_glare = self.sun_glare;
        scene.physics.parcels = self.parcels;
        scene.physics.wind.speed_mps = self.wind_speed_mps;
        scene.physics.wind.direction_deg = self.wind_direction_deg;
        scene.projection.band_bottom_m = Some(self.band_bottom_m);
        scene.projection.band_top_m = Some(self.band_top_m);
    }
}
