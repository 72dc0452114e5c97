//! A headless wgpu device for offscreen rendering, tests and benchmarks:
//! adapter selection, validation errors returned (not panics), readback.

use std::sync::mpsc;

use super::requirements::check_adapter;

/// The order adapters are tried in ([`GpuContext::new`], the sky demo):
/// hardware first, software last.
pub fn adapter_preference(t: wgpu::DeviceType) -> u8 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

/// Errors of the headless GPU path.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found. Install a Vulkan driver (on Debian/Ubuntu, software Vulkan: `apt-get install mesa-vulkan-drivers`), or render with --backend cpu"
    )]
    NoAdapter,
    #[error("the GPU adapter {adapter} refused a device: {message}")]
    RequestDevice { adapter: String, message: String },
    #[error("{0}; render with --backend cpu, or use a Vulkan, Metal or D3D12 adapter")]
    Unsupported(#[from] super::requirements::Unsupported),
    #[error("wgpu reported an error: {0}")]
    Wgpu(String),
    #[error("reading the image back from the GPU failed: {0}")]
    Readback(String),
    #[error(transparent)]
    Render(#[from] super::RenderError),
}

/// The iterations after which Mesa's llvmpipe (lavapipe) ends a shader's
/// loops, all of them together (its `LP_MAX_TGSI_LOOP_ITERATIONS`): the
/// likely reason, not proven, why lavapipe's picture departs from the
/// CPU twin's once primary steps times shadow steps pass about 10,000
/// (fair weather at 64x48: 0.1 levels at 512 x 20 and 1024 x 10, 1.3 at
/// 1024 x 20, 11 at distant cloud bases; each lit sample also sums its
/// shadow steps' weights in a loop). docs/gpu.md, "Lavapipe at 1024
/// steps or more".
pub const LLVMPIPE_LOOP_ITERATIONS: u32 = 65_535;

/// A device and queue with what the renderer can use.
pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter_info: wgpu::AdapterInfo,
    /// Whether the device records timestamp queries.
    pub timestamps: bool,
}

impl GpuContext {
    /// The best adapter of `backends` that can draw the clouds
    /// ([`check_adapter`]): a discrete GPU before an integrated one, a
    /// virtual one, then a software one; with timestamp queries when it
    /// has them. `Err(NoAdapter)` when there is no adapter at all, and
    /// `Err(Unsupported)`, naming what the best one lacks, when none can
    /// draw (an OpenGL-only machine). (The binaries pass
    /// `wgpu::Backends::from_env()`, i.e. `WGPU_BACKEND`, when it is set.)
    pub fn new(backends: wgpu::Backends) -> Result<Self, GpuError> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = backends;
        let instance = wgpu::Instance::new(desc);
        let mut adapters = pollster::block_on(instance.enumerate_adapters(backends));
        adapters.sort_by_key(|a| adapter_preference(a.get_info().device_type));
        let mut refused = None;
        for adapter in &adapters {
            match check_adapter(adapter) {
                Ok(()) => return Self::from_adapter(adapter),
                Err(e) => {
                    refused.get_or_insert(e);
                }
            }
        }
        Err(refused.map_or(GpuError::NoAdapter, GpuError::Unsupported))
    }

    /// A device on `adapter`, refused ([`check_adapter`]) when the
    /// adapter cannot draw the clouds.
    pub fn from_adapter(adapter: &wgpu::Adapter) -> Result<Self, GpuError> {
        check_adapter(adapter)?;
        let adapter_info = adapter.get_info();
        let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let required_features = if timestamps {
            wgpu::Features::TIMESTAMP_QUERY
        } else {
            wgpu::Features::empty()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("cumulus"),
            required_features,
            required_limits: super::requirements::limits().using_resolution(adapter.limits()),
            ..Default::default()
        }))
        .map_err(|e| GpuError::RequestDevice {
            adapter: adapter_info.name.clone(),
            message: e.to_string(),
        })?;
        Ok(Self {
            device,
            queue,
            adapter_info,
            timestamps,
        })
    }

    /// Whether the adapter is Mesa's software rasterizer (lavapipe,
    /// "llvmpipe"), which ends every shader loop after
    /// [`LLVMPIPE_LOOP_ITERATIONS`].
    pub fn is_llvmpipe(&self) -> bool {
        self.adapter_info.name.contains("llvmpipe")
    }

    /// "name (backend, driver)".
    pub fn describe(&self) -> String {
        let i = &self.adapter_info;
        format!(
            "{} ({:?}, {} {})",
            i.name, i.backend, i.driver, i.driver_info
        )
    }

    /// Runs `f` inside validation and out-of-memory error scopes and waits
    /// for the GPU: an error wgpu reports comes back as `Err`, not a panic.
    pub fn checked<T>(&self, f: impl FnOnce() -> T) -> Result<T, GpuError> {
        let oom = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let out = f();
        let v = pollster::block_on(validation.pop());
        let o = pollster::block_on(oom.pop());
        match v.or(o) {
            Some(e) => Err(GpuError::Wgpu(e.to_string())),
            None => Ok(out),
        }
    }

    /// Blocks until the GPU is idle.
    pub fn wait(&self) -> Result<(), GpuError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| GpuError::Wgpu(e.to_string()))
    }

    /// Copies `texture` (`bytes_per_texel` per texel, one mip) to the CPU:
    /// tightly packed rows.
    pub fn read_texture(
        &self,
        texture: &wgpu::Texture,
        bytes_per_texel: u32,
    ) -> Result<Vec<u8>, GpuError> {
        let size = texture.size();
        let row = size.width * bytes_per_texel;
        let padded =
            row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let rows = size.height * size.depth_or_array_layers;
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: padded as u64 * rows as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("readback"),
            });
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(size.height),
                },
            },
            size,
        );
        self.queue.submit([encoder.finish()]);
        let data = self.map_read(&buffer)?;
        let mut out = Vec::with_capacity((row * rows) as usize);
        for y in 0..rows as usize {
            let start = y * padded as usize;
            out.extend_from_slice(&data[start..start + row as usize]);
        }
        Ok(out)
    }

    /// Maps a `MAP_READ` buffer, waits for the GPU, and copies it out.
    pub fn map_read(&self, buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
        let slice = buffer.slice(..);
        let (tx, rx) = mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.wait()?;
        rx.recv()
            .map_err(|e| GpuError::Readback(e.to_string()))?
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        let data = slice
            .get_mapped_range()
            .map_err(|e| GpuError::Readback(e.to_string()))?
            .to_vec();
        buffer.unmap();
        Ok(data)
    }

    /// Reads an `Rgba16Float` texture as `f32` RGBA.
    pub fn read_rgba16f(&self, texture: &wgpu::Texture) -> Result<Vec<[f32; 4]>, GpuError> {
        let bytes = self.read_texture(texture, 8)?;
        let halves: &[half::f16] = bytemuck::cast_slice(&bytes);
        Ok(halves
            .chunks_exact(4)
            .map(|c| [c[0].to_f32(), c[1].to_f32(), c[2].to_f32(), c[3].to_f32()])
            .collect())
    }
}
