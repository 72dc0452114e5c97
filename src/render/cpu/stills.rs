//! Pictures made of the renderer's marches ([`super::renderer::march_ray`]):
//! one march a pixel, the mean of the frames TSAA accumulates, the
//! clouds-only layer, the CLI's stills with the sun's glare, and the
//! supersampled reference.

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use super::frame::Frame;
use super::glare::{add_glare, sun_visibility};
use super::renderer::{RaySample, march_ray, pixel_dither};
use super::sky::{sun_direction, sun_disk_irradiance};
use super::tone_map::to_srgb8;
use crate::render::sampling::{frame_offset, jitter};

/// Renders a `width x height` image of linear radiance, row-major, each
/// pixel the mean of `offsets` marches through its centre whose samples
/// are shifted from the pixel's dither by the first `offsets` frames'
/// golden-ratio offsets ([`frame_offset`]): the dither's grain averages
/// out, as the GPU's TSAA averages its per-frame offsets. `offsets = 1`
/// is [`render_linear`].
pub fn render_linear_offsets(width: u32, height: u32, fr: &Frame, offsets: u32) -> Vec<Vec3> {
    render_marches(width, height, fr, offsets, false, |s| {
        s.radiance.extend(0.0)
    })
    .into_iter()
    .map(Vec4::truncate)
    .collect()
}

/// The converged oracle: each pixel the mean of the `frames` marches the
/// GPU's TSAA accumulates with a static camera (frame `k`'s sub-pixel
/// jitter and dither offset, [`jitter`]); with more steps than the GPU's
/// (the caller's `fr`), the clean image the GPU's converged frames are
/// measured against. `frames` is best a multiple of
/// [`crate::render::sampling::JITTER_CYCLE`]. Past the cycle the sub-pixel jitter
/// repeats but the dither offsets go on ([`frame_offset`]), so every
/// frame differs (the GPU repeats both; up to the cycle the two agree).
pub fn render_converged(width: u32, height: u32, fr: &Frame, frames: u32) -> Vec<Vec3> {
    render_marches(width, height, fr, frames, true, |s| s.radiance.extend(0.0))
        .into_iter()
        .map(Vec4::truncate)
        .collect()
}

/// A still picture (`cumulus render --backend cpu`): with `offsets` of 2
/// or more, the mean of the first `offsets` frames the GPU's TSAA
/// accumulates ([`render_converged`]: each frame's sub-pixel jitter and
/// dither offset), so edges are anti-aliased as the GPU's accumulated
/// frames are (through pixel centres alone, the far ground's cloud
/// shadows and the clouds' outlines against the sky are staircases);
/// with 1, one march through each pixel's centre ([`render_linear`]).
pub fn render_still(width: u32, height: u32, fr: &Frame, offsets: u32) -> Vec<Vec3> {
    render_still_reporting(width, height, fr, offsets, &|_| {})
}

/// [`render_still`], calling `progress` with the share of the rows done
/// (0 to 1) after each band of rows, on the calling thread.
pub fn render_still_reporting(
    width: u32,
    height: u32,
    fr: &Frame,
    offsets: u32,
    progress: &dyn Fn(f32),
) -> Vec<Vec3> {
    render_marches_reporting(
        width,
        height,
        fr,
        offsets.max(1),
        offsets > 1,
        progress,
        |s| s.radiance.extend(0.0),
    )
    .into_iter()
    .map(Vec4::truncate)
    .collect()
}

/// Per pixel (rayon over rows, row-major) the mean over `frames` marches
/// of `pick` of the ray's sample: through the pixel's centre with frame
/// `k`'s dither offset, or (`jittered`) also with its sub-pixel jitter.
fn render_marches(
    width: u32,
    height: u32,
    fr: &Frame,
    frames: u32,
    jittered: bool,
    pick: impl Fn(RaySample) -> Vec4 + Sync,
) -> Vec<Vec4> {
    render_marches_reporting(width, height, fr, frames, jittered, &|_| {}, pick)
}

/// Bands of rows a picture's progress is reported in.
const PROGRESS_BANDS: usize = 50;

/// [`render_marches`], in bands of rows (each band's rows in parallel),
/// `progress` called with the share of the rows done after each band.
fn render_marches_reporting(
    width: u32,
    height: u32,
    fr: &Frame,
    frames: u32,
    jittered: bool,
    progress: &dyn Fn(f32),
    pick: impl Fn(RaySample) -> Vec4 + Sync,
) -> Vec<Vec4> {
    let spread = fr.view.pixel_spread(width, height);
    let mut out = vec![Vec4::ZERO; (width * height) as usize];
    in_bands(
        &mut out,
        width as usize,
        height as usize,
        &|x, y, px| {
            let at = PixelMarches {
                x: x as u32,
                y: y as u32,
                width,
                height,
                spread,
            };
            *px = pixel_marches(at, fr, frames, jittered, &pick);
        },
        progress,
    );
    out
}

/// Runs `each(x, y, pixel)` over every pixel of a `w x h` row-major
/// image, in [`PROGRESS_BANDS`] bands of rows (each band's rows in
/// parallel), calling `progress` with the share of the rows done after
/// each band, on the calling thread.
pub(crate) fn in_bands<T: Send>(
    px: &mut [T],
    w: usize,
    h: usize,
    each: &(dyn Fn(usize, usize, &mut T) + Sync),
    progress: &dyn Fn(f32),
) {
    let band_rows = h.div_ceil(PROGRESS_BANDS).max(1);
    for (b, band) in px.chunks_mut((w * band_rows).max(1)).enumerate() {
        band.par_chunks_mut(w.max(1))
            .enumerate()
            .for_each(|(r, row)| {
                let y = b * band_rows + r;
                for (x, p) in row.iter_mut().enumerate() {
                    each(x, y, p);
                }
            });
        progress(((b + 1) * band_rows).min(h) as f32 / h.max(1) as f32);
    }
}

/// Which pixel [`pixel_marches`] marches through, of an image of
/// `width x height` whose pixel cone is `spread` radians
/// ([`crate::render::camera::View::pixel_spread`], once per image).
#[derive(Clone, Copy)]
pub(crate) struct PixelMarches {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
    pub spread: f32,
}

/// Pixel `(x, y)`'s mean over `frames` marches of `pick` of the ray's
/// sample ([`render_marches`], one pixel).
fn pixel_marches(
    at: PixelMarches,
    fr: &Frame,
    frames: u32,
    jittered: bool,
    pick: &impl Fn(RaySample) -> Vec4,
) -> Vec4 {
    let n = frames.max(1);
    let mut sum = Vec4::ZERO;
    for k in 0..n {
        sum += pick(frame_march(at, fr, k, jittered));
    }
    sum / n as f32
}

/// Frame `k`'s march through pixel `at`: its sub-pixel jitter (when
/// `jittered`) and its dither offset, past the jitter's cycle too (the
/// same as `jitter(k)`'s within it), so that more than JITTER_CYCLE
/// stills' marches are all distinct.
pub(crate) fn frame_march(at: PixelMarches, fr: &Frame, k: u32, jittered: bool) -> RaySample {
    let PixelMarches {
        x,
        y,
        width,
        height,
        spread,
    } = at;
    let [jx, jy] = if jittered {
        let [jx, jy, _] = jitter(k);
        [jx, jy]
    } else {
        [0.0, 0.0]
    };
    let dir = fr
        .view
        .camera_ray(x as f32 + 0.5 + jx, y as f32 + 0.5 + jy, width, height);
    let d = (pixel_dither(x, y) + frame_offset(k)).fract();
    march_ray(fr.view.eye(), dir, d, spread, fr)
}

/// The source of the sun's glare in a `width x height` still of `fr`
/// made of `offsets` marches a pixel ([`render_still`]): the sun disk's
/// irradiance at the camera ([`sun_disk_irradiance`]) times its
/// visibility through the clouds ([`sun_visibility`]: the transmittance
/// of the still's own marches at the taps across the disk, 0 where the
/// terrain hides it) times `render.sun_glare`; zero when that is 0, and
/// for single scattering.
pub fn glare_source(width: u32, height: u32, fr: &Frame, offsets: u32) -> Vec3 {
    let q = &fr.quality;
    let sun_dir = sun_direction(fr.sun_elevation_deg, fr.sun_azimuth_deg);
    let irradiance = sun_disk_irradiance(&fr.sky_light(), sun_dir);
    if q.sun_glare <= 0.0 || q.single_scattering || irradiance == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let eye = fr.view.eye();
    let spread = fr.view.pixel_spread(width, height);
    let visibility = sun_visibility(&fr.view, width, height, sun_dir, |x, y| {
        let centre = fr
            .view
            .camera_ray(x as f32 + 0.5, y as f32 + 0.5, width, height);
        let hidden = fr
            .terrain
            .is_some_and(|h| h.intersect(eye, centre, q.max_distance_m).is_some());
        if hidden {
            return 0.0;
        }
        let pick = |s: RaySample| Vec4::splat(s.transmittance);
        let at = PixelMarches {
            x,
            y,
            width,
            height,
            spread,
        };
        pixel_marches(at, fr, offsets, offsets > 1, &pick).x
    });
    irradiance * visibility * q.sun_glare
}

/// Adds the sun's glare ([`glare_source`], [`super::glare`]) to a still
/// of `fr` made of `offsets` marches a pixel, before its tone map.
pub fn add_sun_glare(linear: &mut [Vec3], width: u32, height: u32, fr: &Frame, offsets: u32) {
    let source = glare_source(width, height, fr, offsets);
    let sun_dir = sun_direction(fr.sun_elevation_deg, fr.sun_azimuth_deg);
    add_glare(linear, &fr.view, width, height, sun_dir, source);
}

/// The clouds alone, without the sky or terrain behind them: per pixel
/// the premultiplied cloud radiance (`xyz`, linear, the haze in front of
/// the clouds included) and opacity (`w`, one minus the transmittance),
/// the mean of `offsets` shifted marches; an application composites it as
/// `clouds.xyz + (1 - clouds.w) · background`. The terrain is not marched
/// to (the twin of the GPU's clouds-only output, which marches only to
/// the application's depth buffer).
pub fn render_clouds_linear(width: u32, height: u32, fr: &Frame, offsets: u32) -> Vec<Vec4> {
    let fr = &Frame {
        terrain: None,
        ..*fr
    };
    render_marches(width, height, fr, offsets, false, |s| {
        s.clouds.extend(1.0 - s.transmittance)
    })
}

/// Renders a `width x height` image of linear radiance, row-major, each
/// pixel one march with its fixed dither (the GPU's twin without TSAA).
pub fn render_linear(width: u32, height: u32, fr: &Frame) -> Vec<Vec3> {
    // One offset: the dither itself (frame 0's offset is 0, the fract of
    // a value in [0, 1) is itself, and a sum of one divided by one is
    // exact).
    render_linear_offsets(width, height, fr, 1)
}

/// A `width x height` image of `samples x samples` rays per pixel
/// (a box filter over a finer image), with the sun's glare, as sRGB8: the reference that TSAA's
/// jittered frames converge to, for the benchmark's error and the tests.
pub fn supersampled_srgb8(width: u32, height: u32, samples: u32, fr: &Frame) -> Vec<u8> {
    let s = samples.max(1);
    let fine = render_linear(width * s, height * s, fr);
    let mut out = vec![Vec3::ZERO; (width * height) as usize];
    for y in 0..height * s {
        for x in 0..width * s {
            out[((y / s) * width + x / s) as usize] +=
                fine[(y * width * s + x) as usize] / (s * s) as f32;
        }
    }
    // The glare's source read on the fine image, its spread at the
    // pixels' centres, as the GPU's composite evaluates it.
    let sun_dir = sun_direction(fr.sun_elevation_deg, fr.sun_azimuth_deg);
    let source = glare_source(width * s, height * s, fr, 1);
    add_glare(&mut out, &fr.view, width, height, sun_dir, source);
    to_srgb8(&out, fr.quality.exposure)
}

/// The PNG picture of a still (`cumulus render --backend cpu`):
/// [`render_still`] of `offsets` marches a pixel, the sun's glare added
/// ([`add_sun_glare`]), tone-mapped and sRGB-encoded ([`to_srgb8`]).
pub fn still_srgb8(width: u32, height: u32, fr: &Frame, offsets: u32) -> Vec<u8> {
    let mut linear = render_still(width, height, fr, offsets);
    add_sun_glare(&mut linear, width, height, fr, offsets);
    to_srgb8(&linear, fr.quality.exposure)
}
