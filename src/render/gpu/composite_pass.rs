//! The `composite` pass: the resolved cloud layer over the sky, the
//! terrain or the application's own colour (where its depth buffer has
//! geometry): tone-mapped into an 8-bit target, linear radiance into a
//! floating-point one.

use super::bind::{self, Recorder, UNFILTERABLE};
use super::inputs::Inputs;
use super::shaders::{self, Background};

/// The pass's name.
pub const PASS_COMPOSITE: &str = "composite";

/// Whether `format` is a floating-point colour format: such a target
/// receives linear radiance, not tone-mapped and encoded pixels.
pub fn is_hdr(format: wgpu::TextureFormat) -> bool {
    matches!(
        format,
        wgpu::TextureFormat::Rgba16Float
            | wgpu::TextureFormat::Rgba32Float
            | wgpu::TextureFormat::Rg11b10Ufloat
    )
}

/// Whether the composite dithers into `format` (`DITHER`): its 8-bit
/// colour formats, as the CPU's `to_srgb8` does.
pub fn dithers(format: wgpu::TextureFormat) -> bool {
    matches!(
        format,
        wgpu::TextureFormat::Rgba8Unorm
            | wgpu::TextureFormat::Rgba8UnormSrgb
            | wgpu::TextureFormat::Bgra8Unorm
            | wgpu::TextureFormat::Bgra8UnormSrgb
    )
}

/// One pipeline per background, built on first use.
#[derive(Default)]
pub struct CompositePass {
    pipelines: Vec<(Background, wgpu::RenderPipeline, wgpu::BindGroupLayout)>,
}

impl CompositePass {
    /// Drops the pipelines (their constants changed).
    pub fn invalidate(&mut self) {
        self.pipelines.clear();
    }

    /// Pipelines built so far.
    pub fn pipeline_count(&self) -> usize {
        self.pipelines.len()
    }

    /// The index of the pipeline for `background` into a target of
    /// `target_format`, built now if it does not exist yet
    /// (`CloudRenderer::warm_up` builds it ahead of the first frame).
    pub fn pipeline(
        &mut self,
        device: &wgpu::Device,
        inputs: &Inputs,
        constants: &[(&str, f64)],
        target_format: wgpu::TextureFormat,
        background: Background,
    ) -> usize {
        let (group0, physical) = (&inputs.layout, inputs.sky.is_some());
        if let Some(i) = self.pipelines.iter().position(|(b, _, _)| *b == background) {
            return i;
        }
        let mut entries = vec![bind::texture_entry(0, UNFILTERABLE)];
        match background {
            Background::Sky => {}
            Background::Terrain => entries.push(bind::texture_entry(1, UNFILTERABLE)),
            Background::ExternalDepth => {
                entries.push(bind::texture_entry(1, wgpu::TextureSampleType::Depth))
            }
        }
        let layout = bind::layout(device, "composite.group1", &entries);
        let module = bind::module(
            device,
            "composite",
            shaders::composite_pass(background, physical),
        );
        let blend = (background == Background::ExternalDepth)
            .then_some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING);
        let encode = if target_format.is_srgb() { 0.0 } else { 1.0 };
        let mut constants = constants.to_vec();
        constants.push(("ENCODE_SRGB", encode));
        constants.push(("TONE_MAP", (!is_hdr(target_format)) as u8 as f64));
        constants.push(("DITHER", dithers(target_format) as u8 as f64));
        let pipeline = bind::full_screen_pipeline(
            device,
            "composite",
            &module,
            &[group0, &layout],
            &[Some(wgpu::ColorTargetState {
                format: target_format,
                blend,
                write_mask: wgpu::ColorWrites::ALL,
            })],
            None,
            &constants,
        );
        self.pipelines.push((background, pipeline, layout));
        self.pipelines.len() - 1
    }

    /// Records the pass: `clouds` over `background` (whose texture, for
    /// the terrain's colour or an external depth buffer, is `behind`) into
    /// `target`.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        device: &wgpu::Device,
        inputs: &Inputs,
        constants: &[(&str, f64)],
        target: &wgpu::TextureView,
        background: Background,
        clouds: &wgpu::TextureView,
        behind: Option<&wgpu::TextureView>,
    ) {
        let i = self.pipeline(
            device,
            inputs,
            constants,
            target.texture().format(),
            background,
        );
        let mut resources = vec![wgpu::BindingResource::TextureView(clouds)];
        resources.extend(behind.map(wgpu::BindingResource::TextureView));
        let (_, pipeline, layout) = &self.pipelines[i];
        let group1 = bind::bind(device, "composite.group1", layout, &resources);
        let mut pass = rec.begin(
            PASS_COMPOSITE,
            &[bind::color_attachment(target, None)],
            None,
        );
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &inputs.group, &[]);
        pass.set_bind_group(1, &group1, &[]);
        pass.draw(0..3, 0..1);
    }
}
