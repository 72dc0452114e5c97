//! The `terrain` pass (only when the scene has terrain): the tiled
//! heightfield mesh, lit and shadowed by the clouds, into an HDR colour
//! target and a depth buffer that the cloud pass marches up to.

use super::bind::{self, Recorder, UNFILTERABLE};
use super::inputs::Inputs;
use super::shaders;
use super::textures::{self, CLOUD_FORMAT, DEPTH_FORMAT};
use crate::render::terrain::Heightfield;

/// The pass's name.
pub const PASS_TERRAIN: &str = "terrain";

/// The pipeline, the heights and the pass's targets.
pub struct TerrainPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    group1: wgpu::BindGroup,
    vertices: u32,
    /// Side of the height texture, m.
    pub extent_m: f32,
    /// The highest point, m.
    pub max_m: f32,
    /// HDR colour (alpha 1 where terrain was drawn).
    pub color: wgpu::Texture,
    pub depth: wgpu::Texture,
}

impl TerrainPass {
    /// The pass for heightfield `h` and a `width x height` target.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        inputs: &Inputs,
        constants: &[(&str, f64)],
        h: &Heightfield,
        (width, height): (u32, u32),
    ) -> Self {
        let layout = bind::layout(
            device,
            "terrain.group1",
            &[bind::texture_entry(0, UNFILTERABLE)],
        );
        let heights = textures::upload_heights(device, queue, h);
        let group1 = bind::bind(
            device,
            "terrain.group1",
            &layout,
            &[wgpu::BindingResource::TextureView(&bind::view(&heights))],
        );
        let n = h.size() as u32;
        let (color, depth) = targets(device, width, height);
        Self {
            pipeline: pipeline(device, inputs, &layout, constants),
            layout,
            group1,
            vertices: n * n * 6,
            extent_m: h.extent_m(),
            max_m: h.max_m(),
            color,
            depth,
        }
    }

    /// Rebuilds the pipeline (the cloud shadows use the shadow-step
    /// constant).
    pub fn rebuild_pipeline(
        &mut self,
        device: &wgpu::Device,
        inputs: &Inputs,
        constants: &[(&str, f64)],
    ) {
        self.pipeline = pipeline(device, inputs, &self.layout, constants);
    }

    /// Recreates the colour and depth targets for a new size.
    pub fn resize(&mut self, device: &wgpu::Device, width: u32, height: u32) {
        (self.color, self.depth) = targets(device, width, height);
    }

    /// Records the pass: as many tiles of the heightfield around the camera
    /// as `max_distance_m` reaches.
    pub fn record(&self, rec: &mut Recorder, inputs: &Inputs, max_distance_m: f32) {
        let (cv, dv) = (bind::view(&self.color), bind::view(&self.depth));
        let reach = (max_distance_m / self.extent_m).ceil() as u32;
        let instances = (2 * reach + 1).pow(2);
        let mut pass = rec.begin(
            PASS_TERRAIN,
            &[bind::color_attachment(&cv, Some(wgpu::Color::TRANSPARENT))],
            Some(wgpu::RenderPassDepthStencilAttachment {
                view: &dv,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
        );
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &inputs.group, &[]);
        pass.set_bind_group(1, &self.group1, &[]);
        pass.draw(0..self.vertices, 0..instances);
    }
}

fn targets(device: &wgpu::Device, width: u32, height: u32) -> (wgpu::Texture, wgpu::Texture) {
    let make = |label, format| {
        textures::create_2d(device, label, width, height, format, textures::TARGET_USAGE)
    };
    (
        make("terrain.color", CLOUD_FORMAT),
        make("terrain.depth", DEPTH_FORMAT),
    )
}

fn pipeline(
    device: &wgpu::Device,
    inputs: &Inputs,
    group1: &wgpu::BindGroupLayout,
    constants: &[(&str, f64)],
) -> wgpu::RenderPipeline {
    let source = shaders::terrain_pass(inputs.sky.is_some());
    let module = bind::module(device, "terrain", source);
    let layout = bind::pipeline_layout(device, "terrain", &[&inputs.layout, group1]);
    let options = || wgpu::PipelineCompilationOptions {
        constants,
        zero_initialize_workgroup_memory: false,
    };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("terrain"),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_terrain"),
            compilation_options: options(),
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
            compilation_options: options(),
            targets: &[Some(CLOUD_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}
