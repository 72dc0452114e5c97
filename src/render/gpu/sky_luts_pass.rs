//! The sky tables of `render::cpu::sky_luts` built on the GPU: four
//! compute passes (`shaders/sky_luts_build.wgsl`) into `Rgba32Float` storage
//! textures of the CPU tables' sizes. The transmittance and
//! multiple-scattering tables are rebuilt only when the [`SkyParams`]
//! change, the sky view only when they or its inputs (the sun's elevation,
//! the camera's altitude) do: the pass keeps the last inputs and skips a
//! build whose inputs are equal. The renderer's passes read the tables
//! under the physical sky (`shaders/sky_physical.wgsl`, bindings 7 to 11
//! of group 0, `inputs`).

use glam::Vec3;

use super::bind::{self, compute_entry};
use super::context::{GpuContext, GpuError};
use super::shaders::sky_luts_pass;
use super::textures::create_2d;
use super::uniforms::{SkyParamsUniforms, SkyViewUniforms};
use crate::render::cpu::sky_luts::{
    Lut2, MULTI_SCATTERING_SIZE, SKY_AMBIENT_SIZE, SKY_VIEW_SIZE, SkyParams, TRANSMITTANCE_SIZE,
    radius_at_altitude,
};

pub use super::textures::LUT_FORMAT;
/// The compute shaders' workgroup side (`@workgroup_size(8, 8)`).
const WORKGROUP: u32 = 8;
/// Byte offset between the tables' resolved timestamp pairs
/// (`wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT`).
const RESOLVE_STRIDE: u64 = 256;

/// One of the three tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SkyTable {
    Transmittance,
    MultiScattering,
    SkyView,
    SkyAmbient,
}

impl SkyTable {
    /// The four, in build order (the sky ambient is the sky view's mean,
    /// built with it).
    pub const ALL: [SkyTable; 4] = [
        SkyTable::Transmittance,
        SkyTable::MultiScattering,
        SkyTable::SkyView,
        SkyTable::SkyAmbient,
    ];

    /// Its label (texture, pipeline, bind group, compute pass).
    pub fn label(self) -> &'static str {
        match self {
            SkyTable::Transmittance => "sky_luts.transmittance",
            SkyTable::MultiScattering => "sky_luts.multi_scattering",
            SkyTable::SkyView => "sky_luts.sky_view",
            SkyTable::SkyAmbient => "sky_luts.sky_ambient",
        }
    }

    /// Its size, texels (the CPU table's).
    pub fn size(self) -> (u32, u32) {
        match self {
            SkyTable::Transmittance => TRANSMITTANCE_SIZE,
            SkyTable::MultiScattering => MULTI_SCATTERING_SIZE,
            SkyTable::SkyView => SKY_VIEW_SIZE,
            SkyTable::SkyAmbient => SKY_AMBIENT_SIZE,
        }
    }

    fn entry_point(self) -> &'static str {
        match self {
            SkyTable::Transmittance => "cs_transmittance",
            SkyTable::MultiScattering => "cs_multi_scattering",
            SkyTable::SkyView => "cs_sky_view",
            SkyTable::SkyAmbient => "cs_sky_ambient",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// Builds per table: of one call, or in all since creation
/// ([`SkyLutsPass::builds`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TableBuilds {
    pub transmittance: u32,
    pub multi_scattering: u32,
    pub sky_view: u32,
}

impl TableBuilds {
    fn add(&mut self, other: TableBuilds) {
        self.transmittance += other.transmittance;
        self.multi_scattering += other.multi_scattering;
        self.sky_view += other.sky_view;
    }
}

/// The inputs of the last build, compared to skip an unchanged one.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Inputs {
    params: SkyParams,
    view: SkyViewUniforms,
}

/// Timestamp queries of the three passes: pair `k` (queries 2k, 2k + 1)
/// is resolved at `RESOLVE_STRIDE * k`, so a table not rebuilt keeps its
/// last time.
struct Timestamps {
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: wgpu::Buffer,
}

/// The three tables, their compute pipelines and bind groups.
pub struct SkyLutsPass {
    textures: [wgpu::Texture; 4],
    pipelines: [wgpu::ComputePipeline; 4],
    groups: [wgpu::BindGroup; 4],
    params_buffer: wgpu::Buffer,
    view_buffer: wgpu::Buffer,
    timestamps: Option<Timestamps>,
    last: Inputs,
    builds: TableBuilds,
}

fn uniform(binding: u32) -> wgpu::BindGroupLayoutEntry {
    compute_entry(
        binding,
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
    )
}

/// Bindings 0..n of `shaders/sky_luts_build.wgsl`: params, the table written,
/// the transmittance table, the multiple-scattering table, the sky view's
/// inputs. Each pass binds a prefix.
fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 6] {
    let table = |binding| {
        compute_entry(
            binding,
            wgpu::BindingType::Texture {
                sample_type: bind::UNFILTERABLE,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
        )
    };
    [
        uniform(0),
        compute_entry(
            1,
            wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: LUT_FORMAT,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
        ),
        table(2),
        table(3),
        uniform(4),
        table(5),
    ]
}

fn buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage,
        mapped_at_creation: false,
    })
}

/// The sky view's inputs: the camera's clamped radius, the sun's cos zenith.
fn view_inputs(p: &SkyParams, sun_dir: Vec3, camera_altitude_m: f32) -> SkyViewUniforms {
    SkyViewUniforms {
        camera_radius_km: radius_at_altitude(camera_altitude_m, p),
        sun_cos_zenith: sun_dir.y,
    }
}

impl SkyLutsPass {
    /// The textures and pipelines, and the three tables of `params` for the
    /// sun at `sun_dir` and a camera at `camera_altitude_m`.
    pub fn new(
        ctx: &GpuContext,
        params: &SkyParams,
        sun_dir: Vec3,
        camera_altitude_m: f32,
    ) -> Result<Self, GpuError> {
        let mut pass = ctx.checked(|| Self::create(&ctx.device, ctx.timestamps, params))?;
        let view = view_inputs(params, sun_dir, camera_altitude_m);
        ctx.checked(|| pass.full_build(&ctx.device, &ctx.queue, params, view))?;
        Ok(pass)
    }

    /// [`Self::new`] on an application's device (no error scope, no
    /// timestamps): the tables the renderer's passes read under the
    /// physical sky, built now.
    pub fn with_device(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        params: &SkyParams,
        sun_dir: Vec3,
        camera_altitude_m: f32,
    ) -> Self {
        let mut pass = Self::create(device, false, params);
        let view = view_inputs(params, sun_dir, camera_altitude_m);
        pass.full_build(device, queue, params, view);
        pass
    }

    fn create(device: &wgpu::Device, timestamps: bool, params: &SkyParams) -> Self {
        let uniform_usage = wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST;
        let params_size = size_of::<SkyParamsUniforms>() as u64;
        let params_buffer = buffer(device, "sky_luts.params", params_size, uniform_usage);
        let view_size = size_of::<SkyViewUniforms>() as u64;
        let view_buffer = buffer(device, "sky_luts.view", view_size, uniform_usage);
        let textures = SkyTable::ALL.map(|t| {
            let usage = wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC;
            create_2d(device, t.label(), t.size().0, t.size().1, LUT_FORMAT, usage)
        });
        let module = bind::module(device, "sky_luts", sky_luts_pass());
        let entries = layout_entries();
        let views = textures.each_ref().map(bind::view);
        let pipelines_and_groups = SkyTable::ALL.map(|t| {
            let bindings = [2, 3, 5, 6][t.index()];
            let layout = bind::layout(device, t.label(), &entries[..bindings]);
            let pipeline_layout = bind::pipeline_layout(device, t.label(), &[&layout]);
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(t.label()),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(t.entry_point()),
                compilation_options: Default::default(),
                cache: None,
            });
            let resources = [
                params_buffer.as_entire_binding(),
                wgpu::BindingResource::TextureView(&views[t.index()]),
                wgpu::BindingResource::TextureView(&views[0]),
                wgpu::BindingResource::TextureView(&views[1]),
                view_buffer.as_entire_binding(),
                wgpu::BindingResource::TextureView(&views[2]),
            ];
            let group = bind::bind(device, t.label(), &layout, &resources[..bindings]);
            (pipeline, group)
        });
        let [(p0, g0), (p1, g1), (p2, g2), (p3, g3)] = pipelines_and_groups;
        let timestamps = timestamps.then(|| Timestamps {
            queries: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("sky_luts.timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 8,
            }),
            resolve: buffer(
                device,
                "sky_luts.timestamps.resolve",
                4 * RESOLVE_STRIDE,
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            ),
            readback: buffer(
                device,
                "sky_luts.timestamps.readback",
                4 * RESOLVE_STRIDE,
                wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            ),
        });
        Self {
            textures,
            pipelines: [p0, p1, p2, p3],
            groups: [g0, g1, g2, g3],
            params_buffer,
            view_buffer,
            timestamps,
            last: Inputs {
                params: *params,
                view: SkyViewUniforms {
                    camera_radius_km: f32::NAN,
                    sun_cos_zenith: f32::NAN,
                },
            },
            builds: TableBuilds::default(),
        }
    }

    /// Rebuilds what the inputs' change touches: all three tables when
    /// `params` changed, else the sky view when the sun's elevation or
    /// the camera's radius changed (its azimuth is relative to the sun's,
    /// so a sun that only turns rebuilds nothing), else nothing. Returns
    /// the tables it rebuilt.
    pub fn build_all(
        &mut self,
        ctx: &GpuContext,
        params: &SkyParams,
        sun_dir: Vec3,
        camera_altitude_m: f32,
    ) -> Result<TableBuilds, GpuError> {
        ctx.checked(|| self.update(&ctx.device, &ctx.queue, params, sun_dir, camera_altitude_m))
    }

    /// [`Self::build_all`] on an application's device (no error scope).
    pub fn update(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        params: &SkyParams,
        sun_dir: Vec3,
        camera_altitude_m: f32,
    ) -> TableBuilds {
        if *params == self.last.params {
            return self.update_sky_view(device, queue, sun_dir, camera_altitude_m);
        }
        let view = view_inputs(params, sun_dir, camera_altitude_m);
        self.full_build(device, queue, params, view)
    }

    fn full_build(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        params: &SkyParams,
        view: SkyViewUniforms,
    ) -> TableBuilds {
        let block = SkyParamsUniforms::new(params);
        queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&block));
        queue.write_buffer(&self.view_buffer, 0, bytemuck::bytes_of(&view));
        self.encode(device, queue, [true; 4]);
        self.last = Inputs {
            params: *params,
            view,
        };
        self.count(TableBuilds {
            transmittance: 1,
            multi_scattering: 1,
            sky_view: 1,
        })
    }

    /// Rebuilds the sky view for a new sun or camera altitude, unless its
    /// inputs (the sun's cos zenith, the camera's clamped radius) are
    /// those of the last build. Returns the tables it rebuilt.
    pub fn rebuild_sky_view(
        &mut self,
        ctx: &GpuContext,
        sun_dir: Vec3,
        camera_altitude_m: f32,
    ) -> Result<TableBuilds, GpuError> {
        ctx.checked(|| self.update_sky_view(&ctx.device, &ctx.queue, sun_dir, camera_altitude_m))
    }

    /// [`Self::rebuild_sky_view`] on an application's device.
    pub fn update_sky_view(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        sun_dir: Vec3,
        camera_altitude_m: f32,
    ) -> TableBuilds {
        let view = view_inputs(&self.last.params, sun_dir, camera_altitude_m);
        if view == self.last.view {
            return TableBuilds::default();
        }
        queue.write_buffer(&self.view_buffer, 0, bytemuck::bytes_of(&view));
        self.encode(device, queue, [false, false, true, true]);
        self.last.view = view;
        self.count(TableBuilds {
            sky_view: 1,
            ..TableBuilds::default()
        })
    }

    fn count(&mut self, built: TableBuilds) -> TableBuilds {
        self.builds.add(built);
        built
    }

    /// Records and submits the compute passes of the tables in `which`
    /// (in build order: each reads the ones before it), each labelled with
    /// its table and timed when the device has timestamps. Does not wait.
    fn encode(&self, device: &wgpu::Device, queue: &wgpu::Queue, which: [bool; 4]) {
        {
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("sky_luts"),
            });
            for t in SkyTable::ALL.into_iter().filter(|t| which[t.index()]) {
                let k = t.index() as u32;
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(t.label()),
                    timestamp_writes: self.timestamps.as_ref().map(|ts| {
                        wgpu::ComputePassTimestampWrites {
                            query_set: &ts.queries,
                            beginning_of_pass_write_index: Some(2 * k),
                            end_of_pass_write_index: Some(2 * k + 1),
                        }
                    }),
                });
                pass.set_pipeline(&self.pipelines[t.index()]);
                pass.set_bind_group(0, &self.groups[t.index()], &[]);
                let (w, h) = t.size();
                pass.dispatch_workgroups(w.div_ceil(WORKGROUP), h.div_ceil(WORKGROUP), 1);
                drop(pass);
                if let Some(ts) = &self.timestamps {
                    let offset = RESOLVE_STRIDE * k as u64;
                    encoder.resolve_query_set(&ts.queries, 2 * k..2 * k + 2, &ts.resolve, offset);
                }
            }
            if let Some(ts) = &self.timestamps {
                encoder.copy_buffer_to_buffer(&ts.resolve, 0, &ts.readback, 0, 4 * RESOLVE_STRIDE);
            }
            queue.submit([encoder.finish()]);
        }
    }

    /// The uniform block of the params the tables were built with.
    pub fn params_buffer(&self) -> &wgpu::Buffer {
        &self.params_buffer
    }

    /// The params of the last build.
    pub fn params(&self) -> &SkyParams {
        &self.last.params
    }

    /// Builds per table since creation (the first build counts one each).
    pub fn builds(&self) -> TableBuilds {
        self.builds
    }

    /// The table's texture (`Rgba32Float`, read with `textureLoad`).
    pub fn texture(&self, table: SkyTable) -> &wgpu::Texture {
        &self.textures[table.index()]
    }

    /// The table read back to the CPU (waits for the GPU).
    pub fn read_table(&self, ctx: &GpuContext, table: SkyTable) -> Result<Lut2, GpuError> {
        let bytes = ctx.read_texture(self.texture(table), 16)?;
        let (width, height) = table.size();
        Ok(Lut2 {
            width,
            height,
            texels: bytemuck::pod_collect_to_vec(&bytes),
        })
    }

    /// The GPU time (ms) of each table's latest build, in [`SkyTable::ALL`]
    /// order (0 for a table never timed); `None` without timestamp queries.
    /// Waits for the GPU.
    pub fn table_times_ms(&self, ctx: &GpuContext) -> Result<Option<[f64; 4]>, GpuError> {
        let Some(ts) = &self.timestamps else {
            return Ok(None);
        };
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&ctx.map_read(&ts.readback)?);
        let period_ns = ctx.queue.get_timestamp_period() as f64;
        let stride = (RESOLVE_STRIDE / 8) as usize;
        Ok(Some(SkyTable::ALL.map(|t| {
            let (a, b) = (ticks[stride * t.index()], ticks[stride * t.index() + 1]);
            b.saturating_sub(a) as f64 * period_ns * 1e-6
        })))
    }
}
