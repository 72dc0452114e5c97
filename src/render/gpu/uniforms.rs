//! The per-frame uniform block shared with WGSL.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::render::cpu::camera::Camera;
use crate::render::cpu::density::DensityParams;
use crate::render::cpu::renderer::{Quality, SUN_INTENSITY};
use crate::render::cpu::sky::{sky_radiance, sun_color, sun_direction};

/// Near plane of [`view_projection`], m.
pub const NEAR_M: f32 = 1.0;

/// The projection the terrain pass rasterises with and the cloud pass
/// reads a depth buffer with: left-handed, `look_to_lh` along the camera's
/// forward with `+y` up (exactly the CPU camera's basis, so pixel `(x, y)`
/// sees the CPU ray through it), depth 0 at [`NEAR_M`] and 1 at `far_m`.
pub fn view_projection(camera: &Camera, aspect: f32, far_m: f32) -> Mat4 {
    let (forward, _, _) = camera.basis();
    Mat4::perspective_lh(camera.fov_deg.to_radians(), aspect, NEAR_M, far_m)
        * Mat4::look_to_lh(camera.position_m, forward, Vec3::Y)
}

// Keep in sync with shaders/clouds.wgsl: Frame.
/// Everything the passes read per frame; one `vec4` per line of the WGSL
/// struct (the meaning of each lane is in the shader).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct FrameUniforms {
    pub cam_pos: [f32; 4],
    pub cam_forward: [f32; 4],
    pub cam_right: [f32; 4],
    pub cam_up: [f32; 4],
    pub sun_dir: [f32; 4],
    pub sun_light: [f32; 4],
    pub ambient_top: [f32; 4],
    pub sky_up: [f32; 4],
    pub band: [f32; 4],
    pub map: [f32; 4],
    pub jitter: [f32; 4],
    pub depth: [f32; 4],
    pub counts: [u32; 4],
    pub mask: [u32; 4],
    pub view_proj: [[f32; 4]; 4],
    pub prev_view_proj: [[f32; 4]; 4],
}

const _: () = assert!(size_of::<FrameUniforms>() == 352);

/// The per-frame inputs of [`FrameUniforms::new`].
#[derive(Debug, Clone, Copy)]
pub struct FrameInputs {
    pub camera: Camera,
    pub prev_view_proj: Mat4,
    pub width: u32,
    pub height: u32,
    pub sun_elevation_deg: f32,
    pub sun_azimuth_deg: f32,
    pub density: DensityParams,
    pub quality: Quality,
    /// Sub-pixel ray offset (pixels) and dither offset (0..1): zero without TSAA.
    pub jitter: [f32; 3],
    /// Weight of the new frame in the TSAA history (1: history reset).
    pub blend: f32,
    pub frame_index: u32,
    /// Terrain texture extent and highest point, m (zero without terrain).
    pub terrain: [f32; 2],
    /// P's width and height, texels.
    pub p_size: [u32; 2],
    /// Coverage mask: width, height, P texels per mask cell, 0.
    pub mask: [u32; 4],
}

impl FrameUniforms {
    /// Fills the block; the per-frame constants (sun colour, zenith
    /// ambient) are computed here once instead of per pixel.
    pub fn new(i: &FrameInputs) -> Self {
        let (f, r, u) = i.camera.basis();
        let (w, h) = (i.width.max(1) as f32, i.height.max(1) as f32);
        let tan_half = (0.5 * i.camera.fov_deg.to_radians()).tan();
        let sun_dir = sun_direction(i.sun_elevation_deg, i.sun_azimuth_deg);
        let sun = sun_color(sun_dir) * SUN_INTENSITY;
        let sky_up = sky_radiance(Vec3::Y, sun_dir);
        let ambient = sky_up * 0.25;
        let q = &i.quality;
        let d = &i.density;
        let v4 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
        Self {
            cam_pos: v4(i.camera.position_m, tan_half),
            cam_forward: v4(f, w / h),
            cam_right: v4(r, w),
            cam_up: v4(u, h),
            sun_dir: v4(sun_dir, q.haze_distance_m),
            sun_light: v4(sun, q.max_distance_m),
            ambient_top: v4(ambient, q.exposure),
            sky_up: v4(sky_up, 0.0),
            band: [
                d.band_bottom_m,
                d.band_top_m,
                d.coverage,
                d.extinction_per_m,
            ],
            map: [d.map_extent_m, d.detail_strength, d.detail_scale_m, 0.0],
            jitter: [i.jitter[0], i.jitter[1], i.jitter[2], i.blend],
            depth: [NEAR_M, q.max_distance_m, i.terrain[0], i.terrain[1]],
            counts: [q.steps.max(1), i.p_size[0], i.p_size[1], i.frame_index],
            mask: i.mask,
            view_proj: view_projection(&i.camera, w / h, q.max_distance_m).to_cols_array_2d(),
            prev_view_proj: i.prev_view_proj.to_cols_array_2d(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn view_projection_puts_the_cpu_ray_through_its_pixel() {
        let cam = Camera {
            position_m: Vec3::new(10.0, 300.0, -40.0),
            yaw_deg: 33.0,
            pitch_deg: 17.0,
            fov_deg: 55.0,
        };
        let (w, h) = (320, 200);
        let vp = view_projection(&cam, w as f32 / h as f32, 40_000.0);
        for (x, y) in [(0.5, 0.5), (160.0, 100.0), (319.5, 10.25), (3.0, 199.0)] {
            let p = cam.position_m + cam.ray(x, y, w, h) * 1234.0;
            let c = vp * p.extend(1.0);
            let ndc = c.truncate() / c.w;
            let px = (
                (ndc.x + 1.0) * 0.5 * w as f32,
                (1.0 - ndc.y) * 0.5 * h as f32,
            );
            assert!(
                (px.0 - x).abs() < 1e-2 && (px.1 - y).abs() < 1e-2,
                "{px:?} vs {x},{y}"
            );
            assert!((0.0..1.0).contains(&ndc.z));
        }
    }
}
