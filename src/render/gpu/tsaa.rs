//! Temporal anti-aliasing: the camera-cut rule and
//! the `tsaa` pass with its ping-pong history (the shader is
//! `shaders/tsaa.wgsl`); the jitter sequence is `render::sampling`'s.

use super::bind::{self, FILTERABLE, Recorder, UNFILTERABLE};
use super::inputs::Inputs;
use super::shaders;
use super::textures::{self, CLOUD_FORMAT, DISTANCE_FORMAT};
use crate::render::camera::View;

/// The pass's name.
pub const PASS_TSAA: &str = "tsaa";

pub use crate::render::sampling::{JITTER_CYCLE, halton, jitter};

/// The camera moved so far in one frame that the history is useless: more
/// than [`CUT_DISTANCE_M`] or turned by more than [`CUT_ANGLE_DEG`], or the
/// field of view changed by more than a degree.
pub const CUT_DISTANCE_M: f32 = 500.0;
/// See [`CUT_DISTANCE_M`].
pub const CUT_ANGLE_DEG: f32 = 30.0;

/// Whether going from `a` to `b` in one frame is a camera cut.
pub fn is_cut(a: &View, b: &View) -> bool {
    a.eye().distance(b.eye()) > CUT_DISTANCE_M
        || a.forward()
            .dot(b.forward())
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees()
            > CUT_ANGLE_DEG
        || (a.vertical_fov_deg() - b.vertical_fov_deg()).abs() > 1.0
}

/// TSAA settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TsaaSettings {
    /// Weight of the new frame in the history, `(0, 1]` (0.1: about the
    /// last ten frames).
    pub blend: f32,
}

impl Default for TsaaSettings {
    fn default() -> Self {
        Self { blend: 0.1 }
    }
}

/// The TSAA pass: reprojects, clamps and blends the history (a ping-pong
/// pair) with the new cloud layer. It exists only with TSAA on, and with
/// it the cloud distance the cloud pass writes.
pub struct TsaaPass {
    pub settings: TsaaSettings,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    history: [wgpu::Texture; 2],
    /// The cloud distance of each pixel (written by the cloud pass).
    pub distance: wgpu::Texture,
    /// History texture written last.
    latest: usize,
    /// Frames accumulated since the last reset.
    pub frames: u32,
}

impl TsaaPass {
    /// The pass for a `width x height` target, with an empty history.
    pub fn new(
        device: &wgpu::Device,
        group0: &wgpu::BindGroupLayout,
        constants: &[(&str, f64)],
        settings: TsaaSettings,
        (width, height): (u32, u32),
    ) -> Self {
        let layout = bind::layout(
            device,
            "tsaa.group1",
            &[
                bind::texture_entry(0, UNFILTERABLE),
                bind::texture_entry(1, UNFILTERABLE),
                bind::texture_entry(2, FILTERABLE),
                bind::sampler_entry(3),
            ],
        );
        let module = bind::module(device, "tsaa", shaders::tsaa_pass());
        let pipeline = bind::full_screen_pipeline(
            device,
            "tsaa",
            &module,
            &[group0, &layout],
            &[Some(CLOUD_FORMAT.into())],
            None,
            constants,
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("tsaa.clamp_linear"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let (history, distance) = targets(device, width, height);
        Self {
            settings,
            pipeline,
            layout,
            sampler,
            history,
            distance,
            latest: 0,
            frames: 0,
        }
    }

    /// Recreates the history and distance for a new size (an empty
    /// history).
    pub fn resize(&mut self, device: &wgpu::Device, width: u32, height: u32) {
        (self.history, self.distance) = targets(device, width, height);
        self.frames = 0;
    }

    /// The weight of this frame in the history: 1 right after a reset.
    pub fn blend(&self) -> f32 {
        if self.frames == 0 {
            1.0
        } else {
            self.settings.blend.clamp(1e-3, 1.0)
        }
    }

    /// The history texture written last (the resolved clouds).
    pub fn latest(&self) -> &wgpu::Texture {
        &self.history[self.latest]
    }

    /// Records the pass: blends `clouds` into the history and returns the
    /// view of the history written, the frame's resolved cloud layer.
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        device: &wgpu::Device,
        inputs: &Inputs,
        clouds: &wgpu::TextureView,
    ) -> wgpu::TextureView {
        let (read, write) = (self.latest, 1 - self.latest);
        let (rv, wv) = (
            bind::view(&self.history[read]),
            bind::view(&self.history[write]),
        );
        let group1 = bind::bind(
            device,
            "tsaa.group1",
            &self.layout,
            &[
                wgpu::BindingResource::TextureView(clouds),
                wgpu::BindingResource::TextureView(&bind::view(&self.distance)),
                wgpu::BindingResource::TextureView(&rv),
                wgpu::BindingResource::Sampler(&self.sampler),
            ],
        );
        let mut pass = rec.begin(
            PASS_TSAA,
            &[bind::color_attachment(&wv, Some(wgpu::Color::TRANSPARENT))],
            None,
        );
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &inputs.group, &[]);
        pass.set_bind_group(1, &group1, &[]);
        pass.draw(0..3, 0..1);
        drop(pass);
        self.latest = write;
        self.frames += 1;
        wv
    }
}

fn targets(device: &wgpu::Device, width: u32, height: u32) -> ([wgpu::Texture; 2], wgpu::Texture) {
    let make = |label, format| {
        textures::create_2d(device, label, width, height, format, textures::TARGET_USAGE)
    };
    (
        [
            make("tsaa.history0", CLOUD_FORMAT),
            make("tsaa.history1", CLOUD_FORMAT),
        ],
        make("clouds.distance", DISTANCE_FORMAT),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halton_is_the_radical_inverse() {
        assert_eq!(halton(1, 2), 0.5);
        assert_eq!(halton(2, 2), 0.25);
        assert_eq!(halton(3, 2), 0.75);
        assert!((halton(1, 3) - 1.0 / 3.0).abs() < 1e-7);
        assert!((halton(5, 3) - 7.0 / 9.0).abs() < 1e-7);
    }

    #[test]
    fn jitter_averages_to_the_pixel_centre() {
        let (mut sx, mut sy) = (0.0, 0.0);
        for n in 0..JITTER_CYCLE {
            let [x, y, d] = jitter(n);
            assert!(
                (-0.5..0.5).contains(&x) && (-0.5..0.5).contains(&y) && (0.0..1.0).contains(&d)
            );
            sx += x;
            sy += y;
        }
        assert!((sx / 16.0).abs() < 0.05 && (sy / 16.0).abs() < 0.05);
    }
}
