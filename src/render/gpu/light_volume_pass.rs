//! The light volume on the GPU: the twin of
//! [`crate::render::cpu::light_volume`] (`shaders/light_volume.wgsl`,
//! `shaders/light_volume_build.wgsl`). Built by compute passes of its
//! own, submitted before the frame's, whenever P, the sun or the density
//! changed ([`LightVolumePass::mark_stale`]), not per frame. The last
//! step writes the fluence and its net flux (`light_flux`) into an rgba
//! 3D texture (half floats), which the
//! cloud pass reads with one filtered fetch per lit sample (bind group
//! 2): reading the buffer's eight corners by hand made the pass 37 %
//! slower on lavapipe. It exists only with multiple scattering on
//! (`render.octaves > 0`).

use bytemuck::{Pod, Zeroable};

use super::bind::{self, compute_entry};
use super::context::{GpuContext, GpuError};
use super::shaders;
use crate::render::cpu::density::DensityParams;
use crate::render::cpu::light_volume::{DiffusionGrid, LIGHT_SWEEPS};

/// The build's name (its compute pass's label).
pub const PASS_LIGHT_VOLUME: &str = "light_volume";

// Keep in sync with shaders/light_volume.wgsl: DiffusionGrid.
/// The grid as WGSL reads it.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct DiffusionGridUniforms {
    /// nx, ny, nz, nx · nz.
    pub cells: [u32; 4],
    /// The cells' sides (m), the band's bottom (m).
    pub cell_m: [f32; 4],
}

const _: () = assert!(size_of::<DiffusionGridUniforms>() == 32);

impl From<&DiffusionGrid> for DiffusionGridUniforms {
    fn from(g: &DiffusionGrid) -> Self {
        Self {
            cells: [g.cells.x, g.cells.y, g.cells.z, g.cells.x * g.cells.z],
            cell_m: [g.cell_m.x, g.cell_m.y, g.cell_m.z, g.bottom_m],
        }
    }
}

/// The fluence texture's format: filterable, and writable by a compute
/// pass without extra features.
const FLUENCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The stride of `light_step`'s entries (the dynamic offsets' alignment).
const STEP_STRIDE: u64 = 256;
/// Invocations per workgroup (`@workgroup_size(64)`, `LIGHT_WORKGROUP`).
pub const LIGHT_WORKGROUP: u32 = 64;
/// Workgroups per row of a folded dispatch (`light_invocation` in WGSL).
const ROW: u32 = 4096;

/// The workgroups of a dispatch over `n` invocations, folded into rows of
/// [`ROW`] past that many.
fn workgroups(n: u32) -> (u32, u32) {
    let groups = n.div_ceil(LIGHT_WORKGROUP);
    if groups <= ROW {
        (groups.max(1), 1)
    } else {
        (ROW, groups.div_ceil(ROW))
    }
}

struct Pipelines {
    cell_extinction: wgpu::ComputePipeline,
    sun_depth_layer: wgpu::ComputePipeline,
    relax: wgpu::ComputePipeline,
    fluence_texture: wgpu::ComputePipeline,
}

/// The light volume's buffers, its build and what the cloud pass binds.
pub struct LightVolumePass {
    pub grid: DiffusionGrid,
    build_layout: wgpu::BindGroupLayout,
    build_group: wgpu::BindGroup,
    /// Group 2 of the cloud pass: the fluence texture and its sampler.
    pub read_layout: wgpu::BindGroupLayout,
    pub read_group: wgpu::BindGroup,
    /// The fluence per cell (per unit sun irradiance).
    pub fluence: wgpu::Buffer,
    /// What the cloud pass samples: per cell the fluence (r) and the net
    /// flux (gba), half floats.
    pub texture: wgpu::Texture,
    pipelines: Option<Pipelines>,
    stale: bool,
    builds: u32,
}

fn storage(device: &wgpu::Device, label: &str, cells: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: (cells.max(1) * 4) as u64,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

fn buffer_type(ty: wgpu::BufferBindingType, dynamic: bool) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty,
        has_dynamic_offset: dynamic,
        min_binding_size: None,
    }
}

impl LightVolumePass {
    /// The volume for the density `d` (its grid, [`DiffusionGrid::new`]),
    /// stale until its first [`Self::build_if_stale`].
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, d: &DensityParams) -> Self {
        let grid = DiffusionGrid::new(d);
        let cells = grid.len();
        let grid_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("light_volume.grid"),
            size: size_of::<DiffusionGridUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(
            &grid_buffer,
            0,
            bytemuck::bytes_of(&DiffusionGridUniforms::from(&grid)),
        );
        // One entry per layer (`x`: the layer), then one per colour (`y`).
        let layers = grid.cells.y as u64;
        let steps = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("light_volume.steps"),
            size: (layers + 2) * STEP_STRIDE,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut entries = vec![0u8; ((layers + 2) * STEP_STRIDE) as usize];
        for e in 0..layers + 2 {
            let value: [u32; 4] = if e < layers {
                [e as u32, 0, 0, 0]
            } else {
                [0, (e - layers) as u32, 0, 0]
            };
            let at = (e * STEP_STRIDE) as usize;
            entries[at..at + 16].copy_from_slice(bytemuck::bytes_of(&value));
        }
        queue.write_buffer(&steps, 0, &entries);
        let sigma = storage(device, "light_volume.extinction", cells);
        let tau = storage(device, "light_volume.sun_depth", cells);
        let fluence = storage(device, "light_volume.fluence", cells);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("light_volume.fluence_texture"),
            size: wgpu::Extent3d {
                width: grid.cells.x,
                height: grid.cells.y,
                depth_or_array_layers: grid.cells.z,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: FLUENCE_FORMAT,
            usage: wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let texture_view = bind::view(&texture);
        let rw = wgpu::BufferBindingType::Storage { read_only: false };
        let uniform = wgpu::BufferBindingType::Uniform;
        let build_layout = bind::layout(
            device,
            "light_volume.build",
            &[
                compute_entry(0, buffer_type(uniform, false)),
                compute_entry(1, buffer_type(uniform, true)),
                compute_entry(2, buffer_type(rw, false)),
                compute_entry(3, buffer_type(rw, false)),
                compute_entry(4, buffer_type(rw, false)),
                compute_entry(
                    5,
                    wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: FLUENCE_FORMAT,
                        view_dimension: wgpu::TextureViewDimension::D3,
                    },
                ),
            ],
        );
        let step_binding = wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &steps,
            offset: 0,
            size: wgpu::BufferSize::new(16),
        });
        let build_group = bind::bind(
            device,
            "light_volume.build",
            &build_layout,
            &[
                grid_buffer.as_entire_binding(),
                step_binding,
                sigma.as_entire_binding(),
                tau.as_entire_binding(),
                fluence.as_entire_binding(),
                wgpu::BindingResource::TextureView(&texture_view),
            ],
        );
        // Across the domain the volume repeats; up and down it clamps to
        // the outer cells' centres, as the CPU's `read_cells` does.
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("light_volume.sampler"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let read_layout = bind::layout(
            device,
            "light_volume.read",
            &[
                bind::texture_3d_entry(0, bind::FILTERABLE),
                bind::sampler_entry(1),
            ],
        );
        let read_group = bind::bind(
            device,
            "light_volume.read",
            &read_layout,
            &[
                wgpu::BindingResource::TextureView(&texture_view),
                wgpu::BindingResource::Sampler(&sampler),
            ],
        );
        Self {
            grid,
            build_layout,
            build_group,
            read_layout,
            read_group,
            fluence,
            texture,
            pipelines: None,
            stale: true,
            builds: 0,
        }
    }

    /// The next frame builds the volume anew (P, the sun or the density
    /// changed).
    pub fn mark_stale(&mut self) {
        self.stale = true;
    }

    /// Drops the pipelines (group 0's layout or the constants changed).
    pub fn invalidate(&mut self) {
        self.pipelines = None;
        self.stale = true;
    }

    /// Whether the build's pipelines exist (after the first build).
    pub fn has_pipelines(&self) -> bool {
        self.pipelines.is_some()
    }

    /// The fluence of every cell read back to the CPU, in the CPU's
    /// [`DiffusionGrid::index`] order (waits for the GPU).
    pub fn read_fluence(&self, ctx: &GpuContext) -> Result<Vec<f32>, GpuError> {
        let size = self.fluence.size();
        let readback = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("light_volume.readback"),
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("light_volume.readback"),
            });
        encoder.copy_buffer_to_buffer(&self.fluence, 0, &readback, 0, size);
        ctx.queue.submit([encoder.finish()]);
        let bytes = ctx.map_read(&readback)?;
        let mut values: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
        values.truncate(self.grid.len());
        Ok(values)
    }

    /// The texture the cloud pass samples, read back to the CPU: per cell,
    /// in the CPU's [`DiffusionGrid::index`] order, the fluence and the
    /// net flux (waits for the GPU).
    pub fn read_light(&self, ctx: &GpuContext) -> Result<Vec<[f32; 4]>, GpuError> {
        // The texture's texel (i, j, k) is cell (i, j, k); it reads back
        // k-major (then j, then i), the grid's index is j-major.
        let texels = ctx.read_rgba16f(&self.texture)?;
        let (nx, ny) = (self.grid.cells.x as usize, self.grid.cells.y as usize);
        let mut cells = vec![[0.0; 4]; self.grid.len()];
        for (t, texel) in texels.into_iter().enumerate() {
            let (i, j, k) = (t % nx, (t / nx) % ny, t / (nx * ny));
            cells[self.grid.index(i as i32, j as i32, k as i32)] = texel;
        }
        Ok(cells)
    }

    /// Builds since the pass was made.
    pub fn builds(&self) -> u32 {
        self.builds
    }

    /// Builds the build's pipelines if they do not exist yet (at the first
    /// build, or ahead of it from `CloudRenderer::warm_up`).
    pub fn warm(
        &mut self,
        device: &wgpu::Device,
        group0_layout: &wgpu::BindGroupLayout,
        constants: &[(&str, f64)],
    ) {
        pipelines(
            &mut self.pipelines,
            &self.build_layout,
            device,
            group0_layout,
            constants,
        );
    }

    /// Builds the volume when it is stale: records and submits the
    /// extinction of every cell, the sun's optical depth layer by layer
    /// from the band's top, and [`LIGHT_SWEEPS`] red-black sweeps from
    /// nothing. Reads group 0 (`inputs`, whose frame uniforms must hold
    /// this frame's sun and density: call after writing them).
    pub fn build_if_stale(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        group0_layout: &wgpu::BindGroupLayout,
        group0: &wgpu::BindGroup,
        constants: &[(&str, f64)],
    ) {
        if !self.stale {
            return;
        }
        self.stale = false;
        self.builds += 1;
        let p = pipelines(
            &mut self.pipelines,
            &self.build_layout,
            device,
            group0_layout,
            constants,
        );
        let g = &self.grid;
        let all = workgroups(g.len() as u32);
        let columns = workgroups(g.cells.x * g.cells.z);
        let layers = g.cells.y;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some(PASS_LIGHT_VOLUME),
        });
        encoder.clear_buffer(&self.fluence, 0, None);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(PASS_LIGHT_VOLUME),
                timestamp_writes: None,
            });
            pass.set_bind_group(0, group0, &[]);
            let step = |e: u32| [(e as u64 * STEP_STRIDE) as u32];
            pass.set_pipeline(&p.cell_extinction);
            pass.set_bind_group(1, &self.build_group, &step(0));
            pass.dispatch_workgroups(all.0, all.1, 1);
            pass.set_pipeline(&p.sun_depth_layer);
            for j in (0..layers).rev() {
                pass.set_bind_group(1, &self.build_group, &step(j));
                pass.dispatch_workgroups(columns.0, columns.1, 1);
            }
            pass.set_pipeline(&p.relax);
            for _ in 0..LIGHT_SWEEPS {
                for colour in 0..2 {
                    pass.set_bind_group(1, &self.build_group, &step(layers + colour));
                    pass.dispatch_workgroups(all.0, all.1, 1);
                }
            }
            pass.set_pipeline(&p.fluence_texture);
            pass.set_bind_group(1, &self.build_group, &step(0));
            pass.dispatch_workgroups(all.0, all.1, 1);
        }
        queue.submit([encoder.finish()]);
    }
}

/// The build's pipelines in `slot`, made there first if it is empty.
fn pipelines<'a>(
    slot: &'a mut Option<Pipelines>,
    build_layout: &wgpu::BindGroupLayout,
    device: &wgpu::Device,
    group0_layout: &wgpu::BindGroupLayout,
    constants: &[(&str, f64)],
) -> &'a Pipelines {
    slot.get_or_insert_with(|| {
        let module = bind::module(device, PASS_LIGHT_VOLUME, shaders::light_volume_build());
        let layout =
            bind::pipeline_layout(device, PASS_LIGHT_VOLUME, &[group0_layout, build_layout]);
        let pipeline = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(PASS_LIGHT_VOLUME),
                layout: Some(&layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants,
                    zero_initialize_workgroup_memory: false,
                },
                cache: None,
            })
        };
        Pipelines {
            cell_extinction: pipeline("cell_extinction"),
            sun_depth_layer: pipeline("sun_depth_layer"),
            relax: pipeline("relax"),
            fluence_texture: pipeline("fluence_texture"),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folded_dispatches_cover_every_invocation() {
        for n in [1, 63, 64, 65, 4096 * 64, 4096 * 64 + 1, 1_769_472] {
            let (x, y) = workgroups(n);
            assert!(x <= 65_535 && y <= 65_535);
            // `light_invocation`: id.x + id.y · ROW · 64 reaches n - 1.
            assert!(
                (x * LIGHT_WORKGROUP - 1) + (y - 1) * ROW * LIGHT_WORKGROUP >= n - 1,
                "{n}"
            );
        }
    }
}
