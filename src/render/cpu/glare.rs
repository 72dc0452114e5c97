//! The sun's glare in the tone-mapped pictures: the light a lens and an
//! eye scatter from the bright sun disk onto the image around it, so the
//! sun is a glowing disk instead of a few clipped pixels (`render.sun_glare`,
//! default 1; 0 leaves it out). Each function is the twin of the WGSL
//! function of the same name in `shaders/glare.wgsl`.
//!
//! The spread is the small-angle term of the CIE's glare spread function
//! for the human eye (CIE 146:2002, after Vos and van den Berg): the
//! veiling luminance at `θ` degrees from a source of illuminance `E` at
//! the eye is `L = E · 10 / θ³` (θ in degrees, `L / E` in 1/sr). The full
//! function adds terms falling as `1/θ²` and `1/θ` and a constant, which
//! veil the whole field of an eye looking near the sun; a camera's picture
//! does not show that veil, so they are left out (with them a sun 60° off
//! the frame greyed a blue sky by 10-30 %). Inside the disk the spread is
//! held at its value at the disk's edge.
//!
//! The source is the sun as the camera sees it: the disk's irradiance at
//! the camera ([`super::sky::sun_disk_irradiance`]) times the clouds'
//! transmittance over the disk, read from the frame's own cloud layer at
//! [`GLARE_TAPS`] pixels across the disk ([`sun_visibility`]); a sun
//! outside the frame reads the nearest pixels on its edge, so the glare
//! fades with the clouds there instead of vanishing as the sun leaves
//! the frame. Only the PNG pictures and an LDR target get it: the linear
//! outputs (OpenEXR, an engine's HDR target) stay the scene's radiance,
//! for an engine's own bloom.

use glam::{Vec2, Vec3};

use crate::render::camera::View;

/// The CIE glare spread function's small-angle coefficient, sr⁻¹·deg³
/// (`GLARE_CORE` in WGSL): `L / E = 10 / θ³`.
pub const GLARE_CORE: f32 = 10.0;
/// The angle under which the spread is held, degrees
/// (`GLARE_MIN_DEG`): about the sun's angular radius, 0.2678°.
pub const GLARE_MIN_DEG: f32 = 0.27;
/// The pixels the sun's visibility is read at (`GLARE_TAPS`): the
/// disk's centre and four points at [`GLARE_TAP_REACH`] of its radius,
/// left, right, up and down.
pub const GLARE_TAPS: usize = 5;
/// How far out across the disk the outer taps sit, as a fraction of its
/// radius (`GLARE_TAP_REACH`).
pub const GLARE_TAP_REACH: f32 = 0.6;

/// The glare's spread at cosine `cos_theta` from the sun, 1/sr
/// (`glare_spread` in WGSL): [`GLARE_CORE`]` / θ³`, θ in degrees, at
/// least [`GLARE_MIN_DEG`].
#[inline]
pub fn glare_spread(cos_theta: f32) -> f32 {
    // θ from the chord, exact for small angles where acos has few ulps.
    let chord = (2.0 - 2.0 * cos_theta.clamp(-1.0, 1.0)).max(0.0).sqrt();
    let theta = (2.0 * (0.5 * chord).min(1.0).asin())
        .to_degrees()
        .max(GLARE_MIN_DEG);
    GLARE_CORE / (theta * theta * theta)
}

/// The glare's radiance along `dir` from a sun toward `sun_dir` whose
/// visible irradiance (times `render.sun_glare`) is `source`
/// (`sun_glare` in WGSL).
#[inline]
pub fn sun_glare(dir: Vec3, sun_dir: Vec3, source: Vec3) -> Vec3 {
    source * glare_spread(dir.dot(sun_dir))
}

/// Where the sun's centre falls in a `width x height` image, in pixels
/// (`(0, 0)` the top-left corner, the pixel centres at `+0.5`; the inverse
/// of [`View::camera_ray`]); `None` behind the camera (`sun_pixel` in
/// WGSL). A direction's projection does not depend on its distance, so
/// the direction itself is projected.
#[inline]
pub fn sun_pixel(view: &View, width: u32, height: u32, sun_dir: Vec3) -> Option<Vec2> {
    let c = view.view_projection() * sun_dir.extend(0.0);
    if c.w <= 1e-6 {
        return None;
    }
    let (w, h) = (width.max(1) as f32, height.max(1) as f32);
    Some(Vec2::new(
        (c.x / c.w + 1.0) * 0.5 * w,
        (1.0 - c.y / c.w) * 0.5 * h,
    ))
}

/// The [`GLARE_TAPS`] pixels (integer coordinates, clamped to the image)
/// the sun's visibility is read at, for a sun at pixel `centre` whose
/// radius covers `radius_px` pixels (`glare_tap` in WGSL, tap by tap).
#[inline]
pub fn glare_tap(centre: Vec2, radius_px: f32, tap: usize, width: u32, height: u32) -> [u32; 2] {
    let r = GLARE_TAP_REACH * radius_px;
    let o = match tap {
        1 => Vec2::new(-r, 0.0),
        2 => Vec2::new(r, 0.0),
        3 => Vec2::new(0.0, -r),
        4 => Vec2::new(0.0, r),
        _ => Vec2::ZERO,
    };
    let p = (centre + o).floor();
    [
        p.x.clamp(0.0, width.max(1) as f32 - 1.0) as u32,
        p.y.clamp(0.0, height.max(1) as f32 - 1.0) as u32,
    ]
}

/// The sun disk's radius in pixels at the image's centre, for a pixel
/// cone of `pixel_spread` radians ([`View::pixel_spread`]).
#[inline]
pub fn sun_radius_px(pixel_spread: f32) -> f32 {
    GLARE_MIN_DEG.to_radians() / pixel_spread.max(1e-9)
}

/// The sun's visibility through the clouds, 0..1 (`sun_visibility` in
/// WGSL): the mean over the [`GLARE_TAPS`] of `transmittance(x, y)`, the
/// cloud layer's transmittance at pixel `(x, y)` (0 where terrain hides
/// the sky); a tap whose ray points below the horizon counts 0, as the
/// flat ground or sea is drawn there (a sun that has set behind it glares
/// no more, whatever light the sky model still gives it); 0 for a sun
/// behind the camera.
pub fn sun_visibility(
    view: &View,
    width: u32,
    height: u32,
    sun_dir: Vec3,
    transmittance: impl Fn(u32, u32) -> f32,
) -> f32 {
    let Some(centre) = sun_pixel(view, width, height, sun_dir) else {
        return 0.0;
    };
    let radius = sun_radius_px(view.pixel_spread(width, height));
    let sum: f32 = (0..GLARE_TAPS)
        .map(|tap| {
            let [x, y] = glare_tap(centre, radius, tap, width, height);
            let ray = view.camera_ray(x as f32 + 0.5, y as f32 + 0.5, width, height);
            if ray.y < 0.0 {
                0.0
            } else {
                transmittance(x, y)
            }
        })
        .sum();
    sum / GLARE_TAPS as f32
}

/// Adds the glare of a sun of visible irradiance `source` (times the
/// strength) to a `width x height` image of linear radiance, row-major.
pub fn add_glare(
    linear: &mut [Vec3],
    view: &View,
    width: u32,
    height: u32,
    sun_dir: Vec3,
    source: Vec3,
) {
    if source == Vec3::ZERO {
        return;
    }
    let w = width.max(1) as usize;
    for (i, px) in linear.iter_mut().enumerate() {
        let (x, y) = ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
        *px += sun_glare(view.camera_ray(x, y, width, height), sun_dir, source);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::camera::Camera;
    use std::f32::consts::PI;

    #[test]
    fn the_spread_falls_as_the_cube_of_the_angle() {
        let at = |deg: f32| glare_spread(deg.to_radians().cos());
        // 10 / θ³: 10 at 1°, 0.08 at 5°, 0.01 at 10°.
        assert!((at(1.0) / 10.0 - 1.0).abs() < 0.01, "{}", at(1.0));
        assert!((at(5.0) / 0.08 - 1.0).abs() < 0.01, "{}", at(5.0));
        assert!((at(2.0) / at(4.0) - 8.0).abs() < 0.05);
        // Held at the disk's edge inside it: finite at the centre.
        assert_eq!(at(0.0), at(0.1));
        assert!((at(0.0) / (10.0 / GLARE_MIN_DEG.powi(3)) - 1.0).abs() < 1e-3);
        // It scatters a few per cent of the sun's light, not more: the
        // spread's integral over the sphere beyond the disk.
        let n = 20_000;
        let total: f64 = (0..n)
            .map(|i| {
                let theta = (GLARE_MIN_DEG as f64
                    + (180.0 - GLARE_MIN_DEG as f64) * (i as f64 + 0.5) / n as f64)
                    .to_radians();
                let dtheta = (180.0 - GLARE_MIN_DEG as f64).to_radians() / n as f64;
                glare_spread(theta.cos() as f32) as f64 * 2.0 * PI as f64 * theta.sin() * dtheta
            })
            .sum();
        assert!(total > 0.05 && total < 0.09, "{total}");
    }

    #[test]
    fn the_sun_pixel_is_where_the_camera_ray_points() {
        let cam = Camera {
            position_m: Vec3::new(0.0, 100.0, 0.0),
            yaw_deg: 30.0,
            pitch_deg: 10.0,
            fov_deg: 50.0,
        };
        let (w, h) = (320, 200);
        let view = cam.view(w as f32 / h as f32, 40_000.0);
        for (x, y) in [(160.5, 100.5), (3.25, 190.0), (300.0, 12.5)] {
            let dir = view.camera_ray(x, y, w, h);
            let p = sun_pixel(&view, w, h, dir).expect("in front");
            assert!((p - Vec2::new(x, y)).length() < 0.02, "{p} vs ({x}, {y})");
        }
        // Behind the camera: none.
        assert_eq!(sun_pixel(&view, w, h, -view.forward()), None);
    }

    #[test]
    fn the_visibility_reads_the_cloud_layer_over_the_disk() {
        let cam = Camera {
            position_m: Vec3::ZERO,
            yaw_deg: 0.0,
            pitch_deg: 20.0,
            fov_deg: 10.0,
        };
        let (w, h) = (200, 200);
        let view = cam.view(1.0, 40_000.0);
        let sun = view.forward();
        // A 10° field over 200 pixels: the disk's radius is 5.4 pixels.
        let r = sun_radius_px(view.pixel_spread(w, h));
        assert!((r - 5.4).abs() < 0.1, "{r}");
        // Clear sky: 1; a cloud over the left half of the disk: 1/5 of
        // the taps (the left one) is hidden, the centre's column is not.
        assert_eq!(sun_visibility(&view, w, h, sun, |_, _| 1.0), 1.0);
        let half = sun_visibility(&view, w, h, sun, |x, _| if x < 97 { 0.0 } else { 1.0 });
        assert!((half - 0.8).abs() < 1e-6, "{half}");
        // A sun behind the camera is not seen.
        assert_eq!(sun_visibility(&view, w, h, -sun, |_, _| 1.0), 0.0);
        // Nor one that has set behind the flat ground: the taps below the
        // horizon are hidden, those above it are not (half the disk up).
        let level = Camera {
            pitch_deg: 0.0,
            ..cam
        }
        .view(1.0, 40_000.0);
        let set = Vec3::new(0.0, -0.02, 1.0).normalize();
        assert_eq!(sun_visibility(&level, w, h, set, |_, _| 1.0), 0.0);
        let half = sun_visibility(&level, w, h, Vec3::Z, |_, _| 1.0);
        assert!(half > 0.0 && half < 1.0, "{half}");
        // A sun outside the frame reads the pixels on its edge.
        let off = view.camera_ray(260.0, 100.0, w, h);
        let edge = sun_visibility(&view, w, h, off, |x, _| if x == w - 1 { 0.5 } else { 1.0 });
        assert_eq!(edge, 0.5);
    }
}
