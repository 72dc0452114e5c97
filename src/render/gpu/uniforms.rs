//! The uniform blocks shared with WGSL: the frame's, and the sky tables'.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::render::camera::View;
use crate::render::cpu::density::DensityParams;
use crate::render::cpu::frame::Quality;
use crate::render::cpu::sky::SUN_INTENSITY;
use crate::render::cpu::sky::{sun_color, sun_direction};
use crate::render::cpu::sky_luts::SkyParams;
#[cfg(doc)]
use crate::render::cpu::sky_luts::radius_at_altitude;

// Keep in sync with shaders/frame.wgsl: Frame.
/// Everything the passes read per frame; one `vec4` per line of the WGSL
/// struct (the meaning of each lane is in the shader).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct FrameUniforms {
    pub cam_pos: [f32; 4],
    pub screen: [f32; 4],
    pub sun_dir: [f32; 4],
    pub sun_light: [f32; 4],
    pub exposure: [f32; 4],
    pub band: [f32; 4],
    pub map: [f32; 4],
    pub jitter: [f32; 4],
    pub terrain: [f32; 4],
    pub counts: [u32; 4],
    pub mask: [u32; 4],
    pub view_proj: [[f32; 4]; 4],
    pub prev_view_proj: [[f32; 4]; 4],
    pub inverse_projection: [[f32; 4]; 4],
    pub view_to_world: [[f32; 4]; 4],
}

const _: () = assert!(size_of::<FrameUniforms>() == 432);

/// The per-frame inputs of [`FrameUniforms::new`].
#[derive(Debug, Clone, Copy)]
pub struct FrameInputs {
    pub view: View,
    /// The depth read by the cloud pass is the terrain pass's, which stores
    /// a reversed view's depth flipped (`1 - d`, so its buffer is always
    /// cleared to 1 and compared with `Less`).
    pub depth_flipped: bool,
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
    /// Terrain texture extent and highest point, m, and the terrain
    /// mesh's stride (`terrain_pass::mesh_stride`) (zero without terrain).
    pub terrain: [f32; 3],
    /// P's width and height, texels.
    pub p_size: [u32; 2],
    /// Coverage mask: width, height, P texels per mask cell, 0.
    pub mask: [u32; 4],
    /// Texels per side of the cloud map.
    pub map_size: u32,
    /// The cloud pass adds the clouds the sea mirrors to the cloud layer,
    /// for the composite's sea ([`crate::render::gpu::CloudRenderer::render`]);
    /// not in an engine's clouds-only layer, drawn over its own ground.
    pub sea_in_layer: bool,
    /// The share of the ground under cloud (P's covered fraction): the
    /// sunlight the clouds scatter down onto the land.
    pub cloud_cover: f32,
}

impl FrameUniforms {
    /// Fills the block; the analytic sky's sun colour is computed here
    /// once instead of per pixel (the physical sky reads its tables).
    pub fn new(i: &FrameInputs) -> Self {
        let (w, h) = (i.width.max(1) as f32, i.height.max(1) as f32);
        let sun_dir = sun_direction(i.sun_elevation_deg, i.sun_azimuth_deg);
        let sun = sun_color(sun_dir) * SUN_INTENSITY;
        let q = &i.quality;
        let d = &i.density;
        let v4 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
        Self {
            cam_pos: v4(i.view.eye(), i.view.pixel_spread(i.width, i.height)),
            screen: [
                w,
                h,
                i.view.far_depth(),
                if i.depth_flipped { 1.0 } else { 0.0 },
            ],
            sun_dir: v4(sun_dir, q.haze_distance_m),
            sun_light: v4(sun, q.max_distance_m),
            exposure: [
                q.exposure,
                if i.sea_in_layer { 1.0 } else { 0.0 },
                i.cloud_cover,
                q.sun_glare,
            ],
            band: [
                d.band_bottom_m,
                d.band_top_m,
                d.coverage,
                d.extinction_per_m,
            ],
            map: [
                d.map_extent_m,
                d.detail_strength,
                d.detail_scale_m,
                d.map_extent_m / i.map_size.max(1) as f32,
            ],
            jitter: [i.jitter[0], i.jitter[1], i.jitter[2], i.blend],
            terrain: [i.terrain[0], i.terrain[1], q.sea_time_s, i.terrain[2]],
            counts: [q.steps.max(1), i.p_size[0], i.p_size[1], i.frame_index],
            mask: i.mask,
            view_proj: i.view.view_projection().to_cols_array_2d(),
            prev_view_proj: i.prev_view_proj.to_cols_array_2d(),
            inverse_projection: i.view.inverse_projection().to_cols_array_2d(),
            view_to_world: i.view.view_to_world().to_cols_array_2d(),
        }
    }
}

// Keep in sync with shaders/sky_luts/atmosphere.wgsl: SkyParams.
/// [`SkyParams`] as the sky tables' WGSL reads it: each `vec3f` shares its
/// 16 bytes with the scalar after it; 88 bytes of members, 96 in all.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SkyParamsUniforms {
    pub rayleigh_scattering: [f32; 3],
    pub ground_radius_km: f32,
    pub ozone_absorption: [f32; 3],
    pub top_radius_km: f32,
    pub ground_albedo: [f32; 3],
    pub rayleigh_scale_height_km: f32,
    pub sun_irradiance: [f32; 3],
    pub mie_scattering: f32,
    pub mie_extinction: f32,
    pub mie_scale_height_km: f32,
    pub mie_g: f32,
    pub ozone_center_km: f32,
    pub ozone_width_km: f32,
    pub sun_angular_radius_deg: f32,
    /// The WGSL struct's tail padding (its size rounds up to 16 bytes).
    pub _pad: [f32; 2],
}

const _: () = assert!(size_of::<SkyParamsUniforms>() == 96);

impl SkyParamsUniforms {
    /// The block of `p`, field for field.
    pub fn new(p: &SkyParams) -> Self {
        Self {
            rayleigh_scattering: p.rayleigh_scattering.to_array(),
            ground_radius_km: p.ground_radius_km,
            ozone_absorption: p.ozone_absorption.to_array(),
            top_radius_km: p.top_radius_km,
            ground_albedo: p.ground_albedo.to_array(),
            rayleigh_scale_height_km: p.rayleigh_scale_height_km,
            sun_irradiance: p.sun_irradiance.to_array(),
            mie_scattering: p.mie_scattering,
            mie_extinction: p.mie_extinction,
            mie_scale_height_km: p.mie_scale_height_km,
            mie_g: p.mie_g,
            ozone_center_km: p.ozone_center_km,
            ozone_width_km: p.ozone_width_km,
            sun_angular_radius_deg: p.sun_angular_radius_deg,
            _pad: [0.0; 2],
        }
    }
}

// Keep in sync with shaders/sky_luts/atmosphere.wgsl: SkyView.
/// The sky view's inputs besides [`SkyParams`]: the camera's radius (km,
/// [`radius_at_altitude`]) and the sun's cos zenith.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SkyViewUniforms {
    pub camera_radius_km: f32,
    pub sun_cos_zenith: f32,
}

const _: () = assert!(size_of::<SkyViewUniforms>() == 8);
