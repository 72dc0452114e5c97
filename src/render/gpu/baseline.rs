//! The per-parcel baseline renderer (Goswami & Neyret 2017 style), for
//! `cumulus bench` only: each cloudy parcel is a noisy sphere and each
//! march sample tests every parcel, so its cost grows with the parcel
//! count, unlike the cloud-map pass. Same lighting, sky and tone map
//! (`shaders/baseline.wgsl` calls the cloud pass's functions).

use bytemuck::{Pod, Zeroable};

use super::bind::{self, Recorder};
use super::settings::GpuSettings;
use super::uniforms::{FrameInputs, FrameUniforms};
use crate::render::camera::Camera;

/// The baseline's WGSL.
pub const BASELINE: &str = include_str!("../../../shaders/baseline.wgsl");

// Keep in sync with shaders/baseline.wgsl: Sphere.
/// One parcel as a sphere: world centre and radius (m), fill density
/// (`crate::prepare::spheres` makes them from the parcels).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Sphere {
    pub centre_radius: [f32; 4],
    pub fill: [f32; 4],
}

const _: () = assert!(size_of::<Sphere>() == 32);

/// The baseline renderer: one full-screen pass straight into the target.
pub struct BaselineRenderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    settings: GpuSettings,
    uniforms: wgpu::Buffer,
    group0: wgpu::BindGroup,
    group1_layout: wgpu::BindGroupLayout,
    group1: wgpu::BindGroup,
    buffer: wgpu::Buffer,
    count: usize,
    pipeline: wgpu::RenderPipeline,
    width: u32,
    height: u32,
}

impl BaselineRenderer {
    /// The baseline for a target of `format` (its settings' quality,
    /// density scale, detail and sun are the cloud-map renderer's).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        format: wgpu::TextureFormat,
        settings: &GpuSettings,
    ) -> Self {
        let uniforms = bind::uniform_buffer(device, "baseline.frame_uniforms");
        let group0_layout = bind::layout(device, "baseline.group0", &[bind::uniform_entry(0)]);
        let group1_layout = bind::layout(device, "baseline.spheres", &[bind::storage_entry(0)]);
        let group0 = bind::bind(
            device,
            "baseline.group0",
            &group0_layout,
            &[uniforms.as_entire_binding()],
        );
        let module = bind::module(device, "baseline", super::shaders::baseline_pass());
        let mut constants = settings.constants();
        constants.push(("ENCODE_SRGB", (!format.is_srgb()) as u8 as f64));
        constants.push((
            "TONE_MAP",
            (!super::composite_pass::is_hdr(format)) as u8 as f64,
        ));
        let pipeline = bind::full_screen_pipeline(
            device,
            "baseline",
            &module,
            &[&group0_layout, &group1_layout],
            &[Some(format.into())],
            Some("fs_baseline"),
            &constants,
        );
        let (buffer, group1) = Self::sphere_buffer(device, &group1_layout, 1);
        let mut r = Self {
            device: device.clone(),
            queue: queue.clone(),
            settings: *settings,
            uniforms,
            group0,
            group1_layout,
            group1,
            buffer,
            count: 0,
            pipeline,
            width: 1,
            height: 1,
        };
        r.update_spheres(&[]);
        r
    }

    fn sphere_buffer(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        n: usize,
    ) -> (wgpu::Buffer, wgpu::BindGroup) {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("baseline.spheres"),
            size: (n.max(1) * size_of::<Sphere>()) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = bind::bind(
            device,
            "baseline.spheres",
            layout,
            &[buffer.as_entire_binding()],
        );
        (buffer, group)
    }

    /// Uploads the spheres (none: one empty sphere far below the ground).
    pub fn update_spheres(&mut self, spheres: &[Sphere]) {
        let empty = [Sphere {
            centre_radius: [0.0, -1e7, 0.0, 0.0],
            fill: [0.0; 4],
        }];
        let data = if spheres.is_empty() {
            &empty[..]
        } else {
            spheres
        };
        if data.len() != self.count {
            (self.buffer, self.group1) =
                Self::sphere_buffer(&self.device, &self.group1_layout, data.len());
            self.count = data.len();
        }
        self.queue
            .write_buffer(&self.buffer, 0, bytemuck::cast_slice(data));
    }

    /// The target's size.
    pub fn resize(&mut self, width: u32, height: u32) {
        self.width = width;
        self.height = height;
    }

    /// Records the frame; with `timestamps`, writes queries 0 and 1.
    pub fn render(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        camera: &Camera,
        timestamps: Option<&wgpu::QuerySet>,
    ) {
        if self.width == 0 || self.height == 0 {
            return;
        }
        let aspect = self.width as f32 / self.height as f32;
        let u = FrameUniforms::new(&FrameInputs {
            view: camera.view(aspect, self.settings.quality.max_distance_m),
            depth_flipped: false,
            prev_view_proj: glam::Mat4::IDENTITY,
            width: self.width,
            height: self.height,
            sun_elevation_deg: self.settings.sun_elevation_deg,
            sun_azimuth_deg: self.settings.sun_azimuth_deg,
            density: self.settings.density,
            quality: self.settings.quality,
            jitter: [0.0; 3],
            blend: 1.0,
            frame_index: 0,
            terrain: [0.0; 2],
            p_size: [1, 1],
            mask: [1, 1, 1, 0],
            map_size: 1,
        });
        self.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        let mut rec = Recorder::new(encoder, timestamps);
        let mut pass = rec.begin(
            "baseline",
            &[bind::color_attachment(target, Some(wgpu::Color::BLACK))],
            None,
        );
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group0, &[]);
        pass.set_bind_group(1, &self.group1, &[]);
        pass.draw(0..3, 0..1);
    }
}
