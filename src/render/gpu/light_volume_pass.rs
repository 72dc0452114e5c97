//! The light volume on the GPU: the twin of
//! [`crate::render::cpu::light_volume`] and
//! [`crate::render::cpu::light_transport`] (`shaders/light_grid.wgsl`,
//! `shaders/light_transport.wgsl`, `shaders/light_volume_build.wgsl`).
//! Built by compute passes of its own, submitted before the frame's,
//! whenever P, the sun or the density changed
//! ([`LightVolumePass::mark_stale`]), not per frame: the cells'
//! extinction, then the photons in batches (each photon one invocation,
//! drawing the CPU's random numbers), each batch's tracks added to
//! fixed-point cells with atomics and folded into float sums, and last
//! the sums through the phase into three rgba 3D textures (half floats),
//! which the cloud pass reads with three filtered fetches per lit sample
//! (bind group 2). It exists only with multiple scattering on
//! (`render.octaves > 0`) and photons to trace (`render.light_photons`).
//!
//! Over 600 lines by one: the pass, its buffers, its bind groups and its
//! readbacks for the tests are one owner's; the progressive build is
//! already apart (`light_volume_progressive.rs`).

use bytemuck::{Pod, Zeroable};

use super::bind::{self, compute_entry};
use super::context::{GpuContext, GpuError};
use super::shaders;
use crate::render::cpu::density::DensityParams;
use crate::render::cpu::light_grid::{LightVolumeGrid, light_photons};

/// The build's name (its compute pass's label).
pub const PASS_LIGHT_VOLUME: &str = "light_volume";

// Keep in sync with shaders/light_grid.wgsl: LightVolumeGrid.
/// The grid as WGSL reads it.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct LightVolumeGridUniforms {
    /// nx, ny, nz, nx · nz.
    pub cells: [u32; 4],
    /// The cells' sides (m), the band's bottom (m).
    pub cell_m: [f32; 4],
}

const _: () = assert!(size_of::<LightVolumeGridUniforms>() == 32);

impl From<&LightVolumeGrid> for LightVolumeGridUniforms {
    fn from(g: &LightVolumeGrid) -> Self {
        Self {
            cells: [g.cells.x, g.cells.y, g.cells.z, g.cells.x * g.cells.z],
            cell_m: [g.cell_m.x, g.cell_m.y, g.cell_m.z, g.bottom_m],
        }
    }
}

pub use super::textures::PLANE_FORMAT;

/// The fixed-point cells' unit, m of track (`TRACK_UNIT` in WGSL): a
/// track's length times its harmonic is rounded to it, far below the
/// cells' 40 m.
pub const TRACK_UNIT: f32 = 1.0 / 256.0;
/// Photons per column of cells in one batch: its tracks are folded into
/// the float sums before the next batch, so no cell's 32-bit sum
/// overflows (a column's 24 photons lay at most a few kilometres of
/// track in a cell, 2^31 units are 8,400 km). A progressive build traces
/// one batch a frame: a quarter of the default `render.light_photons`
/// (96), so an application's frame that follows a change of the clouds
/// costs a quarter of a whole build.
pub const BATCH_PER_COLUMN: u32 = 24;

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

/// The batches of `photons`: each batch's first photon and count.
fn batches(photons: u32, batch: u32) -> Vec<(u32, u32)> {
    let batch = batch.max(1);
    (0..photons.div_ceil(batch))
        .map(|b| (b * batch, batch.min(photons - b * batch)))
        .collect()
}

struct Pipelines {
    cell_extinction: wgpu::ComputePipeline,
    trace: wgpu::ComputePipeline,
    fold_tracks: wgpu::ComputePipeline,
    sh_planes: wgpu::ComputePipeline,
}

/// The light volume's buffers, its build and what the cloud pass binds.
pub struct LightVolumePass {
    pub grid: LightVolumeGrid,
    /// Photons per column of cells (`render.light_photons`).
    pub per_column: u32,
    build_layout: wgpu::BindGroupLayout,
    build_group: wgpu::BindGroup,
    /// Group 2 of the cloud pass: the three planes and their sampler.
    pub read_layout: wgpu::BindGroupLayout,
    pub read_group: wgpu::BindGroup,
    /// One batch's fixed-point tracks, nine a cell.
    tracks: wgpu::Buffer,
    /// The tracks of every batch, nine a cell, m.
    pub sums: wgpu::Buffer,
    /// What the cloud pass samples: per cell the radiance coefficients
    /// through the phase (`sh_planes`), half floats.
    pub planes: [wgpu::Texture; 3],
    /// The full build's batches: each one's first photon and count.
    batches: Vec<(u32, u32)>,
    /// `light_step`'s buffer: one entry per batch, then the progressive
    /// frame's.
    steps: wgpu::Buffer,
    /// `light_fold`: what a fold keeps of the sums and gains of a batch.
    fold: wgpu::Buffer,
    /// One batch per frame into a running mean (see
    /// [`Self::set_progressive`]), else whole builds.
    progressive: bool,
    /// Progressive: batches folded since the volume was made (they number
    /// the photons), since the last change, the batch from which that
    /// change's exact mean starts, and the batches still to trace before
    /// the volume rests.
    traced: u32,
    since_change: u32,
    mean_from: u32,
    pending: u32,
    pipelines: Option<Pipelines>,
    stale: bool,
    builds: u32,
}

fn storage(device: &wgpu::Device, label: &str, words: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: (words.max(1) * 4) as u64,
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
    /// The volume for the density `d` (its grid, [`LightVolumeGrid::new`])
    /// with `per_column` photons a column, stale until its first
    /// [`Self::build_if_stale`].
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        d: &DensityParams,
        per_column: u32,
    ) -> Self {
        let grid = LightVolumeGrid::new(d);
        let cells = grid.len();
        let grid_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("light_volume.grid"),
            size: size_of::<LightVolumeGridUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(
            &grid_buffer,
            0,
            bytemuck::bytes_of(&LightVolumeGridUniforms::from(&grid)),
        );
        let photons = light_photons(&grid, per_column);
        let columns = grid.cells.x * grid.cells.z;
        let batches = batches(photons, columns.saturating_mul(BATCH_PER_COLUMN));
        // One entry per batch: its first photon, its count, the total; the
        // last entry is the progressive frame's, written per frame.
        let entries_count = batches.len() as u64 + 1;
        let steps = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("light_volume.steps"),
            size: entries_count * STEP_STRIDE,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut entries = vec![0u8; (entries_count * STEP_STRIDE) as usize];
        for (e, (first, count)) in batches.iter().enumerate() {
            let value: [u32; 4] = [*first, *count, photons, 0];
            let at = e * STEP_STRIDE as usize;
            entries[at..at + 16].copy_from_slice(bytemuck::bytes_of(&value));
        }
        queue.write_buffer(&steps, 0, &entries);
        let fold = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("light_volume.fold"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        // The mean extinction, then the sun's (`cell_extinctions`).
        let sigma = storage(device, "light_volume.extinction", 2 * cells);
        let tracks = storage(device, "light_volume.tracks", 9 * cells);
        let sums = storage(device, "light_volume.sums", 9 * cells);
        let plane = |k: usize| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(
                    [
                        "light_volume.plane0",
                        "light_volume.plane1",
                        "light_volume.plane2",
                    ][k],
                ),
                size: wgpu::Extent3d {
                    width: grid.cells.x,
                    height: grid.cells.y,
                    depth_or_array_layers: grid.cells.z,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format: PLANE_FORMAT,
                usage: wgpu::TextureUsages::STORAGE_BINDING
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let planes = [plane(0), plane(1), plane(2)];
        let views = planes.each_ref().map(bind::view);
        let rw = wgpu::BufferBindingType::Storage { read_only: false };
        let uniform = wgpu::BufferBindingType::Uniform;
        let plane_entry = |binding: u32| {
            compute_entry(
                binding,
                wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: PLANE_FORMAT,
                    view_dimension: wgpu::TextureViewDimension::D3,
                },
            )
        };
        let build_layout = bind::layout(
            device,
            "light_volume.build",
            &[
                compute_entry(0, buffer_type(uniform, false)),
                compute_entry(1, buffer_type(uniform, true)),
                compute_entry(2, buffer_type(rw, false)),
                compute_entry(3, buffer_type(rw, false)),
                compute_entry(4, buffer_type(rw, false)),
                plane_entry(5),
                plane_entry(6),
                plane_entry(7),
                compute_entry(8, buffer_type(uniform, false)),
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
                tracks.as_entire_binding(),
                sums.as_entire_binding(),
                wgpu::BindingResource::TextureView(&views[0]),
                wgpu::BindingResource::TextureView(&views[1]),
                wgpu::BindingResource::TextureView(&views[2]),
                fold.as_entire_binding(),
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
                bind::texture_3d_entry(1, bind::FILTERABLE),
                bind::texture_3d_entry(2, bind::FILTERABLE),
                bind::sampler_entry(3),
            ],
        );
        let read_group = bind::bind(
            device,
            "light_volume.read",
            &read_layout,
            &[
                wgpu::BindingResource::TextureView(&views[0]),
                wgpu::BindingResource::TextureView(&views[1]),
                wgpu::BindingResource::TextureView(&views[2]),
                wgpu::BindingResource::Sampler(&sampler),
            ],
        );
        Self {
            grid,
            per_column,
            build_layout,
            build_group,
            read_layout,
            read_group,
            tracks,
            sums,
            planes,
            batches,
            steps,
            fold,
            progressive: false,
            traced: 0,
            since_change: 0,
            mean_from: 0,
            pending: 0,
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

    /// Progressive building, for an interactive frame loop: each frame
    /// whose volume is stale or still settling traces one batch
    /// ([`BATCH_PER_COLUMN`] photons a column; a full count is `window`
    /// batches). A new volume is the mean of its batches so far. After a
    /// change of the clouds or the sun, the next `window` batches follow
    /// it as a running mean (the light lags changing clouds by about that
    /// many frames) and, if nothing changes again, the `window` after
    /// them make the exact mean of the new light alone; then it rests.
    /// Off (the default): a stale volume is built whole before the frame
    /// (stills, tests, benchmarks). Switching starts afresh.
    pub fn set_progressive(&mut self, on: bool) {
        if self.progressive != on {
            self.progressive = on;
            self.traced = 0;
            self.since_change = 0;
            self.mean_from = 0;
            self.pending = 0;
            self.stale = true;
        }
    }

    /// The batches a full count of photons takes.
    fn batch_count(&self) -> u32 {
        self.batches.len() as u32
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

    /// Every cell's nine track sums read back to the CPU, as radiance
    /// coefficients per unit irradiance under the sun `sun_dir` (the
    /// CPU's [`crate::render::cpu::light_volume::LightVolume::sh`]), in
    /// the CPU's [`LightVolumeGrid::index`] order (waits for the GPU).
    pub fn read_sh(
        &self,
        ctx: &GpuContext,
        sun_dir: glam::Vec3,
    ) -> Result<Vec<[f32; 9]>, GpuError> {
        let size = self.sums.size();
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
        encoder.copy_buffer_to_buffer(&self.sums, 0, &readback, 0, size);
        ctx.queue.submit([encoder.finish()]);
        let bytes = ctx.map_read(&readback)?;
        let values: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
        let scale = crate::render::cpu::light_transport::transport_scale(
            &self.grid,
            sun_dir,
            light_photons(&self.grid, self.per_column),
        );
        Ok(values
            .chunks_exact(9)
            .take(self.grid.len())
            .map(|c| std::array::from_fn(|k| c[k] * scale))
            .collect())
    }

    /// The three planes the cloud pass samples, read back to the CPU: per
    /// cell, in the CPU's [`LightVolumeGrid::index`] order (waits for the
    /// GPU).
    pub fn read_planes(&self, ctx: &GpuContext) -> Result<[Vec<[f32; 4]>; 3], GpuError> {
        let read = |t: &wgpu::Texture| -> Result<Vec<[f32; 4]>, GpuError> {
            // The texture's texel (i, j, k) is cell (i, j, k); it reads
            // back k-major (then j, then i), the grid's index is j-major.
            let texels = ctx.read_rgba16f(t)?;
            let (nx, ny) = (self.grid.cells.x as usize, self.grid.cells.y as usize);
            let mut cells = vec![[0.0; 4]; self.grid.len()];
            for (t, texel) in texels.into_iter().enumerate() {
                let (i, j, k) = (t % nx, (t / nx) % ny, t / (nx * ny));
                cells[self.grid.index(i as i32, j as i32, k as i32)] = texel;
            }
            Ok(cells)
        };
        Ok([
            read(&self.planes[0])?,
            read(&self.planes[1])?,
            read(&self.planes[2])?,
        ])
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
    /// extinction of every cell, the photons batch by batch (each
    /// batch's fixed-point tracks folded into the sums), and the planes.
    /// Reads group 0 (`inputs`, whose frame uniforms must hold this
    /// frame's sun and density: call after writing them).
    pub fn build_if_stale(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        group0_layout: &wgpu::BindGroupLayout,
        group0: &wgpu::BindGroup,
        constants: &[(&str, f64)],
    ) {
        if self.progressive {
            self.build_progressively(device, queue, group0_layout, group0, constants);
            return;
        }
        if !self.stale {
            return;
        }
        self.stale = false;
        self.builds += 1;
        queue.write_buffer(
            &self.fold,
            0,
            bytemuck::cast_slice(&[1.0f32, 1.0, 0.0, 0.0]),
        );
        let batches: Vec<(u32, u32)> = (0..self.batches.len())
            .map(|e| ((e as u64 * STEP_STRIDE) as u32, self.batches[e].1))
            .collect();
        self.record(
            device,
            queue,
            (group0_layout, group0),
            constants,
            (true, true),
            &batches,
        );
    }

    /// Records and submits a build: with `clear`, the tracks and sums
    /// cleared, with `extinction`, the cells' extinction anew; then each
    /// of `batches` (its `light_step` entry's offset and its photons)
    /// traced and folded; last the planes.
    fn record(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (group0_layout, group0): (&wgpu::BindGroupLayout, &wgpu::BindGroup),
        constants: &[(&str, f64)],
        (clear, extinction): (bool, bool),
        batches: &[(u32, u32)],
    ) {
        let p = pipelines(
            &mut self.pipelines,
            &self.build_layout,
            device,
            group0_layout,
            constants,
        );
        let g = &self.grid;
        let all = workgroups(g.len() as u32);
        let words = workgroups(9 * g.len() as u32);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some(PASS_LIGHT_VOLUME),
        });
        if clear {
            encoder.clear_buffer(&self.tracks, 0, None);
            encoder.clear_buffer(&self.sums, 0, None);
        }
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(PASS_LIGHT_VOLUME),
                timestamp_writes: None,
            });
            pass.set_bind_group(0, group0, &[]);
            // Every entry holds the whole count (`z`), which the
            // extinction ignores and the planes read.
            let first = batches.first().map_or(0, |b| b.0);
            pass.set_bind_group(1, &self.build_group, &[first]);
            if extinction {
                pass.set_pipeline(&p.cell_extinction);
                pass.dispatch_workgroups(all.0, all.1, 1);
            }
            for &(offset, count) in batches {
                let photons = workgroups(count);
                pass.set_pipeline(&p.trace);
                pass.set_bind_group(1, &self.build_group, &[offset]);
                pass.dispatch_workgroups(photons.0, photons.1, 1);
                pass.set_pipeline(&p.fold_tracks);
                pass.dispatch_workgroups(words.0, words.1, 1);
            }
            pass.set_pipeline(&p.sh_planes);
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
            trace: pipeline("trace"),
            fold_tracks: pipeline("fold_tracks"),
            sh_planes: pipeline("sh_planes"),
        }
    })
}

#[path = "light_volume_progressive.rs"]
mod progressive;

#[cfg(test)]
#[path = "light_volume_pass_tests.rs"]
mod tests;
