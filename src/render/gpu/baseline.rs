//! The per-parcel baseline renderer (Goswami & Neyret 2017 style), for
//! `cumulus bench` only: each cloudy parcel is a noisy sphere and each
//! march sample tests every parcel, so its cost grows with the parcel
//! count, unlike the cloud-map pass. Same lighting, sky and tone map
//! (`shaders/baseline.wgsl` calls the cloud pass's functions).

use bytemuck::{Pod, Zeroable};

use super::renderer::GpuSettings;
use super::shaders::{CLOUDS, COMPOSITE};
use super::uniforms::{FrameInputs, FrameUniforms};
use crate::render::cpu::camera::Camera;
use crate::sim::Parcels;

/// The baseline's WGSL.
pub const BASELINE: &str = include_str!("../../../shaders/baseline.wgsl");

// Keep in sync with shaders/baseline.wgsl: Sphere.
/// One parcel as a sphere: world centre and radius (m), fill density.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Sphere {
    pub centre_radius: [f32; 4],
    pub fill: [f32; 4],
}

const _: () = assert!(size_of::<Sphere>() == 32);

/// The cloudy, released parcels as spheres in the world frame (the
/// physics' `(x, y, z)` is the world's `(x, z, y)`), with the fill the
/// projection gives them. The spheres are not tiled: the domain is drawn
/// once.
pub fn spheres(parcels: &Parcels, fill_full_condensed_fraction: f64) -> Vec<Sphere> {
    let full = fill_full_condensed_fraction.max(1e-12);
    (0..parcels.len())
        .filter(|&i| parcels.diag[i].qc > 0.0 && parcels.life[i].released())
        .map(|i| {
            let p = parcels.pos[i];
            let qt = parcels.qt[i];
            let fill = if qt > 0.0 {
                (parcels.diag[i].qc / qt / full).clamp(0.0, 1.0)
            } else {
                0.0
            };
            Sphere {
                centre_radius: [
                    p.x as f32,
                    p.z as f32,
                    p.y as f32,
                    parcels.life[i].radius_m as f32,
                ],
                fill: [fill as f32, 0.0, 0.0, 0.0],
            }
        })
        .collect()
}

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
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("baseline.frame_uniforms"),
            size: size_of::<FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty,
            count: None,
        };
        let group0_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("baseline.group0"),
            entries: &[entry(
                0,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
            )],
        });
        let group1_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("baseline.spheres"),
            entries: &[entry(
                1,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
            )],
        });
        let group0 = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("baseline.group0"),
            layout: &group0_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniforms.as_entire_binding(),
            }],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("baseline"),
            source: wgpu::ShaderSource::Wgsl(format!("{CLOUDS}\n{COMPOSITE}\n{BASELINE}").into()),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("baseline"),
            bind_group_layouts: &[Some(&group0_layout), Some(&group1_layout)],
            immediate_size: 0,
        });
        let s = settings;
        let constants = [
            ("SHADOW_STEPS", s.quality.shadow_steps as f64),
            ("OCTAVES", s.quality.octaves as f64),
            ("DETAIL", (s.density.detail_strength > 0.0) as u8 as f64),
            ("ENCODE_SRGB", (!format.is_srgb()) as u8 as f64),
        ];
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("baseline"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_full_screen"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_baseline"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    zero_initialize_workgroup_memory: false,
                },
                targets: &[Some(format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
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
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("baseline.spheres"),
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 1,
                resource: buffer.as_entire_binding(),
            }],
        });
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
        let u = FrameUniforms::new(&FrameInputs {
            camera: *camera,
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
        });
        self.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("baseline"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timestamps.map(|q| wgpu::RenderPassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: Some(0),
                end_of_pass_write_index: Some(1),
            }),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group0, &[]);
        pass.set_bind_group(1, &self.group1, &[]);
        pass.draw(0..3, 0..1);
    }
}
