//! `[render]`: the picture (size, camera, sun), the density and quality
//! knobs, the cloud map and the terrain. Every key is in `docs/scene.md`.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::render::camera::Camera;
use crate::render::cloud_map::CloudMapConfig;
use crate::render::cpu::cirrus::CirrusLayer;
use crate::render::cpu::density::DensityParams;
use crate::render::cpu::exposure::auto_exposure_factor;
use crate::render::cpu::frame::Quality;
use crate::render::cpu::sky::{AtmosphereConfig, GroundConfig};
use crate::render::gpu::terrain_pass::TERRAIN_REACH_MAX;
use crate::render::gpu::{GpuSettings, TsaaSettings};
use crate::render::terrain::TerrainConfig;
use crate::sim::{Band, Check};

/// The renderer a scene draws its clouds with (`[render] renderer`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RenderMethod {
    /// P and the cloud map (Goswami 2019).
    #[default]
    CloudMap,
    /// A pseudo-spheroid per cloudy parcel (Jimenez de Parga & Gomez
    /// Palomo 2018).
    Spheroids,
}

/// How a CPU still spends its marches (`[render] cpu_sampling`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CpuSampling {
    /// One march a pixel, all `cpu_offsets` only where the picture has an
    /// edge, the dither's grain filtered out of the clouds elsewhere
    /// (`render::cpu::still_reconstruction`).
    #[default]
    Adaptive,
    /// `cpu_offsets` marches through every pixel, averaged.
    Uniform,
}

/// The `[render]` scene table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
    /// Which renderer draws the clouds: `"cloud_map"` (default: P and the
    /// cloud map, Goswami 2019) or `"spheroids"` (each cloudy parcel a
    /// pseudo-spheroid, Jimenez de Parga & Gomez Palomo 2018).
    pub renderer: RenderMethod,
    /// Image width, pixels (1..=8192). Default 640.
    pub width: u32,
    /// Image height, pixels (1..=8192). Default 480.
    pub height: u32,
    /// Camera position `[x east, y up, z north]`, m. Default `[0, 100, 0]`.
    pub camera_position_m: [f32; 3],
    /// Camera heading, degrees clockwise from north. Default 20.
    pub camera_yaw_deg: f32,
    /// Camera pitch above the horizon, degrees (-89..=89). Default 12.
    pub camera_pitch_deg: f32,
    /// Vertical field of view, degrees (1..=170). Default 60.
    pub fov_deg: f32,
    /// Sun elevation above the horizon, degrees (-10..=90). Default 40.
    pub sun_elevation_deg: f32,
    /// Sun azimuth, degrees clockwise from north. Default 135.
    pub sun_azimuth_deg: f32,
    /// Fraction of each P-covered cloud-map cell that becomes cloud, 0..=1.
    /// Default 0.75.
    pub coverage: f32,
    /// Extinction of the densest cloud, 1/m (> 0). Default 0.04.
    pub extinction_per_m: f32,
    /// Strength of the 3D detail noise eroding edges, 0..=1 (0: off, not
    /// evaluated). Default 0.6; at the cloud base 0.6 of it erodes, growing
    /// to all of it at the top (`render::cpu::density::erosion_strength`).
    pub detail_strength: f32,
    /// Size of the detail noise's largest features, m (> 0). Default 180.
    pub detail_scale_m: f32,
    /// The fine billows near the camera (`render::cpu::density::detail_fine`:
    /// the detail volume again at 4 times the base's frequency, where a
    /// pixel covers under 6 m). Default true; the path-traced comparisons
    /// turn it off, since the exported grid (9.7 m cells) cannot hold it.
    pub fine_detail: bool,
    /// Primary march steps (1..=4096). Default 48 (chosen from
    /// `cumulus render --quality-report`; docs/renderer.md, "Error against
    /// cost (rendering)").
    pub steps: u32,
    /// Shadow march steps toward the sun (0..=64; 0 = off). Default 20:
    /// fewer, longer steps miss small wisps and leak light (against the
    /// path tracer on a 1024-cell grid, the backlit view's single
    /// scattering measured 12.4 % off per pixel at 20, 9.5 % at 32, 9.0 %
    /// at 64, and 35 % at 12 with the samples at their steps' centres;
    /// docs/ground_truth/single_scattering.sh). With a light volume a ray
    /// away from the sun takes at most 6 of them over its first 200 m and
    /// the sun's depth beyond from the volume
    /// (`render::cpu::lighting::near_shadow_ray`).
    pub shadow_steps: u32,
    /// Multiple-scattering octaves beyond the first (0..=3). Default 3
    /// (the light was fitted to the path tracer with 3). 0 turns multiple
    /// scattering off, the sunlight diffused through the layer and the
    /// light volume with it.
    pub octaves: u32,
    /// Photons the light volume traces per column of its cells (80 m wide)
    /// (0..=65536; [`crate::render::cpu::light_volume`]). Default 96: 1.5
    /// M photons over the fair-weather domain, built in about 4 s on a
    /// 2-core CPU, its directional part smoothed over neighbouring cells
    /// (`light_volume::filter_cells`). Against the path tracer that is
    /// 9.1-10.5 % per pixel over the six views, each within a point of
    /// its figure at 1024 (8.9-9.6 %), the count the light was fitted
    /// with, which takes 15 times as long to build; 64 leaves the backlit
    /// view 1.4 points worse (docs/ground_truth/README.md, "Photons
    /// against error and time"). 0 leaves the light volume out (the
    /// octaves alone carry multiple scattering).
    pub light_photons: u32,
    /// The analytic sky's aerial-perspective distance, m (> 0). Default
    /// 25000 (the physical sky's haze comes from its air,
    /// `[render.atmosphere]`).
    pub haze_distance_m: f32,
    /// Longest ray, m (> 0). Default 40000.
    pub max_distance_m: f32,
    /// Exposure before tone mapping (> 0). Default 1.2.
    pub exposure: f32,
    /// Opens the exposure below a sun 5° high as the ground's light
    /// fades (`render::cpu::exposure`), so sunsets and twilight are not
    /// black. Default true; no shipped scene's sun is that low.
    pub auto_exposure: bool,
    /// The sun's glare in the tone-mapped pictures (`render::cpu::glare`):
    /// the light a lens and an eye scatter around the sun disk, 1 the
    /// CIE's spread for the eye near the sun, 0 none (0..=10). Default 1.
    /// The linear outputs (OpenEXR, an HDR target) never have it.
    pub sun_glare: f32,
    /// Physics seconds simulated before the picture (>= 0). Default 2400.
    pub time_s: f64,
    /// Temporal anti-aliasing on the GPU (CPU pictures average
    /// `cpu_offsets` of the same jittered frames instead).
    /// Off: no jitter, no history textures, no TSAA pass. Default true.
    pub tsaa: bool,
    /// Weight of each new frame in the TSAA history, (0, 1]. Default 0.1.
    pub tsaa_blend: f32,
    /// CPU pictures: the marches a pixel takes, averaged, march `k` as the
    /// GPU's TSAA frame `k` (its sub-pixel jitter, which anti-aliases
    /// edges, and its golden-ratio dither offset, which moves the samples
    /// and the shadow samples within their steps; `render_still`): every
    /// pixel's with `cpu_sampling = "uniform"`, the edges' with
    /// `"adaptive"` (the rest take one). 1: one march through each
    /// pixel's centre (1..=64). Default 4: with adaptive sampling on fair
    /// weather, 8 costs 1.4 times the marches for a still measured 0.09
    /// levels closer to the converged one (docs/renderer.md, "Error
    /// against cost (stills)"). The endless volumes' pictures average the
    /// dither offsets through pixel centres (no TSAA on their GPU pass);
    /// the spheroids' take one march.
    pub cpu_offsets: u32,
    /// How CPU stills of the cloud map spend their marches: `"adaptive"`
    /// (default: one march a pixel, `cpu_offsets` at edges, the grain
    /// filtered; about a fifth of the marches) or `"uniform"`
    /// (`cpu_offsets` everywhere). docs/renderer.md, "Error against cost
    /// (stills)", has each one's error against the converged picture.
    pub cpu_sampling: CpuSampling,
    /// The cloud map (`[render.cloud_map]`).
    pub cloud_map: CloudMapConfig,
    /// The terrain (`[render.terrain]`), off by default.
    pub terrain: TerrainConfig,
    /// The ground where there is no terrain (`[render.ground]`): land by
    /// default, or the sea.
    pub ground: GroundConfig,
    /// The sky model and aerial perspective (`[render.atmosphere]`):
    /// physical by default.
    pub atmosphere: AtmosphereConfig,
    /// The cirrus layer above the clouds (`[render.cirrus]`): none by
    /// default (`cover = 0`).
    pub cirrus: CirrusLayer,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            renderer: RenderMethod::CloudMap,
            width: 640,
            height: 480,
            camera_position_m: [0.0, 100.0, 0.0],
            camera_yaw_deg: 20.0,
            camera_pitch_deg: 12.0,
            fov_deg: 60.0,
            sun_elevation_deg: 40.0,
            sun_azimuth_deg: 135.0,
            coverage: 0.75,
            extinction_per_m: 0.04,
            detail_strength: 0.6,
            detail_scale_m: 180.0,
            fine_detail: true,
            steps: 48,
            shadow_steps: 20,
            octaves: 3,
            light_photons: 96,
            haze_distance_m: 25_000.0,
            max_distance_m: 40_000.0,
            exposure: 1.2,
            auto_exposure: true,
            sun_glare: 1.0,
            time_s: 2400.0,
            tsaa: true,
            tsaa_blend: 0.1,
            cpu_offsets: 4,
            cpu_sampling: CpuSampling::Adaptive,
            cloud_map: Default::default(),
            terrain: TerrainConfig::default(),
            ground: GroundConfig::default(),
            atmosphere: AtmosphereConfig::default(),
            cirrus: CirrusLayer::default(),
        }
    }
}

/// How far the camera may be from the origin horizontally, m.
const CAMERA_REACH_M: f32 = 1e6;

impl RenderSettings {
    /// Every key against its domain.
    pub fn checks(&self) -> Vec<Check> {
        let r = self;
        let f = |v: f32| v as f64;
        let range = Check::range;
        vec![
            Check::new(
                "render.width",
                (1..=8192).contains(&r.width),
                "1..=8192 pixels",
                f(r.width as f32),
            ),
            Check::new(
                "render.height",
                (1..=8192).contains(&r.height),
                "1..=8192 pixels",
                f(r.height as f32),
            ),
            Check::new(
                "render.camera_position_m",
                r.camera_position_m.iter().all(|x| x.is_finite()),
                "three finite numbers [x, y, z] in m",
                f(r.camera_position_m[1]),
            ),
            // Beyond this the f32 ray maths loses the cloud band (a camera
            // at 1e9 m draws a black picture).
            Check::new(
                "render.camera_position_m",
                r.camera_position_m[0].abs() <= CAMERA_REACH_M
                    && r.camera_position_m[2].abs() <= CAMERA_REACH_M,
                "x and z within ±1e6 m",
                f(r.camera_position_m[0]
                    .abs()
                    .max(r.camera_position_m[2].abs())),
            ),
            Check::new(
                "render.camera_position_m",
                (-1e3..=1e5).contains(&r.camera_position_m[1]),
                "a height y within -1000..=100000 m",
                f(r.camera_position_m[1]),
            ),
            Check::new(
                "render.camera_yaw_deg",
                r.camera_yaw_deg.is_finite(),
                "a finite angle",
                f(r.camera_yaw_deg),
            ),
            range(
                "render.camera_pitch_deg",
                f(r.camera_pitch_deg),
                -89.0,
                89.0,
                "-89..=89 degrees",
            ),
            range(
                "render.fov_deg",
                f(r.fov_deg),
                1.0,
                170.0,
                "1..=170 degrees",
            ),
            range(
                "render.sun_elevation_deg",
                f(r.sun_elevation_deg),
                -10.0,
                90.0,
                "-10..=90 degrees",
            ),
            Check::new(
                "render.sun_azimuth_deg",
                r.sun_azimuth_deg.is_finite(),
                "a finite angle",
                f(r.sun_azimuth_deg),
            ),
            range("render.coverage", f(r.coverage), 0.0, 1.0, "0..=1"),
            range(
                "render.detail_strength",
                f(r.detail_strength),
                0.0,
                1.0,
                "0..=1",
            ),
            range(
                "render.detail_scale_m",
                f(r.detail_scale_m),
                1.0,
                1e5,
                "1..=1e5 m",
            ),
            range(
                "render.extinction_per_m",
                f(r.extinction_per_m),
                1e-6,
                10.0,
                "1e-6..=10 1/m",
            ),
            Check::new(
                "render.steps",
                (1..=4096).contains(&r.steps),
                "1..=4096",
                r.steps as f64,
            ),
            Check::new(
                "render.shadow_steps",
                r.shadow_steps <= 64,
                "0..=64",
                r.shadow_steps as f64,
            ),
            Check::new("render.octaves", r.octaves <= 3, "0..=3", r.octaves as f64),
            Check::new(
                "render.light_photons",
                r.light_photons <= 65_536,
                "0..=65536",
                r.light_photons as f64,
            ),
            range(
                "render.haze_distance_m",
                f(r.haze_distance_m),
                1.0,
                1e7,
                "1..=1e7 m",
            ),
            range(
                "render.max_distance_m",
                f(r.max_distance_m),
                1.0,
                1e7,
                "1..=1e7 m",
            ),
            range("render.exposure", f(r.exposure), 1e-3, 1e3, "0.001..=1000"),
            range("render.sun_glare", f(r.sun_glare), 0.0, 10.0, "0..=10"),
            range("render.time_s", r.time_s, 0.0, 1e7, "0..=1e7 s"),
            range("render.tsaa_blend", f(r.tsaa_blend), 1e-3, 1.0, "0.001..=1"),
            Check::new(
                "render.cpu_offsets",
                (1..=64).contains(&r.cpu_offsets),
                "1..=64",
                r.cpu_offsets as f64,
            ),
            Check::new(
                "render.cloud_map.size",
                (16..=2048).contains(&r.cloud_map.size),
                "16..=2048 texels",
                r.cloud_map.size as f64,
            ),
            range(
                "render.cloud_map.cells",
                r.cloud_map.cells,
                1.0,
                64.0,
                "1..=64",
            ),
            range(
                "render.cloud_map.roughness",
                r.cloud_map.roughness,
                0.3,
                0.95,
                "0.3..=0.95",
            ),
            range(
                "render.terrain.relief_m",
                f(r.terrain.relief_m),
                0.0,
                5000.0,
                "0..=5000 m",
            ),
            range(
                "render.terrain.extent_m",
                f(r.terrain.extent_m),
                1.0,
                1e7,
                "1..=1e7 m",
            ),
            Check::new(
                "render.terrain.extent_m",
                !r.terrain.enabled
                    || r.max_distance_m / r.terrain.extent_m <= TERRAIN_REACH_MAX as f32,
                format!(
                    "at least render.max_distance_m / {TERRAIN_REACH_MAX} = {} m with the \
                     terrain on (it repeats every extent_m, and the GPU draws a copy per \
                     repeat out to max_distance_m)",
                    r.max_distance_m / TERRAIN_REACH_MAX as f32
                ),
                f(r.terrain.extent_m),
            ),
            range("render.terrain.hills", r.terrain.hills, 1.0, 64.0, "1..=64"),
            range(
                "render.atmosphere.aerosol_optical_depth",
                f(r.atmosphere.aerosol_optical_depth),
                0.0,
                3.0,
                "0..=3",
            ),
            range("render.cirrus.cover", f(r.cirrus.cover), 0.0, 1.0, "0..=1"),
            range(
                "render.cirrus.altitude_m",
                f(r.cirrus.altitude_m),
                4000.0,
                15000.0,
                "4000..=15000 m",
            ),
            range(
                "render.cirrus.direction_deg",
                f(r.cirrus.direction_deg),
                -360.0,
                360.0,
                "-360..=360 degrees",
            ),
            range(
                "render.cirrus.optical_depth",
                f(r.cirrus.optical_depth),
                0.0,
                3.0,
                "0..=3",
            ),
            range(
                "render.ground.wind_speed_mps",
                f(r.ground.wind_speed_mps),
                0.0,
                30.0,
                "0..=30 m/s",
            ),
            range(
                "render.ground.wind_direction_deg",
                f(r.ground.wind_direction_deg),
                -360.0,
                360.0,
                "-360..=360 degrees",
            ),
            Check::new(
                "render.terrain.size",
                (16..=2048).contains(&r.terrain.size),
                "16..=2048 texels",
                r.terrain.size as f64,
            ),
            Check::new(
                "render.cloud_map.octaves",
                (1..=10).contains(&r.cloud_map.octaves),
                "1..=10",
                r.cloud_map.octaves as f64,
            ),
        ]
    }

    /// The camera.
    pub fn camera(&self) -> Camera {
        Camera {
            position_m: Vec3::from_array(self.camera_position_m),
            yaw_deg: self.camera_yaw_deg,
            pitch_deg: self.camera_pitch_deg,
            fov_deg: self.fov_deg,
        }
    }

    /// The wgpu renderer's settings for this section over the cloud `band`
    /// of a physics domain of side `map_extent_m` (the scene's
    /// `physics.domain_size_m`), at this section's quality.
    pub fn gpu_settings(&self, band: Band, map_extent_m: f64) -> GpuSettings {
        self.gpu_settings_at(band, map_extent_m, self.quality())
    }

    /// [`Self::gpu_settings`] at another `quality`.
    pub fn gpu_settings_at(&self, band: Band, map_extent_m: f64, quality: Quality) -> GpuSettings {
        GpuSettings {
            density: self.density(band, map_extent_m),
            quality,
            sun_elevation_deg: self.sun_elevation_deg,
            sun_azimuth_deg: self.sun_azimuth_deg,
            tsaa: self.tsaa.then_some(TsaaSettings {
                blend: self.tsaa_blend,
            }),
            debug_sample_count: false,
        }
    }

    /// The density's parameters for this section, a cloud band and the
    /// map's extent (the physics domain).
    pub fn density(&self, band: Band, map_extent_m: f64) -> DensityParams {
        DensityParams {
            band_bottom_m: band.bottom_m as f32,
            band_top_m: band.top_m as f32,
            coverage: self.coverage,
            extinction_per_m: self.extinction_per_m,
            map_extent_m: map_extent_m as f32,
            detail_strength: self.detail_strength,
            detail_scale_m: self.detail_scale_m,
            fine_detail: self.fine_detail,
        }
    }

    /// The factor on `exposure` of `auto_exposure`: 1 when off or under a
    /// sun at least 5° high; below it, metered from the clear sky's light
    /// on the ground at the camera's altitude
    /// ([`auto_exposure_factor`]; under the physical sky its tables are
    /// built on the CPU once per sky).
    pub fn exposure_factor(&self) -> f32 {
        if !self.auto_exposure {
            return 1.0;
        }
        auto_exposure_factor(
            &self.atmosphere,
            self.sun_elevation_deg,
            self.camera_position_m[1],
        )
    }

    /// The quality knobs (the exposure metered by [`Self::exposure_factor`]).
    pub fn quality(&self) -> Quality {
        Quality {
            steps: self.steps,
            shadow_steps: self.shadow_steps,
            octaves: self.octaves,
            light_photons: self.light_photons,
            haze_distance_m: self.haze_distance_m,
            max_distance_m: self.max_distance_m,
            exposure: self.exposure * self.exposure_factor(),
            sun_glare: self.sun_glare,
            sea_wind_mps: self.ground.sea_wind_mps(),
            sea_wind_toward_deg: self.ground.wind_direction_deg,
            sea_time_s: self.time_s as f32,
            land_fields: self.ground.land_fields(),
            atmosphere: self.atmosphere,
            cirrus: self.cirrus.drawn(),
            single_scattering: false,
        }
    }
}
