//! The CPU reference renderer: per pixel (rayon over rows), deterministic
//! (one frame: rays through pixel centres, each pixel's blue-noise dither),
//! any step count; the converged oracle that averages the very frames
//! the GPU's TSAA accumulates (`render_converged`); and the CLI's stills,
//! the first `cpu_offsets` of those frames (`render_still`).

use glam::Vec3;
use std::f32::consts::PI;

use super::cirrus::cirrus_over;
use super::density::{band_segment, density_at};
use super::frame::{Frame, MIN_TRANSMITTANCE, diffused_light};
use super::land::{flat_ground_albedo, terrain_albedo};
use super::lighting::{
    ALBEDO, ShadowSteps, ambient_light, cloud_shadow, forward_step_factor, integrate_step,
    light_gains, near_sun_optical_depth, shadow_march, shadow_offset, shadow_ray_length,
    shadow_step_count, sun_scattering, toward_sun,
};
use super::sea::sea_reflection_change;
use super::sea::sea_waves_at;
use super::sky::{
    aerial, background_radiance, ground_up, sky_ambient, sun_direction, sun_light_at,
};
use crate::render::sampling;
use crate::render::terrain::Heightfield;

/// The result of marching one ray: linear radiance and the transmittance
/// of the clouds along it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RaySample {
    /// Everything the ray sees: the clouds over the sky or terrain.
    pub radiance: Vec3,
    /// The clouds' own light (with the haze in front of them),
    /// premultiplied: `radiance = clouds + transmittance · background`.
    pub clouds: Vec3,
    pub transmittance: f32,
    /// The density reads the clouds' march took (its shadow rays' too;
    /// the ground's shadow is not counted): what `debug_sample_count`
    /// counts on the GPU.
    pub reads: u32,
}

/// The pixel's offset of its march samples within their steps, in `(0,
/// 1)`: the blue-noise tile (`render::sampling`), which turns step banding
/// into fine grain without the checker and moire of a structured pattern.
/// Each frame adds its golden-ratio offset (`sampling::frame_offset`).
#[inline]
pub fn pixel_dither(x: u32, y: u32) -> f32 {
    sampling::at(x, y)
}

/// Distance scale of the march's step growth, m: coarse steps are
/// uniform in `ln(t + NEAR_M)`, so a step is about `(t + NEAR_M) / steps
/// · ln((t1 + NEAR_M) / (t0 + NEAR_M))` long: short near the camera, where
/// a pixel covers little and clouds are large on screen, long far away
/// (looking down on the band, `t1 / t0` is near 1 and the steps are
/// uniform). 3 km: along a horizontal ray through a 50 km band the first
/// of 48 steps is 185 m and the last 3.1 km (uniform: 1 km each).
pub const NEAR_M: f32 = 3000.0;

/// The distance at march parameter `s` (0 at `t0`, 1 at the segment's far
/// end, `log_ratio = ln((t1 + NEAR_M) / (t0 + NEAR_M))`).
#[inline]
pub fn march_distance(t0: f32, log_ratio: f32, s: f32) -> f32 {
    (t0 + NEAR_M) * (s * log_ratio).exp() - NEAR_M
}

/// The widest span of `ln(t + NEAR_M)` that the scene's `steps` coarse
/// steps cover: a ray whose band segment spans more (one that crosses the
/// band at a grazing angle: from the ground under the default band, any
/// ray lower than about 40°) takes proportionally more steps, so no
/// coarse step is longer, for its distance, than such a ray's. With 48
/// steps over a ray 3° up (the band from 10 to 30 km away) the steps
/// were 250-640 m: the clouds that fall between two steps' ends were hit
/// only by the dither's samples, drawn as stripes and grain along the
/// horizon; at 2.6 times the steps they are whole.
pub const MARCH_LOG_SPAN: f32 = 0.35;

/// The most steps a grazing ray takes, as a multiple of the scene's
/// `steps` (a horizontal ray through the band from inside it spans
/// `ln(43 / 3) = 2.7`, which would ask for 7.6 times).
pub const MARCH_STEP_FACTOR_MAX: f32 = 4.0;

/// The coarse steps of a band segment that spans `log_ratio` of
/// `ln(t + NEAR_M)` ([`march_distance`]): `steps`, times the span over
/// [`MARCH_LOG_SPAN`] where it is wider, at most
/// [`MARCH_STEP_FACTOR_MAX`] times `steps` (`march_step_count` in WGSL).
#[inline]
pub fn march_step_count(steps: u32, log_ratio: f32) -> u32 {
    let factor = (log_ratio / MARCH_LOG_SPAN).clamp(1.0, MARCH_STEP_FACTOR_MAX);
    (steps.max(1) as f32 * factor).ceil() as u32
}

/// Sub-samples of a coarse march interval that touches cloud.
pub const REFINE: u32 = 4;

/// Marches one ray (the per-pixel function; `march_ray` in WGSL); `dither`
/// in `[0, 1)` places the samples within their steps (0.5: centres) and,
/// through [`shadow_offset`], each lit sample's shadow samples in theirs;
/// `spread` is the pixel's cone angle (radians, [`crate::render::camera::View::pixel_spread`]):
/// a sample at distance `t` reads the textures at the level of detail of
/// a footprint `spread · t` wide.
pub fn march_ray(origin: Vec3, dir: Vec3, dither: f32, spread: f32, fr: &Frame) -> RaySample {
    let d = &fr.density;
    let q = &fr.quality;
    let sun_dir = sun_direction(fr.sun_elevation_deg, fr.sun_azimuth_deg);
    let sky = &fr.sky_light();
    let hit = fr
        .terrain
        .and_then(|h| h.intersect(origin, dir, q.max_distance_m).map(|t| (h, t)));
    let (background, max_t) = match hit {
        Some((h, t)) => (
            terrain_radiance(origin + dir * t, t, dir, sun_dir, spread, h, fr),
            t,
        ),
        None => {
            let bg = background_radiance(
                sky,
                dir,
                sun_dir,
                sea_waves_at(origin, dir, spread, fr),
                flat_ground_shadow(origin, dir, sun_dir, fr),
                flat_ground_albedo(origin, dir, spread, fr),
                (Vec3::ZERO, 1.0),
            );
            let bg = cirrus_over(sky, origin, dir, sun_dir, spread, q.cirrus.as_ref(), bg);
            (
                bg + sea_reflection_change(origin, dir, dither, sun_dir, spread, fr),
                q.max_distance_m,
            )
        }
    };
    let background = if q.single_scattering {
        Vec3::ZERO
    } else {
        background
    };
    let Some((t0, t1)) = band_segment(origin, dir, d.band_bottom_m, d.band_top_m, max_t) else {
        return RaySample {
            radiance: background,
            clouds: Vec3::ZERO,
            transmittance: 1.0,
            reads: 0,
        };
    };
    let log_ratio = ((t1 + NEAR_M) / (t0 + NEAR_M)).ln();
    let steps = march_step_count(q.steps, log_ratio);
    // The sun's light at the band's middle.
    let sun = sun_light_at(sky, 0.5 * (d.band_bottom_m + d.band_top_m), sun_dir);
    // Irradiance from the upper sky and from the ground (π L), scattered
    // isotropically (1/4π).
    let sky_top = sky_ambient(sky, sun_dir) * 0.25;
    let ground = ground_up(sky, sun_dir, q.sea_wind_mps.is_some()) * 0.25;
    let gains = light_gains(fr.light.is_some());
    let cos = dir.dot(sun_dir);
    let shadow_ray = ShadowSteps {
        steps: q.shadow_steps,
        forward: forward_step_factor(cos),
        offset: shadow_offset(dither),
    };
    let toward = toward_sun(cos);
    let mut transmittance = 1.0_f32;
    let mut light = Vec3::ZERO;
    let mut depth_weighted = 0.0_f32;
    // Coarse intervals growing with distance ([`march_distance`]); an
    // interval whose ends touch cloud is sampled REFINE times finer (the
    // dither places the samples), so thin cloud edges seen at grazing
    // angles get several samples, and empty sky costs one density lookup
    // per interval.
    let mut sigma_a = density_at(origin + dir * t0, &fr.fields, d, true, spread * t0);
    let mut reads = 1;
    let mut ta = t0;
    'march: for i in 0..steps {
        let tb = march_distance(t0, log_ratio, (i + 1) as f32 / steps as f32);
        let sigma_b = density_at(origin + dir * tb, &fr.fields, d, true, spread * tb);
        reads += 1;
        let touched = sigma_a > 0.0 || sigma_b > 0.0;
        sigma_a = sigma_b;
        let (n, h) = if touched {
            (REFINE, (tb - ta) / REFINE as f32)
        } else {
            (1, tb - ta)
        };
        let start = ta;
        ta = tb;
        for j in 0..n {
            let t = start + (j as f32 + dither) * h;
            let p = origin + dir * t;
            let footprint = spread * t;
            let sigma_t = density_at(p, &fr.fields, d, true, footprint);
            reads += 1;
            if sigma_t <= 0.0 {
                continue;
            }
            let shadow = shadow_depth(p, sun_dir, shadow_ray, toward, footprint, fr);
            let tau_sun = shadow.tau;
            reads += shadow.reads;
            let eta = ((p.y - d.band_bottom_m) / (d.band_top_m - d.band_bottom_m)).clamp(0.0, 1.0);
            // Sky light from above, darker toward the cloud base, and the
            // ground's from below.
            let (ambient, octaves) = if q.single_scattering {
                (Vec3::ZERO, 0)
            } else {
                (ambient_light(sky_top, ground, eta, &gains), q.octaves)
            };
            let scatter = sun
                * (sun_scattering(tau_sun, cos, sun_dir.y, sigma_t, octaves, &gains)
                    + diffused_light(p, -dir, octaves, fr))
                + ambient;
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
    let (inscatter, haze) = aerial(sky, dir, cloud_distance, sun_dir);
    let clouds = if q.single_scattering {
        light
    } else {
        light * haze + inscatter * opacity
    };
    RaySample {
        radiance: clouds + background * transmittance,
        clouds,
        transmittance,
        reads,
    }
}

/// The sun's optical depth from the lit sample `p` of a primary ray
/// `toward` the sun ([`toward_sun`]; `reads`: the density reads it
/// took): with a light volume, the shadow ray's near part
/// ([`near_sun_optical_depth`]) and the volume's precomputed depth
/// beyond it ([`crate::render::cpu::light_volume::LightVolume::sun_depth_at`]);
/// without one, the whole shadow ray ([`shadow_march`], as
/// [`super::lighting::sun_optical_depth`] takes it). The WGSL march does
/// the same in its one loop.
pub fn shadow_depth(
    p: Vec3,
    sun_dir: Vec3,
    ray: ShadowSteps,
    toward: f32,
    footprint: f32,
    fr: &Frame,
) -> super::lighting::ShadowMarch {
    let d = &fr.density;
    if ray.steps == 0 {
        return shadow_march(p, sun_dir, 0.0, 0, ray.offset, footprint, &fr.fields, d);
    }
    match fr.light {
        Some(v) => {
            let (mut near, rest) =
                near_sun_optical_depth(p, sun_dir, ray, toward, footprint, &fr.fields, d);
            if rest && !near.left_band {
                near.tau += v.sun_depth_at(p + sun_dir * near.travelled, d.map_extent_m);
            }
            near
        }
        None => {
            let length = shadow_ray_length(p, sun_dir, d);
            let count = shadow_step_count(ray.steps, length, ray.forward);
            shadow_march(
                p, sun_dir, length, count, ray.offset, footprint, &fr.fields, d,
            )
        }
    }
}

/// Radiance of the terrain at `p` (distance `t` along `dir`, seen by a
/// pixel of cone angle `spread`): lit by the sun through the clouds
/// (their shadow, when shadows are on), the sky and the sunlight the
/// clouds scatter down (`ground_cloud_light`), faded by aerial
/// perspective. With `land_fields` its level ground's albedo carries the
/// fields' and woods' tint
/// ([`super::land::terrain_albedo`]).
pub fn terrain_radiance(
    p: Vec3,
    t: f32,
    dir: Vec3,
    sun_dir: Vec3,
    spread: f32,
    h: &Heightfield,
    fr: &Frame,
) -> Vec3 {
    let d = &fr.density;
    let n = h.normal_at(p.x, p.z);
    let albedo = terrain_albedo(p, n, dir, t, spread, fr);
    let shadow = if fr.quality.shadow_steps > 0 && sun_dir.y > 0.0 {
        cloud_shadow(p, sun_dir, GROUND_SHADOW_STEPS, &fr.fields, d)
    } else {
        1.0
    };
    let light = &fr.sky_light();
    let sun = sun_light_at(light, p.y, sun_dir);
    let sky = sky_ambient(light, sun_dir) + light.ground_cloud_light;
    let lit = albedo * (sun * (n.dot(sun_dir).max(0.0) * shadow / PI) + sky * (0.5 + 0.5 * n.y));
    let (inscatter, haze) = aerial(light, dir, t, sun_dir);
    lit * haze + inscatter
}

/// The clouds' shadow where a ray that meets no terrain reaches the flat
/// ground (y = 0; land or sea): [`cloud_shadow`] there with the terrain's
/// [`GROUND_SHADOW_STEPS`] samples, 1 without shadows, with the sun down, for a
/// ray that does not reach the ground within `max_distance_m`.
pub fn flat_ground_shadow(origin: Vec3, dir: Vec3, sun_dir: Vec3, fr: &Frame) -> f32 {
    let q = &fr.quality;
    if dir.y >= 0.0 || origin.y <= 0.0 || q.shadow_steps == 0 || sun_dir.y <= 0.0 {
        return 1.0;
    }
    let t = origin.y / -dir.y;
    if t > q.max_distance_m {
        return 1.0;
    }
    let p = Vec3::new(origin.x + dir.x * t, 0.0, origin.z + dir.z * t);
    cloud_shadow(p, sun_dir, GROUND_SHADOW_STEPS, &fr.fields, &fr.density)
}

/// Samples of the clouds' shadow on the ground, terrain or flat
/// (`GROUND_SHADOW_STEPS` in WGSL): one ray across the band per ground
/// pixel, whatever `shadow_steps` the clouds' own light takes.
pub const GROUND_SHADOW_STEPS: u32 = 12;

#[cfg(test)]
#[path = "renderer_tests.rs"]
mod tests;
