//! What the CPU twins of the two stand-alone passes share, the
//! pseudo-spheroids (`spheroids.rs`) and the precomputed volumes
//! (`volume.rs`); WGSL in `shaders/standalone.wgsl`: the analytic sky they
//! draw under (their pipelines bind no sky tables), their per-pixel
//! dither, the end of their march (the clouds hazed by their mean
//! distance), and the picture's per-pixel loop.

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use super::frame::Frame;
use super::land::flat_ground_albedo;
use super::sky::{SkyLight, aerial, background_radiance, sun_direction};
use super::waves::sea_waves_at;
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

/// The end of a march: the clouds' scattered `light`, seen through the
/// air to their transmittance-weighted mean distance
/// (`depth_weighted / opacity`), premultiplied, with the opacity in `w`.
#[inline]
pub fn hazed_clouds(
    sky: &SkyLight,
    light: Vec3,
    transmittance: f32,
    depth_weighted: f32,
    dir: Vec3,
    sun_dir: Vec3,
) -> Vec4 {
    let opacity = 1.0 - transmittance;
    let distance = if opacity > 0.0 {
        depth_weighted / opacity
    } else {
        0.0
    };
    let (inscatter, haze) = aerial(sky, dir, distance, sun_dir);
    (light * haze + inscatter * opacity).extend(opacity)
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
                *px = c.truncate() + (1.0 - c.w) * bg;
            }
        });
    out
}
