//! [`CloudRenderer`]: the cloud band ray-cast as a set of wgpu passes, to
//! embed in any wgpu application.
//!
//! Passes, in order (each exists only when the scene needs it):
//! 1. `terrain` (scene has terrain): the heightfield mesh into an HDR
//!    colour target and a depth buffer.
//! 2. `clouds`: full-screen; marches the band segment of each ray up to the
//!    depth (terrain or an external depth buffer) into the cloud layer
//!    (premultiplied radiance, opacity) and, with TSAA, the cloud distance.
//! 3. `tsaa` (TSAA on): reprojects, clamps and blends the history
//!    (ping-pong pair).
//! 4. `composite`: clouds over the sky or terrain, tone-mapped into the
//!    target.

use glam::Mat4;

use super::shaders::{self, Background};
use super::textures::{self, CLOUD_FORMAT, DEPTH_FORMAT, DISTANCE_FORMAT};
use super::tsaa::{TsaaSettings, is_cut, jitter};
use super::uniforms::{FrameInputs, FrameUniforms, view_projection};
use crate::render::cloud_map::CloudMap;
use crate::render::coverage_mask::CoverageMask;
use crate::render::cpu::camera::Camera;
use crate::render::cpu::density::DensityParams;
use crate::render::cpu::renderer::Quality;
use crate::render::terrain::Heightfield;
use crate::sim::ProjectedField;

/// What the renderer draws and how well. Changing it with
/// [`CloudRenderer::set_settings`] rebuilds only what changed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpuSettings {
    pub density: DensityParams,
    pub quality: Quality,
    pub sun_elevation_deg: f32,
    pub sun_azimuth_deg: f32,
    /// Temporal anti-aliasing (none: no jitter, no history textures, no pass).
    pub tsaa: Option<TsaaSettings>,
    /// Debug: the cloud layer's red channel holds the number of density
    /// samples each pixel took (its alpha is 0), to show that the per-pixel
    /// work does not depend on the parcel count.
    pub debug_sample_count: bool,
}

/// Errors of [`CloudRenderer::render`].
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RenderError {
    #[error(
        "the depth buffer is {depth_w}x{depth_h} but the renderer is {width}x{height}: call resize() with the target's size"
    )]
    DepthSizeMismatch {
        depth_w: u32,
        depth_h: u32,
        width: u32,
        height: u32,
    },
    #[error("the depth buffer's format {0:?} is not a depth format")]
    NotADepthFormat(wgpu::TextureFormat),
    #[error(
        "the target's format {target:?} is not the format {expected:?} the renderer was created for"
    )]
    TargetFormat {
        target: wgpu::TextureFormat,
        expected: wgpu::TextureFormat,
    },
}

/// The passes' names, in the order they run.
pub const PASS_TERRAIN: &str = "terrain";
pub const PASS_CLOUDS: &str = "clouds";
pub const PASS_TSAA: &str = "tsaa";
pub const PASS_COMPOSITE: &str = "composite";

struct TerrainPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    group1: wgpu::BindGroup,
    vertices: u32,
    extent_m: f32,
    max_m: f32,
    color: Option<wgpu::Texture>,
    depth: Option<wgpu::Texture>,
}

struct TsaaPass {
    settings: TsaaSettings,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    history: Option<[wgpu::Texture; 2]>,
    distance: Option<wgpu::Texture>,
    /// History texture written last.
    latest: usize,
    /// Frames accumulated since the last reset.
    frames: u32,
}

/// The wgpu cloud renderer. It sees the simulation only through the
/// projected field P ([`CloudRenderer::update_field`]).
pub struct CloudRenderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    target_format: wgpu::TextureFormat,
    settings: GpuSettings,
    width: u32,
    height: u32,
    uniforms: wgpu::Buffer,
    group0_layout: wgpu::BindGroupLayout,
    group0: wgpu::BindGroup,
    wrap_sampler: wgpu::Sampler,
    p_texture: wgpu::Texture,
    p_size: [u32; 2],
    cloud_map: wgpu::Texture,
    mask: wgpu::Texture,
    mask_info: [u32; 4],
    field: Option<ProjectedField>,
    /// Cloud pass pipelines without and with a depth input, built on first use.
    cloud_pipelines: [Option<wgpu::RenderPipeline>; 2],
    depth_layout: wgpu::BindGroupLayout,
    cloud_layer: Option<wgpu::Texture>,
    /// Composite pipelines, built on first use.
    composite: Vec<(Background, wgpu::RenderPipeline, wgpu::BindGroupLayout)>,
    tsaa: Option<TsaaPass>,
    terrain: Option<TerrainPass>,
    prev_camera: Option<Camera>,
    prev_view_proj: Mat4,
    frame_index: u32,
    timestamps: Option<wgpu::QuerySet>,
    last_passes: Vec<&'static str>,
}

fn tex_entry(binding: u32, sample_type: wgpu::TextureSampleType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

const FLOAT: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: true };
const UNFILTERED: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: false };

fn sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

fn layout(
    device: &wgpu::Device,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries,
    })
}

fn bind(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = resources
        .iter()
        .enumerate()
        .map(|(i, r)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: r.clone(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

fn view(t: &wgpu::Texture) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor::default())
}

/// The full-screen triangle's vertex state.
fn full_screen(module: &wgpu::ShaderModule) -> wgpu::VertexState<'_> {
    wgpu::VertexState {
        module,
        entry_point: Some("vs_full_screen"),
        compilation_options: Default::default(),
        buffers: &[],
    }
}

impl CloudRenderer {
    /// Creates the renderer for a target of `target_format`. The cloud map
    /// is uploaded once; P starts empty (clear sky) until
    /// [`Self::update_field`]. `terrain` builds the terrain pass.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        target_format: wgpu::TextureFormat,
        settings: &GpuSettings,
        cloud_map: &CloudMap,
        terrain: Option<&Heightfield>,
    ) -> Self {
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("clouds.frame_uniforms"),
            size: size_of::<FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group0_layout = layout(
            device,
            "clouds.group0",
            &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                tex_entry(1, FLOAT),
                tex_entry(2, FLOAT),
                tex_entry(3, wgpu::TextureSampleType::Uint),
                sampler_entry(4),
            ],
        );
        let depth_layout = layout(
            device,
            "clouds.depth",
            &[tex_entry(0, wgpu::TextureSampleType::Depth)],
        );
        let wrap_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("clouds.wrap_linear"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let empty = ProjectedField::new(1, 1);
        let p_texture = textures::upload_field(
            device,
            queue,
            "clouds.P",
            1,
            1,
            &textures::field_texels(&empty),
        );
        let n = cloud_map.size() as u32;
        let cm = textures::upload_field(
            device,
            queue,
            "clouds.cloud_map",
            n,
            n,
            &textures::cloud_map_texels(cloud_map),
        );
        let mask = CoverageMask::build(&empty, settings.density.map_extent_m, 0.0);
        let mask_tex = textures::upload_mask(device, queue, &mask);
        let group0 = bind(
            device,
            "clouds.group0",
            &group0_layout,
            &[
                uniforms.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view(&p_texture)),
                wgpu::BindingResource::TextureView(&view(&cm)),
                wgpu::BindingResource::TextureView(&view(&mask_tex)),
                wgpu::BindingResource::Sampler(&wrap_sampler),
            ],
        );
        let mut r = Self {
            device: device.clone(),
            queue: queue.clone(),
            target_format,
            settings: *settings,
            width: 0,
            height: 0,
            uniforms,
            group0_layout,
            group0,
            wrap_sampler,
            p_texture,
            p_size: [1, 1],
            cloud_map: cm,
            mask: mask_tex,
            mask_info: [1, 1, mask.cell as u32, 0],
            field: None,
            cloud_pipelines: [None, None],
            depth_layout,
            cloud_layer: None,
            composite: Vec::new(),
            tsaa: None,
            terrain: None,
            prev_camera: None,
            prev_view_proj: Mat4::IDENTITY,
            frame_index: 0,
            timestamps: None,
            last_passes: Vec::new(),
        };
        r.tsaa = settings.tsaa.map(|t| r.build_tsaa(t));
        r.terrain = terrain.map(|h| r.build_terrain(h));
        r
    }

    /// Values of the pipeline-overridable constants for the settings.
    fn constants(&self) -> Vec<(&'static str, f64)> {
        let s = &self.settings;
        vec![
            ("SHADOW_STEPS", s.quality.shadow_steps as f64),
            ("OCTAVES", s.quality.octaves as f64),
            (
                "DETAIL",
                if s.density.detail_strength > 0.0 {
                    1.0
                } else {
                    0.0
                },
            ),
            ("DEBUG_COUNT", if s.debug_sample_count { 1.0 } else { 0.0 }),
        ]
    }

    fn module(&self, label: &str, source: String) -> wgpu::ShaderModule {
        self.device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            })
    }

    fn pipeline(
        &self,
        label: &str,
        module: &wgpu::ShaderModule,
        group1: &wgpu::BindGroupLayout,
        targets: &[Option<wgpu::ColorTargetState>],
        extra_constants: &[(&'static str, f64)],
    ) -> wgpu::RenderPipeline {
        let pl = self
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &[Some(&self.group0_layout), Some(group1)],
                immediate_size: 0,
            });
        let mut constants = self.constants();
        constants.extend_from_slice(extra_constants);
        self.device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pl),
                vertex: full_screen(module),
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: None,
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        zero_initialize_workgroup_memory: false,
                    },
                    targets,
                }),
                multiview_mask: None,
                cache: None,
            })
    }

    fn build_tsaa(&self, settings: TsaaSettings) -> TsaaPass {
        let layout_ = layout(
            &self.device,
            "tsaa.group1",
            &[
                tex_entry(0, UNFILTERED),
                tex_entry(1, UNFILTERED),
                tex_entry(2, FLOAT),
                sampler_entry(3),
            ],
        );
        let module = self.module("tsaa", shaders::tsaa_pass());
        let pipeline = self.pipeline("tsaa", &module, &layout_, &[Some(CLOUD_FORMAT.into())], &[]);
        let sampler = self.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("tsaa.clamp_linear"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        TsaaPass {
            settings,
            pipeline,
            layout: layout_,
            sampler,
            history: None,
            distance: None,
            latest: 0,
            frames: 0,
        }
    }

    fn build_terrain(&self, h: &Heightfield) -> TerrainPass {
        let layout_ = layout(&self.device, "terrain.group1", &[tex_entry(0, UNFILTERED)]);
        let heights = textures::upload_heights(&self.device, &self.queue, h);
        let group1 = bind(
            &self.device,
            "terrain.group1",
            &layout_,
            &[wgpu::BindingResource::TextureView(&view(&heights))],
        );
        let pipeline = self.terrain_pipeline(&layout_);
        let n = h.size() as u32;
        TerrainPass {
            pipeline,
            layout: layout_,
            group1,
            vertices: n * n * 6,
            extent_m: h.extent_m(),
            max_m: h.max_m(),
            color: None,
            depth: None,
        }
    }

    fn terrain_pipeline(&self, layout_: &wgpu::BindGroupLayout) -> wgpu::RenderPipeline {
        let module = self.module("terrain", shaders::terrain_pass());
        let pl = self
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("terrain"),
                bind_group_layouts: &[Some(&self.group0_layout), Some(layout_)],
                immediate_size: 0,
            });
        let constants = self.constants();
        self.device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("terrain"),
                layout: Some(&pl),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_terrain"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        zero_initialize_workgroup_memory: false,
                    },
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_terrain"),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        zero_initialize_workgroup_memory: false,
                    },
                    targets: &[Some(CLOUD_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
    }

    fn cloud_pipeline(&mut self, depth: bool) -> &wgpu::RenderPipeline {
        let k = depth as usize;
        if self.cloud_pipelines[k].is_none() {
            let tsaa = self.tsaa.is_some();
            let module = self.module("clouds", shaders::cloud_pass(depth, tsaa));
            let empty = layout(&self.device, "clouds.no_depth", &[]);
            let group1 = if depth { &self.depth_layout } else { &empty };
            let mut targets = vec![Some(CLOUD_FORMAT.into())];
            if tsaa {
                targets.push(Some(DISTANCE_FORMAT.into()));
            }
            self.cloud_pipelines[k] = Some(self.pipeline("clouds", &module, group1, &targets, &[]));
        }
        self.cloud_pipelines[k].as_ref().expect("built above")
    }

    fn composite_pipeline(&mut self, background: Background) -> usize {
        if let Some(i) = self.composite.iter().position(|(b, _, _)| *b == background) {
            return i;
        }
        let mut entries = vec![tex_entry(0, UNFILTERED)];
        match background {
            Background::Sky => {}
            Background::Terrain => entries.push(tex_entry(1, UNFILTERED)),
            Background::ExternalDepth => entries.push(tex_entry(1, wgpu::TextureSampleType::Depth)),
        }
        let layout_ = layout(&self.device, "composite.group1", &entries);
        let module = self.module("composite", shaders::composite_pass(background));
        let blend = (background == Background::ExternalDepth)
            .then_some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING);
        let encode = if self.target_format.is_srgb() {
            0.0
        } else {
            1.0
        };
        let pipeline = self.pipeline(
            "composite",
            &module,
            &layout_,
            &[Some(wgpu::ColorTargetState {
                format: self.target_format,
                blend,
                write_mask: wgpu::ColorWrites::ALL,
            })],
            &[("ENCODE_SRGB", encode)],
        );
        self.composite.push((background, pipeline, layout_));
        self.composite.len() - 1
    }

    /// Uploads a new P (after each physics step). P may change size.
    pub fn update_field(&mut self, queue: &wgpu::Queue, field: &ProjectedField) {
        let (w, h) = (field.width().max(1) as u32, field.height().max(1) as u32);
        let texels = if field.width() == 0 || field.height() == 0 {
            textures::field_texels(&ProjectedField::new(1, 1))
        } else {
            textures::field_texels(field)
        };
        let mut rebind = false;
        if [w, h] != self.p_size {
            self.p_texture = textures::upload_field(&self.device, queue, "clouds.P", w, h, &texels);
            self.p_size = [w, h];
            rebind = true;
        } else {
            textures::write_all(queue, &self.p_texture, bytemuck::cast_slice(&texels), 8);
        }
        self.field = Some(field.clone());
        rebind |= self.upload_mask();
        if rebind {
            self.rebind_group0();
        }
    }

    /// Rebuilds the coverage mask for the current P and detail warp;
    /// whether the mask texture was replaced.
    fn upload_mask(&mut self) -> bool {
        let Some(field) = &self.field else {
            return false;
        };
        let d = &self.settings.density;
        let warp = if d.detail_strength > 0.0 {
            d.detail_scale_m * d.detail_strength
        } else {
            0.0
        };
        let mask = CoverageMask::build(field, d.map_extent_m, warp);
        let info = [mask.width as u32, mask.height as u32, mask.cell as u32, 0];
        if info == self.mask_info {
            textures::write_all(&self.queue, &self.mask, &mask.cells, 1);
            false
        } else {
            self.mask = textures::upload_mask(&self.device, &self.queue, &mask);
            self.mask_info = info;
            true
        }
    }

    fn rebind_group0(&mut self) {
        self.group0 = bind(
            &self.device,
            "clouds.group0",
            &self.group0_layout,
            &[
                self.uniforms.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view(&self.p_texture)),
                wgpu::BindingResource::TextureView(&view(&self.cloud_map)),
                wgpu::BindingResource::TextureView(&view(&self.mask)),
                wgpu::BindingResource::Sampler(&self.wrap_sampler),
            ],
        );
    }

    /// Adds, replaces or (with `None`) removes the terrain and its pass.
    pub fn set_terrain(&mut self, terrain: Option<&Heightfield>) {
        self.terrain = terrain.map(|h| self.build_terrain(h));
        self.cloud_pipelines = [None, None];
    }

    /// Replaces the cloud map.
    pub fn update_cloud_map(&mut self, queue: &wgpu::Queue, cloud_map: &CloudMap) {
        let n = cloud_map.size() as u32;
        self.cloud_map = textures::upload_field(
            &self.device,
            queue,
            "clouds.cloud_map",
            n,
            n,
            &textures::cloud_map_texels(cloud_map),
        );
        self.rebind_group0();
    }

    /// Changes the settings: pipelines whose constants changed are rebuilt
    /// (on first use), TSAA's pass and textures are created or dropped.
    pub fn set_settings(&mut self, settings: &GpuSettings) {
        let old = std::mem::replace(&mut self.settings, *settings);
        let constants_changed = old.quality.shadow_steps != settings.quality.shadow_steps
            || old.quality.octaves != settings.quality.octaves
            || (old.density.detail_strength > 0.0) != (settings.density.detail_strength > 0.0)
            || old.debug_sample_count != settings.debug_sample_count;
        let tsaa_changed = old.tsaa.is_some() != settings.tsaa.is_some();
        if constants_changed || tsaa_changed {
            self.cloud_pipelines = [None, None];
            self.composite.clear();
        }
        if tsaa_changed || (constants_changed && self.tsaa.is_some()) {
            self.tsaa = settings.tsaa.map(|t| self.build_tsaa(t));
            self.cloud_layer = None;
        } else if let (Some(t), Some(s)) = (&mut self.tsaa, settings.tsaa) {
            t.settings = s;
        }
        if constants_changed && self.terrain.is_some() {
            // The terrain's cloud shadows use the shadow-step constant.
            let pipeline = self.terrain_pipeline(&self.terrain.as_ref().expect("checked").layout);
            if let Some(t) = &mut self.terrain {
                t.pipeline = pipeline;
            }
        }
        if old.density != settings.density && self.upload_mask() {
            self.rebind_group0();
        }
    }

    /// The settings in use.
    pub fn settings(&self) -> &GpuSettings {
        &self.settings
    }

    /// Sets the size of the target. Zero in either direction is allowed (a
    /// minimised window): `render` then draws nothing. Resets the history.
    pub fn resize(&mut self, width: u32, height: u32) {
        if (width, height) == (self.width, self.height) {
            return;
        }
        self.width = width;
        self.height = height;
        self.cloud_layer = None;
        if let Some(t) = &mut self.tsaa {
            t.history = None;
            t.distance = None;
            t.frames = 0;
        }
        if let Some(t) = &mut self.terrain {
            t.color = None;
            t.depth = None;
        }
    }

    /// The size set by [`Self::resize`].
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Forgets the TSAA history (the next frame is a camera cut).
    pub fn reset_history(&mut self) {
        if let Some(t) = &mut self.tsaa {
            t.frames = 0;
        }
    }

    /// The frame counter that picks the TSAA jitter (it cycles every
    /// [`super::tsaa::JITTER_CYCLE`] frames).
    pub fn frame_index(&self) -> u32 {
        self.frame_index
    }

    /// Sets the frame counter (to replay a jitter phase).
    pub fn set_frame_index(&mut self, n: u32) {
        self.frame_index = n;
    }

    /// Frames in the TSAA history since the last reset (0 without TSAA).
    pub fn history_frames(&self) -> u32 {
        self.tsaa.as_ref().map_or(0, |t| t.frames)
    }

    /// Writes each pass's start and end into `query_set` (two timestamps per
    /// pass, in the order of [`Self::last_passes`]; at least 8 queries).
    /// Needs `Features::TIMESTAMP_QUERY`. `None` stops it.
    pub fn set_timestamp_queries(&mut self, query_set: Option<wgpu::QuerySet>) {
        self.timestamps = query_set;
    }

    /// The passes the last [`Self::render`] ran, in order.
    pub fn last_passes(&self) -> &[&'static str] {
        &self.last_passes
    }

    /// The pipelines that exist now (built on first use), by pass name.
    pub fn pipelines(&self) -> Vec<&'static str> {
        let mut v = Vec::new();
        if self.terrain.is_some() {
            v.push(PASS_TERRAIN);
        }
        let clouds = self.cloud_pipelines.iter().flatten().count();
        v.extend(std::iter::repeat_n(PASS_CLOUDS, clouds));
        if self.tsaa.is_some() {
            v.push(PASS_TSAA);
        }
        v.extend(std::iter::repeat_n(PASS_COMPOSITE, self.composite.len()));
        v
    }

    /// The textures that exist now, by label.
    pub fn textures(&self) -> Vec<&'static str> {
        let mut v = vec!["clouds.P", "clouds.cloud_map", "clouds.coverage_mask"];
        if self.cloud_layer.is_some() {
            v.push("clouds.layer");
        }
        if let Some(t) = &self.tsaa {
            if t.distance.is_some() {
                v.push("clouds.distance");
            }
            if t.history.is_some() {
                v.extend(["tsaa.history0", "tsaa.history1"]);
            }
        }
        if let Some(t) = &self.terrain {
            v.push("terrain.heights");
            if t.color.is_some() {
                v.extend(["terrain.color", "terrain.depth"]);
            }
        }
        v
    }

    /// The cloud layer of the last frame (premultiplied radiance, opacity;
    /// or the sample counts with `debug_sample_count`), for debug views and
    /// tests. `None` before the first frame.
    pub fn cloud_layer(&self) -> Option<&wgpu::Texture> {
        self.cloud_layer.as_ref()
    }

    fn ensure_targets(&mut self) {
        let (w, h) = (self.width, self.height);
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        if self.cloud_layer.is_none() {
            self.cloud_layer = Some(textures::create_2d(
                &self.device,
                "clouds.layer",
                w,
                h,
                CLOUD_FORMAT,
                usage,
            ));
        }
        if let Some(t) = &mut self.tsaa
            && t.history.is_none()
        {
            let make = |label| textures::create_2d(&self.device, label, w, h, CLOUD_FORMAT, usage);
            t.history = Some([make("tsaa.history0"), make("tsaa.history1")]);
            t.distance = Some(textures::create_2d(
                &self.device,
                "clouds.distance",
                w,
                h,
                DISTANCE_FORMAT,
                usage,
            ));
            t.frames = 0;
        }
        if let Some(t) = &mut self.terrain
            && t.color.is_none()
        {
            t.color = Some(textures::create_2d(
                &self.device,
                "terrain.color",
                w,
                h,
                CLOUD_FORMAT,
                usage,
            ));
            t.depth = Some(textures::create_2d(
                &self.device,
                "terrain.depth",
                w,
                h,
                DEPTH_FORMAT,
                usage,
            ));
        }
    }

    fn timestamp_writes(&self, pass: usize) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.timestamps
            .as_ref()
            .map(|q| wgpu::RenderPassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: Some(2 * pass as u32),
                end_of_pass_write_index: Some(2 * pass as u32 + 1),
            })
    }

    /// Records one frame into `encoder`: the clouds (and sky, sun and
    /// terrain) seen by `camera` into `target` (a view of a texture of the
    /// size given to [`Self::resize`] and the format given to
    /// [`Self::new`]). With `depth` (a single-sampled depth texture of the
    /// same size, written with [`super::uniforms::view_projection`]'s
    /// convention, and `TEXTURE_BINDING` usage), pixels with geometry keep
    /// their colour and only the clouds in front of it are blended over
    /// them; pixels at the far plane (1.0) get sky and clouds. The scene's
    /// own terrain takes the place of `depth` when it has one.
    pub fn render(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        depth: Option<&wgpu::TextureView>,
        camera: &Camera,
    ) -> Result<(), RenderError> {
        self.last_passes.clear();
        if self.width == 0 || self.height == 0 {
            return Ok(());
        }
        let tf = target.texture().format();
        if tf.remove_srgb_suffix() != self.target_format.remove_srgb_suffix()
            || tf != self.target_format
        {
            return Err(RenderError::TargetFormat {
                target: tf,
                expected: self.target_format,
            });
        }
        if let Some(d) = depth {
            let t = d.texture();
            if !t.format().is_depth_stencil_format() {
                return Err(RenderError::NotADepthFormat(t.format()));
            }
            if (t.width(), t.height()) != (self.width, self.height) {
                return Err(RenderError::DepthSizeMismatch {
                    depth_w: t.width(),
                    depth_h: t.height(),
                    width: self.width,
                    height: self.height,
                });
            }
        }
        self.ensure_targets();
        // Uniforms: jitter and the blend weight with TSAA.
        let cut = self.prev_camera.is_none_or(|p| is_cut(&p, camera));
        let (jit, blend) = match &mut self.tsaa {
            Some(t) => {
                if cut {
                    t.frames = 0;
                }
                let blend = if t.frames == 0 {
                    1.0
                } else {
                    t.settings.blend.clamp(1e-3, 1.0)
                };
                (jitter(self.frame_index), blend)
            }
            None => ([0.0; 3], 1.0),
        };
        let aspect = self.width as f32 / self.height as f32;
        let view_proj = view_projection(camera, aspect, self.settings.quality.max_distance_m);
        let prev = if cut { view_proj } else { self.prev_view_proj };
        let terrain = self
            .terrain
            .as_ref()
            .map_or([0.0; 2], |t| [t.extent_m, t.max_m]);
        let u = FrameUniforms::new(&FrameInputs {
            camera: *camera,
            prev_view_proj: prev,
            width: self.width,
            height: self.height,
            sun_elevation_deg: self.settings.sun_elevation_deg,
            sun_azimuth_deg: self.settings.sun_azimuth_deg,
            density: self.settings.density,
            quality: self.settings.quality,
            jitter: jit,
            blend,
            frame_index: self.frame_index,
            terrain,
            p_size: self.p_size,
            mask: self.mask_info,
        });
        self.queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        let mut pass_index = 0;

        // 1. Terrain.
        if let Some(t) = &self.terrain {
            let (cv, dv) = (
                view(t.color.as_ref().expect("ensured")),
                view(t.depth.as_ref().expect("ensured")),
            );
            let reach = (self.settings.quality.max_distance_m / t.extent_m).ceil() as u32;
            let instances = (2 * reach + 1).pow(2);
            let ts = self.timestamp_writes(pass_index);
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("terrain"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &cv,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &dv,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: ts,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&t.pipeline);
            pass.set_bind_group(0, &self.group0, &[]);
            pass.set_bind_group(1, &t.group1, &[]);
            pass.draw(0..t.vertices, 0..instances);
            drop(pass);
            self.last_passes.push(PASS_TERRAIN);
            pass_index += 1;
        }

        // 2. Clouds.
        let own_depth = self
            .terrain
            .as_ref()
            .and_then(|t| t.depth.as_ref())
            .map(view);
        let depth_view = own_depth.as_ref().or(depth);
        let depth_group = depth_view.map(|d| {
            bind(
                &self.device,
                "clouds.depth",
                &self.depth_layout,
                &[wgpu::BindingResource::TextureView(d)],
            )
        });
        let empty_group = bind(
            &self.device,
            "clouds.no_depth",
            &layout(&self.device, "clouds.no_depth", &[]),
            &[],
        );
        self.cloud_pipeline(depth_view.is_some());
        let cloud_view = view(self.cloud_layer.as_ref().expect("ensured"));
        let distance_view = self
            .tsaa
            .as_ref()
            .and_then(|t| t.distance.as_ref())
            .map(view);
        {
            let mut attachments = vec![Some(wgpu::RenderPassColorAttachment {
                view: &cloud_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })];
            if let Some(dv) = &distance_view {
                attachments.push(Some(wgpu::RenderPassColorAttachment {
                    view: dv,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                }));
            }
            let ts = self.timestamp_writes(pass_index);
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("clouds"),
                color_attachments: &attachments,
                depth_stencil_attachment: None,
                timestamp_writes: ts,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let pipeline = self.cloud_pipelines[depth_view.is_some() as usize]
                .as_ref()
                .expect("built above");
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &self.group0, &[]);
            pass.set_bind_group(1, depth_group.as_ref().unwrap_or(&empty_group), &[]);
            pass.draw(0..3, 0..1);
        }
        self.last_passes.push(PASS_CLOUDS);
        pass_index += 1;

        // 3. TSAA.
        let mut resolved = cloud_view.clone();
        if let Some(t) = &self.tsaa {
            let history = t.history.as_ref().expect("ensured");
            let (read, write) = (t.latest, 1 - t.latest);
            let (rv, wv) = (view(&history[read]), view(&history[write]));
            let group1 = bind(
                &self.device,
                "tsaa.group1",
                &t.layout,
                &[
                    wgpu::BindingResource::TextureView(&cloud_view),
                    wgpu::BindingResource::TextureView(distance_view.as_ref().expect("ensured")),
                    wgpu::BindingResource::TextureView(&rv),
                    wgpu::BindingResource::Sampler(&t.sampler),
                ],
            );
            let ts = self.timestamp_writes(pass_index);
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("tsaa"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &wv,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: ts,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&t.pipeline);
            pass.set_bind_group(0, &self.group0, &[]);
            pass.set_bind_group(1, &group1, &[]);
            pass.draw(0..3, 0..1);
            drop(pass);
            resolved = wv;
            self.last_passes.push(PASS_TSAA);
            pass_index += 1;
        }
        if let Some(t) = &mut self.tsaa {
            t.latest = 1 - t.latest;
            t.frames += 1;
        }

        // 4. Composite.
        let background = if self.terrain.is_some() {
            Background::Terrain
        } else if depth.is_some() {
            Background::ExternalDepth
        } else {
            Background::Sky
        };
        let ci = self.composite_pipeline(background);
        let terrain_color = self
            .terrain
            .as_ref()
            .and_then(|t| t.color.as_ref())
            .map(view);
        let mut resources = vec![wgpu::BindingResource::TextureView(&resolved)];
        match background {
            Background::Sky => {}
            Background::Terrain => resources.push(wgpu::BindingResource::TextureView(
                terrain_color.as_ref().expect("ensured"),
            )),
            Background::ExternalDepth => resources.push(wgpu::BindingResource::TextureView(
                depth.expect("chosen above"),
            )),
        }
        let (_, pipeline, layout_) = &self.composite[ci];
        let group1 = bind(&self.device, "composite.group1", layout_, &resources);
        {
            let ts = self.timestamp_writes(pass_index);
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("composite"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: ts,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &self.group0, &[]);
            pass.set_bind_group(1, &group1, &[]);
            pass.draw(0..3, 0..1);
        }
        self.last_passes.push(PASS_COMPOSITE);

        self.prev_camera = Some(*camera);
        self.prev_view_proj = view_proj;
        self.frame_index = self.frame_index.wrapping_add(1);
        Ok(())
    }
}
