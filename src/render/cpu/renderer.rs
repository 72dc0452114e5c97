//! The CPU reference renderer: per pixel (rayon over rows), deterministic
//! (ray starts at pixel centres, no jitter), any step count.

use glam::Vec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::camera::Camera;
use super::density::{DensityParams, Fields, band_segment, density_at};
use super::lighting::{integrate_step, sun_optical_depth, sun_scattering};
use super::sky::{sky_radiance, sun_color, sun_direction, sun_disk};
use crate::render::terrain::{Heightfield, TerrainConfig};

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
    /// Distance at which aerial perspective has faded a cloud to 1/e, m.
    pub haze_distance_m: f32,
    /// Rays stop after this distance, m.
    pub max_distance_m: f32,
    /// Exposure multiplier before tone mapping.
    pub exposure: f32,
}

/// Single-scattering albedo of cloud droplets.
pub const ALBEDO: f32 = 0.99;
/// Transmittance below which the march stops (opacity early exit).
pub const MIN_TRANSMITTANCE: f32 = 0.01;

/// Everything a frame needs.
#[derive(Clone, Copy)]
pub struct Frame<'a> {
    pub camera: Camera,
    pub sun_elevation_deg: f32,
    pub sun_azimuth_deg: f32,
    pub fields: Fields<'a>,
    pub density: DensityParams,
    pub quality: Quality,
    /// The terrain, when the scene has one (none: nothing is marched).
    pub terrain: Option<&'a Heightfield>,
}

/// The result of marching one ray: linear radiance and the transmittance
/// of the clouds along it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RaySample {
    pub radiance: Vec3,
    pub transmittance: f32,
}

/// Interleaved gradient noise (Jimenez 2014) in `[0, 1)`: a fixed
/// per-pixel offset of the first march sample that turns step banding into
/// fine noise. Deterministic: the same pixel always gets the same offset.
#[inline]
pub fn pixel_dither(x: u32, y: u32) -> f32 {
    let f = |v: f32| v - v.floor();
    f(52.982_918 * f(0.067_110_56 * x as f32 + 0.005_837_15 * y as f32))
}

/// Sub-samples of a coarse march interval that touches cloud.
pub const REFINE: u32 = 4;

/// Relative sun irradiance: sunlight is about five times the sky's
/// illuminance on a clear day, so a sunlit cloud is brighter than the sky.
pub const SUN_INTENSITY: f32 = 8.0;

/// Marches one ray (the per-pixel function; `march_ray` in WGSL); `dither`
/// in `[0, 1)` places the samples within their steps (0.5: centres).
pub fn march_ray(origin: Vec3, dir: Vec3, dither: f32, fr: &Frame) -> RaySample {
    let d = &fr.density;
    let q = &fr.quality;
    let sun_dir = sun_direction(fr.sun_elevation_deg, fr.sun_azimuth_deg);
    let hit = fr
        .terrain
        .and_then(|h| h.intersect(origin, dir, q.max_distance_m).map(|t| (h, t)));
    let (background, max_t) = match hit {
        Some((h, t)) => (
            terrain_radiance(origin + dir * t, t, dir, sun_dir, h, fr),
            t,
        ),
        None => (
            sky_radiance(dir, sun_dir) + sun_disk(dir, sun_dir),
            q.max_distance_m,
        ),
    };
    let Some((t0, t1)) = band_segment(origin, dir, d.band_bottom_m, d.band_top_m, max_t) else {
        return RaySample {
            radiance: background,
            transmittance: 1.0,
        };
    };
    let steps = q.steps.max(1);
    let dt = (t1 - t0) / steps as f32;
    let sun = sun_color(sun_dir) * SUN_INTENSITY;
    // Irradiance from the upper sky (π L), scattered isotropically (1/4π).
    let ambient_top = sky_radiance(Vec3::Y, sun_dir) * 0.25;
    let cos = dir.dot(sun_dir);
    let mut transmittance = 1.0_f32;
    let mut light = Vec3::ZERO;
    let mut depth_weighted = 0.0_f32;
    // Coarse intervals of `dt`; an interval whose ends touch cloud is
    // sampled REFINE times finer (the dither places the samples), so thin
    // cloud edges seen at grazing angles get several samples, and empty sky
    // costs one density lookup per interval.
    let mut sigma_a = density_at(origin + dir * t0, &fr.fields, d);
    'march: for i in 0..steps {
        let ta = t0 + i as f32 * dt;
        let sigma_b = density_at(origin + dir * (ta + dt), &fr.fields, d);
        let touched = sigma_a > 0.0 || sigma_b > 0.0;
        sigma_a = sigma_b;
        let (n, h) = if touched {
            (REFINE, dt / REFINE as f32)
        } else {
            (1, dt)
        };
        for j in 0..n {
            let t = ta + (j as f32 + dither) * h;
            let p = origin + dir * t;
            let sigma_t = density_at(p, &fr.fields, d);
            if sigma_t <= 0.0 {
                continue;
            }
            let tau_sun = sun_optical_depth(p, sun_dir, q.shadow_steps, &fr.fields, d);
            let eta = ((p.y - d.band_bottom_m) / (d.band_top_m - d.band_bottom_m)).clamp(0.0, 1.0);
            // Sky light from above, darker toward the cloud base.
            let ambient = ambient_top * (0.35 + 0.65 * eta);
            let scatter = sun * sun_scattering(tau_sun, cos, q.octaves) + ambient;
            let s = scatter * (sigma_t * ALBEDO);
            let step_t = (-sigma_t * h).exp();
            light += integrate_step(s, sigma_t, h) * transmittance;
            depth_weighted += t * transmittance * (1.0 - step_t);
            transmittance *= step_t;
            if transmittance < MIN_TRANSMITTANCE {
                break 'march;
            }
        }
    }
    let opacity = 1.0 - transmittance;
    // Aerial perspective: clouds fade into the horizon sky with distance.
    let cloud_distance = if opacity > 0.0 {
        depth_weighted / opacity
    } else {
        0.0
    };
    let haze = (-cloud_distance / q.haze_distance_m.max(1.0)).exp();
    let horizon = sky_radiance(
        Vec3::new(dir.x, dir.y.max(0.0), dir.z).normalize_or(Vec3::Y),
        sun_dir,
    );
    let radiance = light * haze + horizon * (opacity * (1.0 - haze)) + background * transmittance;
    RaySample {
        radiance,
        transmittance,
    }
}

/// Radiance of the terrain at `p` (distance `t` along `dir`): lit by the
/// sun through the clouds (their shadow, when shadows are on) and the sky,
/// faded by aerial perspective.
pub fn terrain_radiance(
    p: Vec3,
    t: f32,
    dir: Vec3,
    sun_dir: Vec3,
    h: &Heightfield,
    fr: &Frame,
) -> Vec3 {
    let d = &fr.density;
    let n = h.normal_at(p.x, p.z);
    let slope = 1.0 - n.y;
    let albedo =
        Vec3::new(0.07, 0.11, 0.04).lerp(Vec3::new(0.16, 0.13, 0.09), (slope * 3.0).min(1.0));
    let shadow = if fr.quality.shadow_steps > 0 && sun_dir.y > 0.0 {
        cloud_shadow(p, sun_dir, fr.quality.shadow_steps * 2, &fr.fields, d)
    } else {
        1.0
    };
    let sun = sun_color(sun_dir) * SUN_INTENSITY;
    let sky = sky_radiance(Vec3::Y, sun_dir);
    let lit = albedo
        * (sun * (n.dot(sun_dir).max(0.0) * shadow / std::f32::consts::PI)
            + sky * (0.5 + 0.5 * n.y));
    let haze = (-t / fr.quality.haze_distance_m.max(1.0)).exp();
    let horizon = sky_radiance(Vec3::new(dir.x, 0.0, dir.z).normalize_or(Vec3::X), sun_dir);
    lit * haze + horizon * (1.0 - haze)
}

/// Transmittance of the cloud band from a ground point `p` toward the sun:
/// `steps` samples across the band segment of the sun ray.
pub fn cloud_shadow(p: Vec3, sun_dir: Vec3, steps: u32, f: &Fields, d: &DensityParams) -> f32 {
    let Some((t0, t1)) = band_segment(p, sun_dir, d.band_bottom_m, d.band_top_m, 20_000.0) else {
        return 1.0;
    };
    let d = &DensityParams {
        detail_strength: 0.0,
        ..*d
    };
    let dt = (t1 - t0) / steps.max(1) as f32;
    let tau: f32 = (0..steps.max(1))
        .map(|i| density_at(p + sun_dir * (t0 + (i as f32 + 0.5) * dt), f, d) * dt)
        .sum();
    (-tau).exp()
}

/// Renders a `width x height` image of linear radiance, row-major.
pub fn render_linear(width: u32, height: u32, fr: &Frame) -> Vec<Vec3> {
    let w = width as usize;
    let mut out = vec![Vec3::ZERO; w * height as usize];
    out.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            for (x, px) in row.iter_mut().enumerate() {
                let dir = fr.camera.ray(x as f32 + 0.5, y as f32 + 0.5, width, height);
                *px = march_ray(
                    fr.camera.position_m,
                    dir,
                    pixel_dither(x as u32, y as u32),
                    fr,
                )
                .radiance;
            }
        });
    out
}

/// The tone map, `1 - e^{-x·exposure}`: linear radiance to display `0..1`.
/// The images and the quality report both use it.
#[inline]
pub fn tone_map(c: f32, exposure: f32) -> f32 {
    1.0 - (-c.max(0.0) * exposure).exp()
}

/// Tone map ([`tone_map`]) and sRGB-encode to 8 bits.
pub fn to_srgb8(linear: &[Vec3], exposure: f32) -> Vec<u8> {
    let enc = |c: f32| {
        let x = tone_map(c, exposure);
        let s = if x <= 0.003_130_8 {
            12.92 * x
        } else {
            1.055 * x.powf(1.0 / 2.4) - 0.055
        };
        (s.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
    };
    linear
        .iter()
        .flat_map(|c| [enc(c.x), enc(c.y), enc(c.z)])
        .collect()
}

/// The `[render]` scene table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
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
    /// evaluated). Default 0.5.
    pub detail_strength: f32,
    /// Size of the detail noise's features, m (> 0). Default 250.
    pub detail_scale_m: f32,
    /// Primary march steps (1..=4096). Default 48 (chosen from
    /// `cumulus render --quality-report`, see README).
    pub steps: u32,
    /// Shadow march steps toward the sun (0..=64; 0 = off). Default 6.
    pub shadow_steps: u32,
    /// Multiple-scattering octaves beyond the first (0..=3). Default 2.
    pub octaves: u32,
    /// Aerial-perspective distance, m (> 0). Default 25000.
    pub haze_distance_m: f32,
    /// Longest ray, m (> 0). Default 40000.
    pub max_distance_m: f32,
    /// Exposure before tone mapping (> 0). Default 1.2.
    pub exposure: f32,
    /// Physics seconds simulated before the picture (>= 0). Default 2400.
    pub time_s: f64,
    /// Temporal anti-aliasing on the GPU (the CPU reference never jitters).
    /// Off: no jitter, no history textures, no TSAA pass. Default true.
    pub tsaa: bool,
    /// Weight of each new frame in the TSAA history, (0, 1]. Default 0.1.
    pub tsaa_blend: f32,
    /// The cloud map (`[render.cloud_map]`).
    pub cloud_map: crate::render::cloud_map::CloudMapConfig,
    /// The terrain (`[render.terrain]`), off by default.
    pub terrain: TerrainConfig,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
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
            detail_strength: 0.5,
            detail_scale_m: 250.0,
            steps: 48,
            shadow_steps: 6,
            octaves: 2,
            haze_distance_m: 25_000.0,
            max_distance_m: 40_000.0,
            exposure: 1.2,
            time_s: 2400.0,
            tsaa: true,
            tsaa_blend: 0.1,
            cloud_map: Default::default(),
            terrain: TerrainConfig::default(),
        }
    }
}

impl RenderSettings {
    /// The camera.
    pub fn camera(&self) -> Camera {
        Camera {
            position_m: Vec3::from_array(self.camera_position_m),
            yaw_deg: self.camera_yaw_deg,
            pitch_deg: self.camera_pitch_deg,
            fov_deg: self.fov_deg,
        }
    }

    /// The quality knobs.
    pub fn quality(&self) -> Quality {
        Quality {
            steps: self.steps,
            shadow_steps: self.shadow_steps,
            octaves: self.octaves,
            haze_distance_m: self.haze_distance_m,
            max_distance_m: self.max_distance_m,
            exposure: self.exposure,
        }
    }
}
