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

/// The most vertices the terrain pass draws a frame. The heightfield's
/// mesh (`size²` cells) is drawn once per tile out to the longest ray,
/// `(2R + 1)²` tiles for `R = ⌈max_distance / extent⌉`: the default
/// terrain (256², 20 km, 40 km) is 9.8 M vertices, but 1 km tiles would
/// make 2.6 G (6561 tiles) and 1 m tiles 2.5·10¹⁵ (6.4·10⁹ tiles, past a
/// `u32`), and lavapipe's frame would never end. Beyond
/// this budget (16.8 M, 1.7 times the default's) each tile's mesh takes
/// every `s`-th height ([`mesh_stride`]).
pub const TERRAIN_VERTEX_BUDGET: u64 = 16 << 20;

/// The most tiles the terrain reaches out in each direction
/// (`render.terrain.extent_m` ≥ `max_distance_m / TERRAIN_REACH_MAX`,
/// checked with the scene): one quad per tile then stays within
/// [`TERRAIN_VERTEX_BUDGET`].
pub const TERRAIN_REACH_MAX: u32 = 512;

/// The tiles out from the camera's in each direction that rays of
/// `max_distance_m` reach over tiles of `extent_m`.
pub fn terrain_reach(max_distance_m: f32, extent_m: f32) -> u32 {
    ((max_distance_m / extent_m).ceil() as u32).min(TERRAIN_REACH_MAX)
}

/// Every how many heights the mesh of each of `(2 reach + 1)²` tiles of
/// a `size²` heightfield takes its vertices: 1 (the full mesh) while
/// that stays within [`TERRAIN_VERTEX_BUDGET`], else the least power of
/// two that does (at most `size`, one quad per tile). The fragments are
/// shaded from the full heightfield whatever the stride; only the
/// silhouettes and the depth coarsen.
pub fn mesh_stride(size: u32, reach: u32) -> u32 {
    let tiles = u64::from(2 * reach + 1).pow(2);
    let mut s = 1;
    while s < size && tiles * mesh_vertices(size, s) > TERRAIN_VERTEX_BUDGET {
        s *= 2;
    }
    s.min(size)
}

/// The vertices of one tile's mesh of a `size²` heightfield at `stride`.
pub fn mesh_vertices(size: u32, stride: u32) -> u64 {
    u64::from(size.div_ceil(stride)).pow(2) * 6
}

/// The pipeline, the heights and the pass's targets.
pub struct TerrainPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    group1: wgpu::BindGroup,
    /// The heightfield's side, heights.
    size: u32,
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
            size: n,
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

    /// The mesh's stride for rays of `max_distance_m` ([`mesh_stride`];
    /// the vertex shader reads it from the frame's uniforms).
    pub fn stride(&self, max_distance_m: f32) -> u32 {
        mesh_stride(self.size, terrain_reach(max_distance_m, self.extent_m))
    }

    /// Records the pass: as many tiles of the heightfield around the camera
    /// as `max_distance_m` reaches, each at [`Self::stride`].
    pub fn record(&self, rec: &mut Recorder, inputs: &Inputs, max_distance_m: f32) {
        let (cv, dv) = (bind::view(&self.color), bind::view(&self.depth));
        let reach = terrain_reach(max_distance_m, self.extent_m);
        let instances = (2 * reach + 1).pow(2);
        let vertices = mesh_vertices(self.size, mesh_stride(self.size, reach)) as u32;
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
        pass.draw(0..vertices, 0..instances);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_terrain_keeps_its_full_mesh() {
        // 256², 20 km tiles, 40 km rays: 25 tiles, 9.8 M vertices.
        assert_eq!(mesh_stride(256, terrain_reach(40_000.0, 20_000.0)), 1);
        // A 512² heightfield over the same tiles would be 39 M: every
        // other height.
        assert_eq!(mesh_stride(512, 2), 2);
    }

    #[test]
    fn every_accepted_terrain_stays_within_the_budget() {
        for size in [16, 255, 256, 300, 1024, 2048] {
            for reach in [0, 1, 2, 7, 40, 300, TERRAIN_REACH_MAX] {
                let s = mesh_stride(size, reach);
                let tiles = u64::from(2 * reach + 1).pow(2);
                let v = tiles * mesh_vertices(size, s);
                assert!(v <= TERRAIN_VERTEX_BUDGET, "{size}² x {tiles}: {v}");
                // The least stride that does: half of it would not.
                if s > 1 {
                    assert!(tiles * mesh_vertices(size, s / 2) > TERRAIN_VERTEX_BUDGET);
                }
            }
        }
        // 1 km tiles to 40 km (the hang): every 16th height.
        assert_eq!(mesh_stride(256, terrain_reach(40_000.0, 1_000.0)), 16);
    }
}
