//! The volume renderer's CPU twin (WGSL in `shaders/volume.wgsl`, each
//! function of the same name): clouds played back from precomputed
//! density volumes (Iwasaki, Nishino & Dobashi 2011; `crate::endless`
//! builds the database and chooses the pair to show). All the volumes sit
//! in one 3D texture of 8-bit densities, stacked along `y`; a frame reads
//! two of them and blends (the cross-dissolve), marching the band with
//! steps that grow with distance and a short shadow march towards the sun
//! per lit sample. The volume tiles the plane (it is one periodic domain).
//! The light is the cloud map's (phase, multiple-scattering octaves,
//! ambient, aerial perspective), under the analytic sky (the pass binds
//! no sky tables). Reads are `textureLoad` with the trilinear weights
//! computed in the shader, so the two twins read the same bytes with the
//! same arithmetic.

use bytemuck::{Pod, Zeroable};
use glam::{Vec3, Vec4};

use super::density::band_segment;
use super::frame::Frame;
use super::lighting::shadow_ray_length;
use super::renderer::{NEAR_M, march_distance, march_step_count};
use super::sky::sun_direction;
use super::standalone::{
    StandaloneMarch, analytic, hazed_clouds, render_standalone, standalone_light, standalone_step,
};

/// Samples of a lit sample's shadow march towards the sun.
pub const VOLUME_SHADOW_STEPS: u32 = 6;

/// The longest of those marches, m: six even steps over the cloud
/// march's longer ray toward a low sun (`SHADOW_RAY_M`) would each be
/// nearly 2 km, longer than the clouds they should find.
pub const VOLUME_SHADOW_RAY_M: f32 = 2_000.0;

// Keep in sync with shaders/volume.wgsl: VolumeParams.
/// Where the volumes lie and which two a frame blends.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct VolumeParams {
    /// The box's lowest corner (m), 0.
    pub origin: [f32; 4],
    /// The box's size (m); the extinction of a full texel (1/m).
    pub extent: [f32; 4],
    /// Voxels along x, y, z of one volume; the volumes stacked.
    pub dims: [u32; 4],
    /// The two volumes shown and the weight of the second, 0.
    pub pick: [f32; 4],
}

const _: () = assert!(size_of::<VolumeParams>() == 64);

/// The volumes as the GPU holds them: one 3D texture `nx x (ny · count)
/// x nz` of bytes (x fastest, then y, then z).
#[derive(Debug, Clone, PartialEq)]
pub struct VolumeStack {
    /// Voxels of one volume along x, y (up), z.
    pub dims: [usize; 3],
    /// Volumes stacked.
    pub count: usize,
    /// The bytes, `density / full · 255` rounded.
    pub texels: Vec<u8>,
}

impl VolumeStack {
    /// The stack of `volumes`, each `dims` voxels in x-fastest order
    /// (x, then y up, then z).
    pub fn new(dims: [usize; 3], volumes: &[Vec<u8>]) -> Self {
        let [nx, ny, nz] = dims;
        let count = volumes.len();
        let mut texels = vec![0u8; nx * ny * nz * count];
        for (v, vol) in volumes.iter().enumerate() {
            for k in 0..nz {
                for j in 0..ny {
                    let src = (k * ny + j) * nx;
                    let dst = (k * ny * count + v * ny + j) * nx;
                    texels[dst..dst + nx].copy_from_slice(&vol[src..src + nx]);
                }
            }
        }
        Self {
            dims,
            count,
            texels,
        }
    }

    /// The texture's size: x, y (all volumes), z.
    pub fn texture_size(&self) -> [u32; 3] {
        [
            self.dims[0] as u32,
            (self.dims[1] * self.count) as u32,
            self.dims[2] as u32,
        ]
    }
}

/// The texel at integer `(x, y, z)` of the stack, in 0..=1 (the WGSL
/// `textureLoad` of an 8-bit unorm texel).
#[inline]
pub fn volume_texel(stack: &VolumeStack, x: i32, y: i32, z: i32) -> f32 {
    let [nx, ny, _] = stack.dims;
    let rows = ny * stack.count;
    stack.texels[(z as usize * rows + y as usize) * nx + x as usize] as f32 / 255.0
}

/// Volume `slab`'s density at `p` in 0..=1, trilinear between voxel
/// centres, periodic across, 0 past the band's ends (half a voxel of
/// fade).
#[inline]
pub fn volume_sample(p: Vec3, slab: f32, params: &VolumeParams, stack: &VolumeStack) -> f32 {
    let dims = Vec3::new(
        params.dims[0] as f32,
        params.dims[1] as f32,
        params.dims[2] as f32,
    );
    let origin = Vec3::from_slice(&params.origin[..3]);
    let extent = Vec3::from_slice(&params.extent[..3]);
    let g = (p - origin) / extent * dims - 0.5;
    if g.y < -1.0 || g.y > dims.y {
        return 0.0;
    }
    let f = g.floor();
    let t = g - f;
    let (nx, ny, nz) = (
        params.dims[0] as i32,
        params.dims[1] as i32,
        params.dims[2] as i32,
    );
    let base = slab as i32 * ny;
    let x0 = (f.x as i32).rem_euclid(nx);
    let x1 = (x0 + 1) % nx;
    let z0 = (f.z as i32).rem_euclid(nz);
    let z1 = (z0 + 1) % nz;
    let yi = f.y as i32;
    let row = |y: i32, x: i32, z: i32| {
        if y < 0 || y >= ny {
            0.0
        } else {
            volume_texel(stack, x, base + y, z)
        }
    };
    let mix = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = mix(row(yi, x0, z0), row(yi, x1, z0), t.x);
    let x10 = mix(row(yi + 1, x0, z0), row(yi + 1, x1, z0), t.x);
    let x01 = mix(row(yi, x0, z1), row(yi, x1, z1), t.x);
    let x11 = mix(row(yi + 1, x0, z1), row(yi + 1, x1, z1), t.x);
    mix(mix(x00, x10, t.y), mix(x01, x11, t.y), t.z)
}

/// Extinction (1/m) at `p`: the two picked volumes blended.
#[inline]
pub fn volume_density(p: Vec3, params: &VolumeParams, stack: &VolumeStack) -> f32 {
    let a = volume_sample(p, params.pick[0], params, stack);
    let b = volume_sample(p, params.pick[1], params, stack);
    params.extent[3] * (a + (b - a) * params.pick[2])
}

/// The sun's optical depth from `p`: [`VOLUME_SHADOW_STEPS`] even steps
/// along the shadow ray (to the band's top, at most [`VOLUME_SHADOW_RAY_M`]).
#[inline]
pub fn volume_optical_depth(
    p: Vec3,
    sun_dir: Vec3,
    length: f32,
    params: &VolumeParams,
    stack: &VolumeStack,
) -> f32 {
    let dt = length / VOLUME_SHADOW_STEPS as f32;
    let mut tau = 0.0;
    for i in 0..VOLUME_SHADOW_STEPS {
        tau += volume_density(p + sun_dir * ((i as f32 + 0.5) * dt), params, stack) * dt;
    }
    tau
}

/// The march of one ray (the twin of the WGSL `march_volume`):
/// premultiplied cloud radiance and opacity.
pub fn march_volume(
    origin: Vec3,
    dir: Vec3,
    dither: f32,
    params: &VolumeParams,
    stack: &VolumeStack,
    fr: &Frame,
) -> Vec4 {
    let q = &fr.quality;
    let d = &fr.density;
    let sky = &analytic(fr);
    let Some((t0, t1)) = band_segment(origin, dir, d.band_bottom_m, d.band_top_m, q.max_distance_m)
    else {
        return Vec4::ZERO;
    };
    let sun_dir = sun_direction(fr.sun_elevation_deg, fr.sun_azimuth_deg);
    let log_ratio = ((t1 + NEAR_M) / (t0 + NEAR_M)).ln();
    let steps = march_step_count(q.steps, log_ratio);
    let l = standalone_light(sky, dir, sun_dir, fr);
    let mut march = StandaloneMarch::START;
    for i in 0..steps {
        let ta = march_distance(t0, log_ratio, i as f32 / steps as f32);
        let tb = march_distance(t0, log_ratio, (i + 1) as f32 / steps as f32);
        let t = ta + dither * (tb - ta);
        let dt = tb - ta;
        let p = origin + dir * t;
        let sigma_t = volume_density(p, params, stack);
        if sigma_t <= 0.0 {
            continue;
        }
        let length = shadow_ray_length(p, sun_dir, d).min(VOLUME_SHADOW_RAY_M);
        let tau_sun = volume_optical_depth(p, sun_dir, length, params, stack);
        if standalone_step(&mut march, &l, p, t, dt, sigma_t, tau_sun, fr) {
            break;
        }
    }
    hazed_clouds(sky, &march, dir, sun_dir)
}

/// A `width x height` image of linear radiance (row-major): per pixel the
/// mean of `offsets` marches ([`render_standalone`]; one offset: the twin
/// of the GPU's single `fs_volume` frame).
pub fn render_volume(
    width: u32,
    height: u32,
    fr: &Frame,
    params: &VolumeParams,
    stack: &VolumeStack,
    offsets: u32,
) -> Vec<Vec3> {
    render_standalone(width, height, fr, offsets, |origin, dir, dither| {
        march_volume(origin, dir, dither, params, stack, fr)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stack_of(values: [[u8; 8]; 2]) -> (VolumeStack, VolumeParams) {
        // Two 2x2x2 volumes.
        let vols: Vec<Vec<u8>> = values.iter().map(|v| v.to_vec()).collect();
        let s = VolumeStack::new([2, 2, 2], &vols);
        let p = VolumeParams {
            origin: [0.0; 4],
            extent: [200.0, 100.0, 200.0, 0.1],
            dims: [2, 2, 2, 2],
            pick: [0.0, 1.0, 0.25, 0.0],
        };
        (s, p)
    }

    #[test]
    fn the_stack_puts_each_volume_in_its_own_rows() {
        let (s, _) = stack_of([[1, 2, 3, 4, 5, 6, 7, 8], [11, 12, 13, 14, 15, 16, 17, 18]]);
        assert_eq!(s.texture_size(), [2, 4, 2]);
        // Volume 1, voxel (1, 0, 1) = its index (1·2 + 0)·2 + 1 = 5.
        assert_eq!(volume_texel(&s, 1, 2, 1), 16.0 / 255.0);
        assert_eq!(volume_texel(&s, 0, 1, 0), 3.0 / 255.0);
    }

    #[test]
    fn samples_interpolate_wrap_across_and_blend_the_pair() {
        let (s, p) = stack_of([[255; 8], [0; 8]]);
        // Voxel centres: a full volume reads 1 anywhere inside the band.
        let at = Vec3::new(50.0, 25.0, 50.0);
        assert!((volume_sample(at, 0.0, &p, &s) - 1.0).abs() < 1e-6);
        // Across the periodic edge it is still 1.
        assert!((volume_sample(Vec3::new(-10.0, 25.0, 190.0), 0.0, &p, &s) - 1.0).abs() < 1e-6);
        // Half a voxel past the top it has faded to half, a voxel past to 0.
        assert!((volume_sample(Vec3::new(50.0, 100.0, 50.0), 0.0, &p, &s) - 0.5).abs() < 1e-6);
        assert_eq!(
            volume_sample(Vec3::new(50.0, 130.0, 50.0), 0.0, &p, &s),
            0.0
        );
        // The blend: 3/4 of the first (full) and 1/4 of the second (empty).
        assert!((volume_density(at, &p, &s) - 0.075).abs() < 1e-6);
    }

    #[test]
    fn the_shadow_march_integrates_a_uniform_slab() {
        let (s, mut p) = stack_of([[255; 8], [255; 8]]);
        p.extent[1] = 1000.0;
        let tau = volume_optical_depth(Vec3::new(50.0, 250.0, 50.0), Vec3::Y, 500.0, &p, &s);
        // 0.1/m over 500 m (the last step reaches the fading top half voxel
        // only at 3/4 of a voxel above 250 + 458: still full).
        assert!((tau - 50.0).abs() < 1e-3, "tau {tau}");
    }
}
