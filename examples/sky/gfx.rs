//! The GPU side of the demo: the window's surface, the device (a
//! `GpuContext` on the adapter that can present to it), the cloud renderer,
//! egui's renderer and the timestamp queries.

use std::sync::Arc;

use anyhow::{Context, Result, anyhow};
use cumulus::render::gpu::context::adapter_preference;
use cumulus::render::gpu::requirements::check_adapter;
use cumulus::render::gpu::{CloudRenderer, FrameUse, GpuContext, GpuSettings, RenderError, is_hdr};
use winit::window::Window;

use crate::world::World;

/// What to install when no adapter can draw to the window.
const NO_ADAPTER: &str = "Install a Vulkan driver (on Debian/Ubuntu, software Vulkan: `sudo apt-get install mesa-vulkan-drivers`), or use `cumulus render --backend cpu` for still pictures";

/// The GPU side: surface, device, the cloud renderer and egui's renderer.
pub struct Gfx {
    pub surface: wgpu::Surface<'static>,
    pub ctx: GpuContext,
    pub config: wgpu::SurfaceConfiguration,
    pub clouds: CloudRenderer,
    pub egui: egui_wgpu::Renderer,
    /// Timestamp queries of the renderer's passes (query set, resolve
    /// buffer, read buffer), when supported.
    pub timestamps: Option<(wgpu::QuerySet, wgpu::Buffer, wgpu::Buffer)>,
    pub period_ns: f64,
    pub description: String,
}

/// The cloud renderer's settings for the world's scene.
pub fn settings_of(world: &World) -> GpuSettings {
    let r = &world.scene.render;
    r.gpu_settings(world.band, world.scene.physics.domain_size_m)
}

impl Gfx {
    /// Finds an adapter that can present to `window` (`WGPU_BACKEND`
    /// narrows the search), configures the surface (sRGB when offered) and
    /// builds the renderers for `world`.
    pub fn new(window: Arc<Window>, world: &World) -> Result<Self> {
        let backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::all());
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = backends;
        let instance = wgpu::Instance::new(desc);
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| anyhow!("no GPU adapter can draw to this window ({e}). {NO_ADAPTER}"))?;
        // The best adapter that presents to the window and can draw the
        // clouds; failing that, the best that presents, which
        // `from_adapter` refuses naming what it lacks.
        let adapter = pollster::block_on(instance.enumerate_adapters(backends))
            .into_iter()
            .filter(|a| a.is_surface_supported(&surface))
            .min_by_key(|a| {
                (
                    check_adapter(a).is_err(),
                    adapter_preference(a.get_info().device_type),
                )
            })
            .ok_or_else(|| anyhow!("no GPU adapter can draw to this window. {NO_ADAPTER}"))?;
        let ctx = GpuContext::from_adapter(&adapter).context("requesting a device")?;
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, size.width.max(1), size.height.max(1))
            .ok_or_else(|| anyhow!("the adapter cannot present to this window"))?;
        let caps = surface.get_capabilities(&adapter);
        // An sRGB format, else any 8-bit one: a floating-point surface
        // would get the renderer's linear radiance, not a tone-mapped picture.
        let pick = caps
            .formats
            .iter()
            .find(|f| f.is_srgb())
            .or_else(|| caps.formats.iter().find(|f| !is_hdr(**f)));
        if let Some(f) = pick {
            config.format = *f;
        }
        if caps.usages.contains(wgpu::TextureUsages::COPY_SRC) {
            config.usage |= wgpu::TextureUsages::COPY_SRC;
        }
        if size.width > 0 && size.height > 0 {
            surface.configure(&ctx.device, &config);
        }
        let clouds = cloud_renderer(&ctx, config.format, world, (size.width, size.height))
            .context("the cloud renderer on this device")?;
        let timestamps = ctx.timestamps.then(|| timestamp_queries(&ctx.device));
        let egui = egui_wgpu::Renderer::new(
            &ctx.device,
            config.format,
            egui_wgpu::RendererOptions::default(),
        );
        let info = adapter.get_info();
        Ok(Self {
            period_ns: ctx.queue.get_timestamp_period() as f64,
            surface,
            ctx,
            config,
            clouds,
            egui,
            timestamps,
            description: format!("{} ({:?})", info.name, info.backend),
        })
    }

    /// A new cloud renderer for a newly loaded world, at the same size
    /// (the old one stays if the device refuses the new one).
    pub fn rebuild_clouds(&mut self, world: &World) -> Result<(), RenderError> {
        let size = self.clouds.size();
        self.clouds = cloud_renderer(&self.ctx, self.config.format, world, size)?;
        Ok(())
    }
}

fn cloud_renderer(
    ctx: &GpuContext,
    format: wgpu::TextureFormat,
    world: &World,
    (width, height): (u32, u32),
) -> Result<CloudRenderer, RenderError> {
    let mut clouds = CloudRenderer::new(
        &ctx.device,
        &ctx.queue,
        format,
        &settings_of(world),
        &world.cloud_map,
        world.terrain.as_ref(),
    )?;
    clouds.update_field(&ctx.queue, &world.field);
    // The clouds change as the demo runs: the light volume follows them a
    // batch of photons a frame instead of a whole build per change.
    clouds.set_progressive_light(true);
    clouds.resize(width, height);
    // The window's first frame would otherwise compile them.
    clouds.warm_up(&[FrameUse::Render { depth: false }]);
    Ok(clouds)
}

/// Eight timestamp queries (two per pass) and their resolve and read
/// buffers.
fn timestamp_queries(device: &wgpu::Device) -> (wgpu::QuerySet, wgpu::Buffer, wgpu::Buffer) {
    let q = device.create_query_set(&wgpu::QuerySetDescriptor {
        label: Some("sky.timestamps"),
        ty: wgpu::QueryType::Timestamp,
        count: 8,
    });
    let buf = |label, usage| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: 64,
            usage,
            mapped_at_creation: false,
        })
    };
    (
        q,
        buf(
            "sky.timestamps.resolve",
            wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        ),
        buf(
            "sky.timestamps.read",
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        ),
    )
}
