//! The per-primitive renderer: each cloudy parcel a pseudo-spheroid
//! (Jimenez de Parga & Gomez Palomo 2018), lit from a light grid the CPU
//! precomputes (`render::cpu::spheroids`, the twin of every WGSL
//! function). `cumulus bench` compares the cloud map against it, and
//! `[render] renderer = "spheroids"` draws a scene with it. Each pixel
//! tests every spheroid once, so its cost grows with the parcel count,
//! unlike the cloud-map pass. Same lighting, analytic sky and tone map
//! (`shaders/spheroids.wgsl` calls the cloud pass's functions).

use super::bind;
use super::settings::GpuSettings;
use super::standalone::StandalonePass;
use crate::render::camera::Camera;
use crate::render::noise_volume::NoiseVolume;

use crate::render::cpu::sky::sun_direction;
use crate::render::cpu::spheroids::LightGrid;
pub use crate::render::cpu::spheroids::Spheroid;

/// The spheroid renderer: one full-screen pass straight into the target.
pub struct SpheroidRenderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pass: StandalonePass,
    group1_layout: wgpu::BindGroupLayout,
    group1: wgpu::BindGroup,
    buffer: wgpu::Buffer,
    grid_buffer: wgpu::Buffer,
    count: usize,
    grid_words: usize,
    grid_ms: f64,
}

impl SpheroidRenderer {
    /// The renderer for a target of `format` (its settings' quality,
    /// density scale, detail and sun are the cloud-map renderer's), its
    /// land's fields reading `noise` (the cloud map's detail volume).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        format: wgpu::TextureFormat,
        settings: &GpuSettings,
        noise: &NoiseVolume,
    ) -> Self {
        let group1_layout = bind::layout(
            device,
            "spheroids.primitives",
            &[bind::storage_entry(0), bind::storage_entry(1)],
        );
        let pass = StandalonePass::new(
            device,
            queue,
            format,
            settings,
            "spheroids",
            super::shaders::spheroids_pass(),
            "fs_spheroids",
            &group1_layout,
            noise,
        );
        let buffer = Self::storage(device, "spheroids.spheroids", 32);
        let grid_buffer = Self::storage(device, "spheroids.light_grid", 16);
        let group1 = Self::bind_primitives(device, &group1_layout, &buffer, &grid_buffer);
        let mut r = Self {
            device: device.clone(),
            queue: queue.clone(),
            pass,
            group1_layout,
            group1,
            buffer,
            grid_buffer,
            count: 0,
            grid_words: 0,
            grid_ms: 0.0,
        };
        r.update_spheroids(&[]);
        r
    }

    fn storage(device: &wgpu::Device, label: &str, bytes: usize) -> wgpu::Buffer {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes.max(16) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    fn bind_primitives(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        spheroids: &wgpu::Buffer,
        grid: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        bind::bind(
            device,
            "spheroids.primitives",
            layout,
            &[spheroids.as_entire_binding(), grid.as_entire_binding()],
        )
    }

    /// Uploads the spheroids (none: one empty spheroid far below the
    /// ground) and builds and uploads their light grid for the settings'
    /// sun and extinction (timed: [`Self::light_grid_ms`]).
    pub fn update_spheroids(&mut self, spheroids: &[Spheroid]) {
        let empty = [Spheroid {
            centre_radius: [0.0, -1e7, 0.0, 1.0],
            shape: [0.0, 1.0, 0.0, 0.0],
        }];
        let data = if spheroids.is_empty() {
            &empty[..]
        } else {
            spheroids
        };
        let start = std::time::Instant::now();
        let settings = self.pass.settings();
        let sun = sun_direction(settings.sun_elevation_deg, settings.sun_azimuth_deg);
        let grid = LightGrid::build(spheroids, sun, settings.density.extinction_per_m);
        let words = grid.to_words();
        self.grid_ms = start.elapsed().as_secs_f64() * 1e3;
        if data.len() != self.count || words.len() != self.grid_words {
            self.buffer = Self::storage(&self.device, "spheroids.spheroids", size_of_val(data));
            self.grid_buffer = Self::storage(&self.device, "spheroids.light_grid", words.len() * 4);
            self.group1 = Self::bind_primitives(
                &self.device,
                &self.group1_layout,
                &self.buffer,
                &self.grid_buffer,
            );
            self.count = data.len();
            self.grid_words = words.len();
        }
        self.queue
            .write_buffer(&self.buffer, 0, bytemuck::cast_slice(data));
        self.queue
            .write_buffer(&self.grid_buffer, 0, bytemuck::cast_slice(&words));
    }

    /// The CPU time of the last light grid's build, ms (the paper's
    /// illumination pass).
    pub fn light_grid_ms(&self) -> f64 {
        self.grid_ms
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
    /// of the renderer's format and reads it back as 8-bit RGB, row-major
    /// (`Err` for other than an RGBA8 format: read those yourself).
    pub fn read_rgb8(
        &mut self,
        ctx: &super::GpuContext,
        camera: &Camera,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, super::GpuError> {
        self.pass
            .read_rgb8(ctx, camera, width, height, &self.group1)
    }
}
