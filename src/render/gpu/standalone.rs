//! `StandalonePass`: what the two stand-alone renderers share, the
//! pseudo-spheroids (`spheroids.rs`) and the precomputed volumes
//! (`volume_pass.rs`): one full-screen draw straight into the target,
//! bind group 0 the frame uniforms (so the analytic sky) and the land's
//! noise (the detail volume, which the fields' woods and patches read;
//! a single texel when the land is plain), the settings' constants, its
//! own bind group 1, and an 8-bit read-back for tools and tests.

use super::bind::{self, FILTERABLE, Recorder};
use super::settings::GpuSettings;
use super::uniforms::{FrameInputs, FrameUniforms};
use super::{GpuContext, GpuError};
use crate::render::camera::Camera;
use crate::render::noise_volume::NoiseVolume;

/// One stand-alone pass: its pipeline, uniforms and target size.
pub(super) struct StandalonePass {
    label: &'static str,
    queue: wgpu::Queue,
    settings: GpuSettings,
    uniforms: wgpu::Buffer,
    group0: wgpu::BindGroup,
    pipeline: wgpu::RenderPipeline,
    format: wgpu::TextureFormat,
    width: u32,
    height: u32,
}

impl StandalonePass {
    /// The pass `label` of WGSL `source`, fragment entry `entry`, for a
    /// target of `format`, its bind group 1 laid out as `group1`; `noise`
    /// is the detail volume the land's fields read (uploaded only when
    /// the settings draw them: `quality.land_fields`).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        format: wgpu::TextureFormat,
        settings: &GpuSettings,
        label: &'static str,
        source: String,
        entry: &str,
        group1: &wgpu::BindGroupLayout,
        noise: &NoiseVolume,
    ) -> Self {
        let uniforms = bind::uniform_buffer(device, label);
        let group0_layout = bind::layout(
            device,
            label,
            &[
                bind::uniform_entry(0),
                bind::sampler_entry(4),
                bind::texture_3d_entry(5, FILTERABLE),
            ],
        );
        let sampler = bind::wrap_linear_sampler(device, "standalone.wrap_linear");
        let land_noise = super::textures::upload_noise_volume(
            device,
            queue,
            settings.quality.land_fields.then_some(noise),
        );
        // The WGSL's bindings 4 and 5 of group 0 (frame.wgsl's
        // wrap_linear and noise_tex), not the next free ones.
        let noise_view = bind::view(&land_noise);
        let group0 = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout: &group0_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::Sampler(&sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::TextureView(&noise_view),
                },
            ],
        });
        let module = bind::module(device, label, source);
        let mut constants = settings.constants();
        // No light volume here: the gains of the renderers without one.
        for (name, value) in &mut constants {
            if *name == "LIGHT_VOLUME" {
                *value = 0.0;
            }
        }
        constants.push(("ENCODE_SRGB", (!format.is_srgb()) as u8 as f64));
        constants.push((
            "TONE_MAP",
            (!super::composite_pass::is_hdr(format)) as u8 as f64,
        ));
        constants.push((
            "DITHER",
            super::composite_pass::dithers(format) as u8 as f64,
        ));
        let pipeline = bind::full_screen_pipeline(
            device,
            label,
            &module,
            &[&group0_layout, group1],
            &[Some(format.into())],
            Some(entry),
            &constants,
        );
        Self {
            label,
            queue: queue.clone(),
            settings: *settings,
            uniforms,
            group0,
            pipeline,
            format,
            width: 1,
            height: 1,
        }
    }

    /// The settings the pass was made with.
    pub(super) fn settings(&self) -> &GpuSettings {
        &self.settings
    }

    /// The target's size.
    pub(super) fn resize(&mut self, width: u32, height: u32) {
        self.width = width;
        self.height = height;
    }

    /// Records the frame of a still view from `camera` with bind group 1
    /// `group1`; with `timestamps`, writes queries 0 and 1.
    pub(super) fn draw(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        camera: &Camera,
        timestamps: Option<&wgpu::QuerySet>,
        group1: &wgpu::BindGroup,
    ) {
        if self.width == 0 || self.height == 0 {
            return;
        }
        let aspect = self.width as f32 / self.height as f32;
        let s = &self.settings;
        let u = FrameUniforms::new(&FrameInputs {
            view: camera.view(aspect, s.quality.max_distance_m),
            depth_flipped: false,
            prev_view_proj: glam::Mat4::IDENTITY,
            width: self.width,
            height: self.height,
            sun_elevation_deg: s.sun_elevation_deg,
            sun_azimuth_deg: s.sun_azimuth_deg,
            density: s.density,
            quality: s.quality,
            jitter: [0.0; 3],
            blend: 1.0,
            frame_index: 0,
            terrain: [0.0; 3],
            p_size: [1, 1],
            mask: [1, 1, 1, 0],
            map_size: 1,
            sea_in_layer: false,
            cloud_cover: 0.0,
        });
        self.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        let mut rec = Recorder::new(encoder, timestamps);
        let mut pass = rec.begin(
            self.label,
            &[bind::color_attachment(target, Some(wgpu::Color::BLACK))],
            None,
        );
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group0, &[]);
        pass.set_bind_group(1, group1, &[]);
        pass.draw(0..3, 0..1);
    }

    /// Draws one frame from `camera` into a new `width x height` target of
    /// the pass's format and reads it back as 8-bit RGB, row-major (`Err`
    /// for other than an RGBA8 format: read those yourself).
    pub(super) fn read_rgb8(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        width: u32,
        height: u32,
        group1: &wgpu::BindGroup,
    ) -> Result<Vec<u8>, GpuError> {
        use wgpu::TextureFormat::{Rgba8Unorm, Rgba8UnormSrgb};
        if !matches!(self.format, Rgba8Unorm | Rgba8UnormSrgb) {
            return Err(GpuError::Readback(format!(
                "the {} pass reads back RGBA8 targets, not {:?}",
                self.label, self.format
            )));
        }
        self.resize(width, height);
        let target = super::textures::create_2d(
            &ctx.device,
            self.label,
            width,
            height,
            self.format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let view = target.create_view(&Default::default());
        let mut e = ctx.device.create_command_encoder(&Default::default());
        self.draw(&mut e, &view, camera, None, group1);
        ctx.queue.submit([e.finish()]);
        let px = ctx.read_texture(&target, 4)?;
        Ok(px
            .chunks_exact(4)
            .flat_map(|q| [q[0], q[1], q[2]])
            .collect())
    }
}
