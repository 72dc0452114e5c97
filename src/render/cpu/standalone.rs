//! What the CPU twins of the two stand-alone passes share, the
//! pseudo-spheroids (`spheroids.rs`) and the precomputed volumes
//! (`volume.rs`); WGSL in `shaders/standalone.wgsl`: the analytic sky they
//! draw under (their pipelines bind no sky tables), their per-pixel
//! dither, the end of their march (the clouds hazed by their mean
//! distance), and the picture's per-pixel loop.

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use super::cirrus::cirrus_over;
use super::frame::{Frame, MIN_TRANSMITTANCE};
use super::land::flat_ground_albedo;
use super::lighting::{ALBEDO, LightGains, ambient_light, integrate_step, sun_scattering};
use super::sea::sea_waves_at;
use super::sky::{
    SkyLight, aerial, background_radiance, ground_up, sky_ambient, sun_direction, sun_light_at,
};
use crate::render::sampling::frame_offset;

/// The sky a stand-alone pass draws under: the frame's, analytic, over
/// the clear sky's land (its GPU twin's uniforms carry no cloud cover).
pub fn analytic<'a>(fr: &'a Frame) -> SkyLight<'a> {
    SkyLight {
        luts: None,
        ground_cloud_light: glam::Vec3::ZERO,
        ..fr.sky_light()
    }
}

/// The per-pixel dither (interleaved gradient noise, Jimenez 2014), so
/// the passes need no blue-noise texture.
#[inline]
pub fn standalone_dither(x: u32, y: u32) -> f32 {
    (52.982_918 * (0.067_110_56 * x as f32 + 0.005_837_15 * y as f32).fract()).fract()
}

/// What lights the samples of one stand-alone march, the same all along
/// the ray (`StandaloneLight` in WGSL).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StandaloneLight {
    /// The sunlight at the band's middle height.
    pub sun: Vec3,
    /// A quarter of the sky's irradiance from above.
    pub sky_top: Vec3,
    /// A quarter of the ground's irradiance from below.
    pub ground: Vec3,
    /// The cosine of the angle between the ray and the sun.
    pub cos_theta: f32,
    pub sun_dir: Vec3,
}

/// The light along a ray `dir` under the sun `sun_dir` and the `sky`.
pub fn standalone_light(sky: &SkyLight, dir: Vec3, sun_dir: Vec3, fr: &Frame) -> StandaloneLight {
    let d = &fr.density;
    StandaloneLight {
        sun: sun_light_at(sky, 0.5 * (d.band_bottom_m + d.band_top_m), sun_dir),
        sky_top: sky_ambient(sky, sun_dir) * 0.25,
        ground: ground_up(sky, sun_dir, fr.quality.sea_wind_mps.is_some()) * 0.25,
        cos_theta: dir.dot(sun_dir),
        sun_dir,
    }
}

/// A stand-alone march's running sums: the light scattered toward the
/// eye, the transmittance so far and the transmittance-weighted distance
/// (`StandaloneMarch` in WGSL).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StandaloneMarch {
    pub light: Vec3,
    pub transmittance: f32,
    pub depth_weighted: f32,
}

impl StandaloneMarch {
    /// Nothing marched yet: no light, clear air.
    pub const START: Self = Self {
        light: Vec3::ZERO,
        transmittance: 1.0,
        depth_weighted: 0.0,
    };
}

/// Adds one sample to the march `m`: extinction `sigma_t` (1/m) at `p`,
/// `t` along the ray, over a step `dt`, with optical depth `tau_sun`
/// toward the sun, lit by `l` with the gains of the renderers without a
/// light volume ([`LightGains::ALONE`]). True once the march is opaque
/// (below [`MIN_TRANSMITTANCE`]): the caller stops.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn standalone_step(
    m: &mut StandaloneMarch,
    l: &StandaloneLight,
    p: Vec3,
    t: f32,
    dt: f32,
    sigma_t: f32,
    tau_sun: f32,
    fr: &Frame,
) -> bool {
    let d = &fr.density;
    let eta = ((p.y - d.band_bottom_m) / (d.band_top_m - d.band_bottom_m)).clamp(0.0, 1.0);
    let g = &LightGains::ALONE;
    let ambient = ambient_light(l.sky_top, l.ground, eta, g);
    let src = (l.sun
        * sun_scattering(
            tau_sun,
            l.cos_theta,
            l.sun_dir.y,
            sigma_t,
            fr.quality.octaves,
            g,
        )
        + ambient)
        * (sigma_t * ALBEDO);
    let step_t = (-sigma_t * dt).exp();
    m.light += integrate_step(src, sigma_t, dt) * m.transmittance;
    m.depth_weighted += t * m.transmittance * (1.0 - step_t);
    m.transmittance *= step_t;
    m.transmittance < MIN_TRANSMITTANCE
}

/// The end of a march `m`: the clouds' scattered light, seen through the
/// air to their transmittance-weighted mean distance
/// (`depth_weighted / opacity`), premultiplied, with the opacity in `w`.
#[inline]
pub fn hazed_clouds(sky: &SkyLight, m: &StandaloneMarch, dir: Vec3, sun_dir: Vec3) -> Vec4 {
    let opacity = 1.0 - m.transmittance;
    let distance = if opacity > 0.0 {
        m.depth_weighted / opacity
    } else {
        0.0
    };
    let (inscatter, haze) = aerial(sky, dir, distance, sun_dir);
    (m.light * haze + inscatter * opacity).extend(opacity)
}

/// A `width x height` image of linear radiance (row-major): per pixel the
/// mean of `offsets` `march(origin, dir, dither)` through its centre,
/// march `k` with the dither shifted by the golden-ratio offset of frame
/// `k` (one offset: the dither itself, the twin of one GPU frame; more:
/// its grain averaged away), over the sky or ground behind. Unlike the
/// cloud map's stills (`render_still`), no sub-pixel jitter: the
/// volumes' GPU pass has no TSAA to match.
pub fn render_standalone(
    width: u32,
    height: u32,
    fr: &Frame,
    offsets: u32,
    march: impl Fn(Vec3, Vec3, f32) -> Vec4 + Sync,
) -> Vec<Vec3> {
    let n = offsets.max(1);
    let sun_dir = sun_direction(fr.sun_elevation_deg, fr.sun_azimuth_deg);
    let sky = &analytic(fr);
    let w = width as usize;
    let spread = fr.view.pixel_spread(width, height);
    let mut out = vec![Vec3::ZERO; w * height as usize];
    out.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            for (x, px) in row.iter_mut().enumerate() {
                let dir = fr
                    .view
                    .camera_ray(x as f32 + 0.5, y as f32 + 0.5, width, height);
                let d0 = standalone_dither(x as u32, y as u32);
                let c = (0..n)
                    .map(|k| march(fr.view.eye(), dir, (d0 + frame_offset(k)).fract()))
                    .sum::<Vec4>()
                    / n as f32;
                let bg = background_radiance(
                    sky,
                    dir,
                    sun_dir,
                    sea_waves_at(fr.view.eye(), dir, spread, fr),
                    1.0,
                    flat_ground_albedo(fr.view.eye(), dir, spread, fr),
                    (Vec3::ZERO, 1.0),
                );
                let eye = fr.view.eye();
                let bg = cirrus_over(
                    sky,
                    eye,
                    dir,
                    sun_dir,
                    spread,
                    fr.quality.cirrus.as_ref(),
                    bg,
                );
                *px = c.truncate() + (1.0 - c.w) * bg;
            }
        });
    out
}
