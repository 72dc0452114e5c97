//! The `clouds` pass: full-screen, it marches the band segment of each
//! ray, up to the depth (the terrain's or the application's) when there is
//! one, into the cloud layer (premultiplied radiance, opacity) and, with
//! TSAA, the cloud distance the reprojection needs. With the light volume
//! (multiple scattering on) it reads its three planes as bind group 2.

use super::bind::{self, Recorder};
use super::inputs::Inputs;
use super::shaders;
use super::textures::{self, CLOUD_FORMAT, DISTANCE_FORMAT};

/// The pass's name.
pub const PASS_CLOUDS: &str = "clouds";

/// The pipelines (built on first use) and the cloud layer.
pub struct CloudPass {
    /// Without and with a depth input (`+ 1`), without and with the light
    /// volume (`+ 2`).
    pipelines: [Option<wgpu::RenderPipeline>; 4],
    depth_layout: wgpu::BindGroupLayout,
    no_depth_layout: wgpu::BindGroupLayout,
    no_depth: wgpu::BindGroup,
    /// The cloud layer of the last frame, at the renderer's size.
    pub layer: wgpu::Texture,
}

impl CloudPass {
    /// The pass for a `width x height` target.
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let no_depth_layout = bind::layout(device, "clouds.no_depth", &[]);
        Self {
            pipelines: [None, None, None, None],
            depth_layout: bind::layout(
                device,
                "clouds.depth",
                &[bind::texture_entry(0, wgpu::TextureSampleType::Depth)],
            ),
            no_depth: bind::bind(device, "clouds.no_depth", &no_depth_layout, &[]),
            no_depth_layout,
            layer: layer(device, width, height),
        }
    }

    /// Recreates the cloud layer for a new size.
    pub fn resize(&mut self, device: &wgpu::Device, width: u32, height: u32) {
        self.layer = layer(device, width, height);
    }

    /// Drops the pipelines (their constants or outputs changed).
    pub fn invalidate(&mut self) {
        self.pipelines = [None, None, None, None];
    }

    /// Pipelines built so far.
    pub fn pipeline_count(&self) -> usize {
        self.pipelines.iter().flatten().count()
    }

    /// The pipeline for a frame with or without `depth` and `light`,
    /// built now if it does not exist yet (`CloudRenderer::warm_up` builds
    /// it ahead of the first frame).
    pub fn pipeline(
        &mut self,
        device: &wgpu::Device,
        inputs: &Inputs,
        constants: &[(&str, f64)],
        depth: bool,
        tsaa: bool,
        light: Option<&wgpu::BindGroupLayout>,
    ) -> &wgpu::RenderPipeline {
        let (group0, physical) = (&inputs.layout, inputs.sky.is_some());
        let (depth_layout, no_depth_layout) = (&self.depth_layout, &self.no_depth_layout);
        let slot = depth as usize + 2 * light.is_some() as usize;
        self.pipelines[slot].get_or_insert_with(|| {
            let source = shaders::cloud_pass(depth, tsaa, physical, light.is_some());
            let module = bind::module(device, "clouds", source);
            let group1 = if depth { depth_layout } else { no_depth_layout };
            let mut groups = vec![group0, group1];
            groups.extend(light);
            let mut targets = vec![Some(CLOUD_FORMAT.into())];
            if tsaa {
                targets.push(Some(DISTANCE_FORMAT.into()));
            }
            bind::full_screen_pipeline(
                device, "clouds", &module, &groups, &targets, None, constants,
            )
        })
    }

    /// Records the pass: clouds in front of `depth` (when given) into the
    /// layer, and the cloud distance into `distance` (TSAA only), lit with
    /// the light volume's planes when `light` (its group 2 layout and
    /// group) is given.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        device: &wgpu::Device,
        inputs: &Inputs,
        constants: &[(&str, f64)],
        depth: Option<&wgpu::TextureView>,
        distance: Option<&wgpu::TextureView>,
        light: Option<(&wgpu::BindGroupLayout, &wgpu::BindGroup)>,
    ) -> wgpu::TextureView {
        let depth_group = depth.map(|d| {
            bind::bind(
                device,
                "clouds.depth",
                &self.depth_layout,
                &[wgpu::BindingResource::TextureView(d)],
            )
        });
        let layer_view = bind::view(&self.layer);
        let pipeline = self
            .pipeline(
                device,
                inputs,
                constants,
                depth.is_some(),
                distance.is_some(),
                light.map(|l| l.0),
            )
            .clone();
        let clear = Some(wgpu::Color::TRANSPARENT);
        let mut attachments = vec![bind::color_attachment(&layer_view, clear)];
        if let Some(d) = distance {
            attachments.push(bind::color_attachment(d, clear));
        }
        let mut pass = rec.begin(PASS_CLOUDS, &attachments, None);
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &inputs.group, &[]);
        pass.set_bind_group(1, depth_group.as_ref().unwrap_or(&self.no_depth), &[]);
        if let Some((_, group)) = light {
            pass.set_bind_group(2, group, &[]);
        }
        pass.draw(0..3, 0..1);
        drop(pass);
        layer_view
    }
}

fn layer(device: &wgpu::Device, width: u32, height: u32) -> wgpu::Texture {
    textures::create_2d(
        device,
        "clouds.layer",
        width,
        height,
        CLOUD_FORMAT,
        textures::TARGET_USAGE,
    )
}
