//! `VolumeRenderer`: clouds played back from precomputed density volumes
//! (Iwasaki, Nishino & Dobashi 2011; `crate::endless` builds the database
//! and picks the pair each frame blends). Every volume is resident in one
//! 8-bit 3D texture, stacked along `y`, uploaded once; a frame changes
//! only the 64-byte pick. One full-screen pass straight into the target
//! (`shaders/volume.wgsl`; the CPU twin is `render::cpu::volume`).

use super::bind;
use super::settings::GpuSettings;
use super::standalone::StandalonePass;
use super::{GpuContext, GpuError};
use crate::render::camera::Camera;
use crate::render::cpu::volume::{VolumeParams, VolumeStack};
use crate::render::noise_volume::NoiseVolume;

/// The volume renderer.
pub struct VolumeRenderer {
    queue: wgpu::Queue,
    pass: StandalonePass,
    params_buffer: wgpu::Buffer,
    params: VolumeParams,
    group1: wgpu::BindGroup,
    texture_bytes: u64,
}

impl VolumeRenderer {
    /// The renderer of `stack` placed by `params` (its pick, the first
    /// pair shown) for a target of `format`, its land's fields reading
    /// `noise` (the cloud map's detail volume).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        format: wgpu::TextureFormat,
        settings: &GpuSettings,
        stack: &VolumeStack,
        params: VolumeParams,
        noise: &NoiseVolume,
    ) -> Result<Self, GpuError> {
        let [w, h, d] = stack.texture_size();
        let limit = device.limits().max_texture_dimension_3d;
        if w.max(h).max(d) > limit {
            return Err(GpuError::Wgpu(format!(
                "the volume stack is {w}x{h}x{d} texels; this device's 3D textures stop at {limit}"
            )));
        }
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("volume.stack"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: d,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::R8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        super::textures::write_all(queue, &texture, &stack.texels, 1);
        let params_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("volume.params"),
            size: size_of::<VolumeParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&params_buffer, 0, bytemuck::bytes_of(&params));
        let group1_layout = bind::layout(
            device,
            "volume.stack",
            &[
                bind::texture_3d_entry(0, wgpu::TextureSampleType::Float { filterable: false }),
                bind::uniform_entry(1),
            ],
        );
        let view = bind::view(&texture);
        let group1 = bind::bind(
            device,
            "volume.stack",
            &group1_layout,
            &[
                wgpu::BindingResource::TextureView(&view),
                params_buffer.as_entire_binding(),
            ],
        );
        let pass = StandalonePass::new(
            device,
            queue,
            format,
            settings,
            "volume",
            super::shaders::volume_pass(),
            "fs_volume",
            &group1_layout,
            noise,
        );
        Ok(Self {
            queue: queue.clone(),
            pass,
            params_buffer,
            params,
            group1,
            texture_bytes: stack.texels.len() as u64,
        })
    }

    /// Shows volumes `a` and `b` blended, `w` of `b`.
    pub fn set_pick(&mut self, a: usize, b: usize, w: f32) {
        self.params.pick = [a as f32, b as f32, w.clamp(0.0, 1.0), 0.0];
        self.queue
            .write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&self.params));
    }

    /// The resident volumes' size on the GPU, bytes.
    pub fn texture_bytes(&self) -> u64 {
        self.texture_bytes
    }

    /// The target's size.
    pub fn resize(&mut self, width: u32, height: u32) {
        self.pass.resize(width, height);
    }

    /// Records the frame; with `timestamps`, writes queries 0 and 1.
    pub fn render(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        camera: &Camera,
        timestamps: Option<&wgpu::QuerySet>,
    ) {
        self.pass
            .draw(encoder, target, camera, timestamps, &self.group1);
    }

    /// Renders one frame from `camera` into a new `width x height` target
    /// and reads it back as 8-bit RGB, row-major (RGBA8 formats only).
    pub fn read_rgb8(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, GpuError> {
        self.pass
            .read_rgb8(ctx, camera, width, height, &self.group1)
    }
}
