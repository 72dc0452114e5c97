//! [`CloudRenderer`]: the cloud band ray-cast as a set of wgpu passes, to
//! embed in any wgpu application.
//!
//! Over 600 lines on purpose: this is the renderer's whole public API
//! (each method documented for embedders, with the doc example), while
//! every pass, its pipelines and targets live in their own modules; a
//! split would scatter one type's methods over files.
//!
//! Passes, in order (each exists only when the scene needs it), each in
//! its own module:
//! 1. `terrain` (scene has terrain, `terrain_pass`): the
//!    heightfield mesh into an HDR colour target and a depth buffer.
//! 2. `light_volume` (multiple scattering on, [`super::light_volume_pass`]):
//!    compute passes submitted before the frame's, only when P, the sun or
//!    the density changed (progressively, one batch of photons a frame,
//!    after [`CloudRenderer::set_progressive_light`]): the sunlight
//!    transported through the clouds.
//! 3. `clouds` (`cloud_pass`): full-screen; marches the band
//!    segment of each ray up to the depth (terrain or an external depth
//!    buffer) into the cloud layer (premultiplied radiance, opacity) and,
//!    with TSAA, the cloud distance.
//! 4. `tsaa` (TSAA on, [`super::tsaa`]): reprojects, clamps and blends the
//!    history (ping-pong pair).
//! 5. `composite` (`composite_pass`): clouds over the sky or
//!    terrain, tone-mapped into an 8-bit target (linear radiance into a
//!    floating-point one).
//!
//! Every pass reads bind group 0 (`inputs`). Size-dependent
//! targets belong to the pass that writes them and are remade on resize.

use glam::Mat4;

use super::cloud_pass::CloudPass;
pub use super::cloud_pass::PASS_CLOUDS;
use super::composite_pass::CompositePass;
pub use super::composite_pass::PASS_COMPOSITE;
use super::frame_checks;
pub use super::frame_checks::RenderError;
use super::inputs::Inputs;
use super::light_volume_pass::LightVolumePass;
pub use super::light_volume_pass::PASS_LIGHT_VOLUME;
use super::requirements::check_device;
use super::settings::GpuSettings;
use super::shaders::Background;
use super::sky_luts_pass::{SkyTable, TableBuilds};
pub use super::terrain_pass::PASS_TERRAIN;
use super::terrain_pass::TerrainPass;
/// The format of [`CloudRenderer::render_clouds`]'s texture.
pub use super::textures::CLOUD_FORMAT as CLOUDS_ONLY_FORMAT;
pub use super::tsaa::PASS_TSAA;
use super::tsaa::{TsaaPass, is_cut, jitter};
use super::uniforms::{FrameInputs, FrameUniforms};
use super::{bind, bind::Recorder};
use crate::render::camera::{ToView, View};
use crate::render::cloud_map::CloudMap;
use crate::render::cpu::light_grid::LightVolumeGrid;
use crate::render::soft_field::{SPREAD_M, soft_field};
use crate::render::terrain::Heightfield;
use crate::sim::ProjectedField;

/// How an application draws with a [`CloudRenderer`], for
/// [`CloudRenderer::warm_up`]: each way needs its own pipelines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameUse {
    /// [`CloudRenderer::render`], with or without the application's depth
    /// buffer.
    Render { depth: bool },
    /// [`CloudRenderer::render_clouds`], with or without it.
    CloudsOnly { depth: bool },
}

/// What the composite of [`CloudRenderer::render`] draws the clouds over:
/// the scene's terrain where it has one, else the application's colour
/// where it gives a depth buffer, else the sky.
fn background(terrain: bool, depth: bool) -> Background {
    match (terrain, depth) {
        (true, _) => Background::Terrain,
        (false, true) => Background::ExternalDepth,
        (false, false) => Background::Sky,
    }
}

/// The wgpu cloud renderer. It sees the simulation only through the
/// projected field P ([`CloudRenderer::update_field`]).
///
/// Clouds move only through P: the cloud map is fixed in the world (it
/// tiles the physics domain), and the renderer has no wind or time input.
/// The parcels drift with the wind and rise, fall and die; re-project them
/// ([`crate::sim::Simulation::project_into`]) and call `update_field` each
/// physics step, and the clouds move with them.
///
/// The settings come from a scene's `[render]` section with
/// [`crate::scene::RenderSettings::gpu_settings`]; nothing needs building
/// by hand:
///
/// ```no_run
/// # fn frame(device: &wgpu::Device, queue: &wgpu::Queue, view: &wgpu::TextureView)
/// #     -> Result<(), Box<dyn std::error::Error>> {
/// use cumulus::render::cloud_map::CloudMap;
/// use cumulus::render::gpu::{CloudRenderer, FrameUse};
/// use cumulus::scene::Scene;
/// use cumulus::sim::{ProjectedField, Simulation};
///
/// let scene = Scene::builtin("fair_weather.toml").expect("shipped")?;
/// let atm = scene.atmosphere(None)?;
/// let band = scene.band(&atm);
/// let r = &scene.render;
/// let settings = r.gpu_settings(band, scene.physics.domain_size_m);
/// let cloud_map = CloudMap::generate(&r.cloud_map);
/// let mut clouds = CloudRenderer::new(
///     device,
///     queue,
///     wgpu::TextureFormat::Rgba8UnormSrgb,
///     &settings,
///     &cloud_map,
///     None,
/// )?;
/// clouds.resize(1280, 720);
/// // Compile the pipelines now, not in the first frame.
/// clouds.warm_up(&[FrameUse::Render { depth: false }]);
/// let mut sim = Simulation::new(scene.physics.clone(), atm);
/// // Parcels rise where the cloud map has its clouds.
/// sim.set_spawn_sites(cumulus::prepare::spawn_sites(&cloud_map, scene.physics.domain_size_m));
/// let mut p = ProjectedField::new(128, 128);
/// // Each frame: advance the physics by the frame's own time (a physics
/// // step is `dt_s`, 5 s by default: stepping once a frame would run the
/// // sky 300 times too fast at 60 frames a second), and re-project and
/// // upload P when the sky has moved, e.g. once per physics step (each
/// // upload blurs P on the CPU and rebuilds the light volume).
/// let frame_s = 1.0 / 60.0;
/// sim.advance(frame_s);
/// sim.project_into(&mut p, band);
/// clouds.update_field(queue, &p);
/// let mut encoder = device.create_command_encoder(&Default::default());
/// clouds.render(&mut encoder, view, None, &r.camera())?;
/// queue.submit([encoder.finish()]);
/// # Ok(())
/// # }
/// ```
pub struct CloudRenderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    target_format: wgpu::TextureFormat,
    settings: GpuSettings,
    width: u32,
    height: u32,
    inputs: Inputs,
    terrain: Option<TerrainPass>,
    /// The sunlight scattered more than once through the clouds
    /// (multiple scattering on).
    light: Option<LightVolumePass>,
    /// Whether the light volume is built a batch a frame
    /// ([`Self::set_progressive_light`]).
    progressive_light: bool,
    clouds: CloudPass,
    tsaa: Option<TsaaPass>,
    composite: CompositePass,
    prev_view: Option<View>,
    prev_view_proj: Mat4,
    /// The last P given to [`Self::update_field`], as projected (spread
    /// again when the map extent changes).
    field: Option<ProjectedField>,
    /// That P's covered fraction (the land's light from the clouds,
    /// `Frame.exposure.z`), counted once per update, not per frame.
    cloud_cover: f32,
    frame_index: u32,
    timestamps: Option<wgpu::QuerySet>,
    last_passes: Vec<&'static str>,
}

impl CloudRenderer {
    /// Creates the renderer for a target of `target_format`. The cloud map
    /// is uploaded once; P starts empty (clear sky) until
    /// [`Self::update_field`]. `terrain` builds the terrain pass. `Err`
    /// ([`RenderError::Unsupported`]) names what `device` lacks
    /// ([`super::requirements`]; an application can ask its adapter first
    /// with `requirements::check_adapter`).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        target_format: wgpu::TextureFormat,
        settings: &GpuSettings,
        cloud_map: &CloudMap,
        terrain: Option<&Heightfield>,
    ) -> Result<Self, RenderError> {
        check_device(device)?;
        let sky = settings.sky_params();
        let inputs = Inputs::new(
            device,
            queue,
            cloud_map,
            settings.noise_volume(),
            sky.as_ref(),
            settings.sun_dir(),
        );
        let constants = settings.constants();
        let size = (0, 0);
        Ok(Self {
            terrain: terrain.map(|h| TerrainPass::new(device, queue, &inputs, &constants, h, size)),
            light: settings.light_volume().then(|| {
                LightVolumePass::new(
                    device,
                    queue,
                    &settings.density,
                    settings.quality.light_photons,
                )
            }),
            clouds: CloudPass::new(device, size.0, size.1),
            tsaa: settings
                .tsaa
                .map(|t| TsaaPass::new(device, &inputs.layout, &constants, t, size)),
            composite: CompositePass::default(),
            progressive_light: false,
            inputs,
            device: device.clone(),
            queue: queue.clone(),
            target_format,
            settings: *settings,
            width: size.0,
            height: size.1,
            prev_view: None,
            field: None,
            cloud_cover: 0.0,
            prev_view_proj: Mat4::IDENTITY,
            frame_index: 0,
            timestamps: None,
            last_passes: Vec::new(),
        })
    }

    /// Uploads a new P (after each physics step). P may change size. The
    /// density reads P spread to the clouds' merging scale
    /// ([`crate::render::soft_field`]), made here from `field`.
    pub fn update_field(&mut self, queue: &wgpu::Queue, field: &ProjectedField) {
        let soft = soft_field(field, SPREAD_M, self.settings.density.map_extent_m);
        self.inputs.update_field(&self.device, queue, &soft);
        self.cloud_cover = field.covered_fraction() as f32;
        if let Some(l) = &mut self.light {
            l.mark_stale();
        }
        self.field = Some(field.clone());
    }

    /// Adds, replaces or (with `None`) removes the terrain and its pass.
    pub fn set_terrain(&mut self, terrain: Option<&Heightfield>) {
        let constants = self.settings.constants();
        let size = (self.width, self.height);
        self.terrain = terrain.map(|h| {
            TerrainPass::new(&self.device, &self.queue, &self.inputs, &constants, h, size)
        });
        self.clouds.invalidate();
    }

    /// Replaces the cloud map.
    pub fn update_cloud_map(&mut self, queue: &wgpu::Queue, cloud_map: &CloudMap) {
        self.inputs.update_cloud_map(&self.device, queue, cloud_map);
        if let Some(l) = &mut self.light {
            l.mark_stale();
        }
    }

    /// Changes the settings: pipelines whose constants changed are rebuilt
    /// (on first use), TSAA's pass and textures are created or dropped.
    pub fn set_settings(&mut self, settings: &GpuSettings) {
        let old = std::mem::replace(&mut self.settings, *settings);
        let queue = self.queue.clone();
        // The physical sky's tables: rebuilt when its params change; its
        // bindings added or removed (every pipeline rebuilt) when the model
        // changes.
        let altitude = self.prev_view.map_or(0.0, |v| v.eye().y);
        let layout_changed = self.inputs.set_sky(
            &self.device,
            &queue,
            settings.sky_params().as_ref(),
            settings.sun_dir(),
            altitude,
        );
        let constants_changed = old.constants() != settings.constants() || layout_changed;
        let tsaa_changed = old.tsaa.is_some() != settings.tsaa.is_some();
        if constants_changed || tsaa_changed {
            self.clouds.invalidate();
            self.composite.invalidate();
        }
        let constants = settings.constants();
        if tsaa_changed || (constants_changed && self.tsaa.is_some()) {
            let size = (self.width, self.height);
            self.tsaa = settings
                .tsaa
                .map(|t| TsaaPass::new(&self.device, &self.inputs.layout, &constants, t, size));
        } else if let (Some(t), Some(s)) = (&mut self.tsaa, settings.tsaa) {
            t.settings = s;
        }
        self.inputs
            .set_detail(&self.device, &queue, settings.noise_volume());
        self.set_light(&old, constants_changed);
        if constants_changed && let Some(t) = &mut self.terrain {
            t.rebuild_pipeline(&self.device, &self.inputs, &constants);
        }
        // The spread is in metres: a new map extent spreads P anew.
        if old.density.map_extent_m != settings.density.map_extent_m
            && let Some(f) = self.field.take()
        {
            let queue = self.queue.clone();
            self.update_field(&queue, &f);
        }
    }

    /// Creates, drops or marks stale the light volume after a change of
    /// settings from `old`.
    fn set_light(&mut self, old: &GpuSettings, constants_changed: bool) {
        let s = &self.settings;
        if old.light_volume() != s.light_volume() {
            self.clouds.invalidate();
        }
        let grid = LightVolumeGrid::new(&s.density);
        if !s.light_volume() {
            self.light = None;
        } else if self
            .light
            .as_ref()
            .is_none_or(|l| l.grid != grid || l.per_column != s.quality.light_photons)
        {
            let mut light = LightVolumePass::new(
                &self.device,
                &self.queue,
                &s.density,
                s.quality.light_photons,
            );
            light.set_progressive(self.progressive_light);
            self.light = Some(light);
            // Group 2's layout is new.
            self.clouds.invalidate();
        } else if let Some(l) = &mut self.light {
            if constants_changed {
                l.invalidate();
            } else if old.density != s.density || old.sun_dir() != s.sun_dir() {
                l.mark_stale();
            }
        }
    }

    /// Builds now the pipelines that frames drawn as `uses` need (the
    /// light volume's build, the cloud pass's and the composite's; the
    /// terrain's and TSAA's are built with their passes), so the first
    /// frame does not stall while the driver compiles them: call it
    /// behind a loading screen. Without it they are built on first use.
    /// A change of settings that changes their constants or the sky model
    /// drops them again: call it again after such a
    /// [`Self::set_settings`]. [`Self::pipelines`] lists what exists.
    pub fn warm_up(&mut self, uses: &[FrameUse]) {
        let constants = self.settings.constants();
        if let Some(l) = &mut self.light {
            l.warm(&self.device, &self.inputs.layout, &constants);
        }
        let light = self.light.as_ref().map(|l| &l.read_layout);
        for u in uses {
            // As `render` and `render_clouds` choose them: `render` marches
            // to the scene's terrain where it has one.
            let (depth, background) = match *u {
                FrameUse::Render { depth } => (
                    depth || self.terrain.is_some(),
                    Some(background(self.terrain.is_some(), depth)),
                ),
                FrameUse::CloudsOnly { depth } => (depth, None),
            };
            self.clouds.pipeline(
                &self.device,
                &self.inputs,
                &constants,
                depth,
                self.tsaa.is_some(),
                light,
            );
            if let Some(b) = background {
                self.composite.pipeline(
                    &self.device,
                    &self.inputs,
                    &constants,
                    self.target_format,
                    b,
                );
            }
        }
    }

    /// The light volume (`None`: multiple scattering is off), for tests and
    /// debug views.
    pub fn light_volume(&self) -> Option<&LightVolumePass> {
        self.light.as_ref()
    }

    /// Builds the light volume one batch of photons a frame into a running
    /// mean ([`LightVolumePass::set_progressive`]), for an interactive
    /// loop whose clouds change every few frames: a frame costs one
    /// batch (1/16 of the default count) instead of a whole build; the
    /// light follows changing clouds over about 16 frames and, once they
    /// rest, holds the new light alone 32 frames after the change. Off by default (stills, tests and
    /// `cumulus bench` build it whole).
    pub fn set_progressive_light(&mut self, on: bool) {
        self.progressive_light = on;
        if let Some(l) = &mut self.light {
            l.set_progressive(on);
        }
    }

    /// How many times the light volume was built since the renderer was
    /// made (`None`: multiple scattering is off, there is none): a still
    /// field under a still sun builds it once.
    pub fn light_volume_builds(&self) -> Option<u32> {
        self.light.as_ref().map(|l| l.builds())
    }

    /// The settings in use.
    pub fn settings(&self) -> &GpuSettings {
        &self.settings
    }

    /// Sets the size of the target. Zero in either direction is allowed (a
    /// minimised window): `render` then draws nothing. Resets the history.
    pub fn resize(&mut self, width: u32, height: u32) {
        if (width, height) == (self.width, self.height) {
            return;
        }
        self.width = width;
        self.height = height;
        self.clouds.resize(&self.device, width, height);
        if let Some(t) = &mut self.tsaa {
            t.resize(&self.device, width, height);
        }
        if let Some(t) = &mut self.terrain {
            t.resize(&self.device, width, height);
        }
    }

    /// The size set by [`Self::resize`].
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Forgets the TSAA history (the next frame is a camera cut).
    pub fn reset_history(&mut self) {
        if let Some(t) = &mut self.tsaa {
            t.frames = 0;
        }
    }

    /// The frame counter that picks the TSAA jitter (it cycles every
    /// [`super::tsaa::JITTER_CYCLE`] frames).
    pub fn frame_index(&self) -> u32 {
        self.frame_index
    }

    /// Sets the frame counter (to replay a jitter phase).
    pub fn set_frame_index(&mut self, n: u32) {
        self.frame_index = n;
    }

    /// Sets the sea's clock, s (`Quality::sea_time_s`): where its waves
    /// are in their travel. Call it every frame with the time that
    /// passes for the viewer (after [`Self::set_settings`], whose
    /// settings carry their own `sea_time_s`); nothing is rebuilt.
    pub fn set_sea_time(&mut self, seconds: f32) {
        self.settings.quality.sea_time_s = seconds;
    }

    /// Frames in the TSAA history since the last reset (0 without TSAA).
    pub fn history_frames(&self) -> u32 {
        self.tsaa.as_ref().map_or(0, |t| t.frames)
    }

    /// Writes each pass's start and end into `query_set` (two timestamps per
    /// pass, in the order of [`Self::last_passes`]; at least 8 queries).
    /// Needs `Features::TIMESTAMP_QUERY`. `None` stops it.
    pub fn set_timestamp_queries(&mut self, query_set: Option<wgpu::QuerySet>) {
        self.timestamps = query_set;
    }

    /// The passes the last [`Self::render`] ran, in order.
    pub fn last_passes(&self) -> &[&'static str] {
        &self.last_passes
    }

    /// The pipelines that exist now (built on first use), by pass name.
    pub fn pipelines(&self) -> Vec<&'static str> {
        let mut v = Vec::new();
        if self.terrain.is_some() {
            v.push(PASS_TERRAIN);
        }
        if self.light.as_ref().is_some_and(|l| l.has_pipelines()) {
            v.push(PASS_LIGHT_VOLUME);
        }
        v.extend(std::iter::repeat_n(
            PASS_CLOUDS,
            self.clouds.pipeline_count(),
        ));
        if self.tsaa.is_some() {
            v.push(PASS_TSAA);
        }
        v.extend(std::iter::repeat_n(
            PASS_COMPOSITE,
            self.composite.pipeline_count(),
        ));
        v
    }

    /// The physical sky's table builds since the renderer was made, per
    /// table (`None` under the analytic sky): a still camera under a still
    /// sun builds nothing after its first frame.
    pub fn sky_table_builds(&self) -> Option<TableBuilds> {
        self.inputs.sky.as_ref().map(|s| s.builds())
    }

    /// The textures that exist now, by label.
    pub fn textures(&self) -> Vec<&'static str> {
        let mut v = vec![
            "clouds.P",
            "clouds.cloud_map",
            "clouds.blue_noise",
            "clouds.coverage_mask",
            "clouds.layer",
        ];
        if self.inputs.detail {
            v.push("clouds.detail_volume");
        }
        if self.tsaa.is_some() {
            v.extend(["clouds.distance", "tsaa.history0", "tsaa.history1"]);
        }
        if self.terrain.is_some() {
            v.extend(["terrain.heights", "terrain.color", "terrain.depth"]);
        }
        if self.inputs.sky.is_some() {
            v.extend(SkyTable::ALL.map(SkyTable::label));
        }
        v
    }

    /// The cloud layer of the last frame (premultiplied radiance, opacity;
    /// or the sample counts with `debug_sample_count`), for debug views and
    /// tests. After [`Self::render`] over the sea, its radiance also holds
    /// what the mirrored clouds change in the sea behind (possibly
    /// negative; the composite draws the bare sea). `None` while the size
    /// is zero (nothing is drawn).
    pub fn cloud_layer(&self) -> Option<&wgpu::Texture> {
        (self.width > 0 && self.height > 0).then_some(&self.clouds.layer)
    }

    /// Records one frame into `encoder`: the clouds (and sky, sun and
    /// terrain) seen by `camera` into `target` (a view of a texture of the
    /// size given to [`Self::resize`] and the format given to
    /// [`Self::new`]). `camera` is the scene's [`crate::render::camera::Camera`] or the
    /// application's own [`View`] (its view and projection matrices; see
    /// [`crate::render::camera`] for the conventions).
    ///
    /// With `depth` (a single-sampled depth texture of the same size with
    /// `TEXTURE_BINDING` usage, written with the same projection as
    /// `camera`: standard or reversed, finite or infinite far plane),
    /// pixels with geometry keep their colour and only the clouds in front
    /// of it are blended over them; pixels at the far value (what the
    /// buffer is cleared to: 1, or 0 reversed) get sky and clouds. The
    /// scene's own terrain takes the place of `depth` when it has one.
    pub fn render(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        depth: Option<&wgpu::TextureView>,
        camera: &impl ToView,
    ) -> Result<(), RenderError> {
        self.last_passes.clear();
        if self.width == 0 || self.height == 0 {
            return Ok(());
        }
        let size = (self.width, self.height);
        let blended = depth.is_some() && self.terrain.is_none();
        frame_checks::check_target(
            target,
            self.target_format,
            size,
            blended,
            self.device.features(),
        )?;
        let depth_only = frame_checks::check_depth(depth, size)?;
        let depth = depth_only.as_ref().or(depth);
        let view = self.view_of(camera);
        self.write_uniforms(&view, self.terrain.is_some(), true);
        let constants = self.settings.constants();
        // A handle (wgpu objects are reference-counted), so `self` stays free.
        let timestamps = self.timestamps.clone();
        let mut rec = Recorder::new(encoder, timestamps.as_ref());
        if let Some(t) = &self.terrain {
            t.record(&mut rec, &self.inputs, self.settings.quality.max_distance_m);
        }
        let own_depth = self.terrain.as_ref().map(|t| bind::view(&t.depth));
        let resolved = self.record_clouds(&mut rec, &constants, own_depth.as_ref().or(depth));
        let terrain_color = self.terrain.as_ref().map(|t| bind::view(&t.color));
        let background = background(terrain_color.is_some(), depth.is_some());
        let behind = terrain_color.as_ref().or(depth);
        self.composite.record(
            &mut rec,
            &self.device,
            &self.inputs,
            &constants,
            target,
            background,
            &resolved,
            behind,
        );
        self.last_passes = rec.passes();
        Ok(())
    }

    /// Records the clouds alone, for an engine that composites them in its
    /// own HDR pipeline, and returns the texture they are in (valid until
    /// the next `render` or `render_clouds`; [`CLOUDS_ONLY_FORMAT`],
    /// `TEXTURE_BINDING | COPY_SRC`, the size given to [`Self::resize`];
    /// `None` while that size is zero).
    ///
    /// Each texel is linear and premultiplied: `rgb` the clouds' radiance
    /// (sunlight of [`crate::render::cpu::sky::SUN_INTENSITY`], no
    /// exposure and no tone map applied; the haze in front of the clouds
    /// included), `a` their opacity, one minus the transmittance. The
    /// engine's own colour `c` behind becomes `rgb + (1 - a) · c`; with
    /// TSAA on, the texture is the resolved history. No sky, sun disk or
    /// terrain is drawn, and the scene's terrain is not marched to: the
    /// clouds stop at `depth` (as in [`Self::render`]) or at the longest
    /// ray.
    ///
    /// ```no_run
    /// # fn frame(
    /// #     clouds: &mut cumulus::render::gpu::CloudRenderer,
    /// #     device: &wgpu::Device,
    /// #     queue: &wgpu::Queue,
    /// #     depth: &wgpu::TextureView,
    /// #     view_matrix: glam::Mat4,
    /// #     projection: glam::Mat4,
    /// # ) -> Result<(), Box<dyn std::error::Error>> {
    /// use cumulus::render::camera::View;
    ///
    /// // The engine's camera: any perspective (here whatever it uses,
    /// // reversed-Z or not), and the depth buffer it drew its scene with.
    /// let view = View::new(view_matrix, projection)?;
    /// let mut encoder = device.create_command_encoder(&Default::default());
    /// if let Some(layer) = clouds.render_clouds(&mut encoder, Some(depth), &view)? {
    ///     let _clouds = layer.create_view(&Default::default());
    ///     // ... bind `_clouds` in the engine's HDR pass:
    ///     // colour = clouds.rgb + (1 - clouds.a) * colour
    /// }
    /// queue.submit([encoder.finish()]);
    /// # Ok(())
    /// # }
    /// ```
    pub fn render_clouds(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        depth: Option<&wgpu::TextureView>,
        camera: &impl ToView,
    ) -> Result<Option<&wgpu::Texture>, RenderError> {
        self.last_passes.clear();
        if self.width == 0 || self.height == 0 {
            return Ok(None);
        }
        let depth_only = frame_checks::check_depth(depth, (self.width, self.height))?;
        let depth = depth_only.as_ref().or(depth);
        let view = self.view_of(camera);
        self.write_uniforms(&view, false, false);
        let constants = self.settings.constants();
        // A handle (wgpu objects are reference-counted), so `self` stays free.
        let timestamps = self.timestamps.clone();
        let mut rec = Recorder::new(encoder, timestamps.as_ref());
        self.record_clouds(&mut rec, &constants, depth);
        self.last_passes = rec.passes();
        Ok(Some(match &self.tsaa {
            Some(t) => t.latest(),
            None => &self.clouds.layer,
        }))
    }

    /// The view `camera` gives at this target's aspect.
    fn view_of(&self, camera: &impl ToView) -> View {
        let aspect = self.width as f32 / self.height as f32;
        camera.to_view(aspect, self.settings.quality.max_distance_m)
    }

    /// The cloud pass up to `depth` and, with TSAA, the resolve; returns
    /// the resolved layer. Moves the frame on (history, jitter).
    fn record_clouds(
        &mut self,
        rec: &mut Recorder,
        constants: &[(&str, f64)],
        depth: Option<&wgpu::TextureView>,
    ) -> wgpu::TextureView {
        let distance = self.tsaa.as_ref().map(|t| bind::view(&t.distance));
        if let Some(l) = &mut self.light {
            l.build_if_stale(
                &self.device,
                &self.queue,
                &self.inputs.layout,
                &self.inputs.group,
                constants,
            );
        }
        let light = self.light.as_ref().map(|l| (&l.read_layout, &l.read_group));
        let layer = self.clouds.record(
            rec,
            &self.device,
            &self.inputs,
            constants,
            depth,
            distance.as_ref(),
            light,
        );
        let resolved = match &mut self.tsaa {
            Some(t) => t.record(rec, &self.device, &self.inputs, &layer),
            None => layer,
        };
        self.frame_index = self.frame_index.wrapping_add(1);
        resolved
    }

    /// Writes the frame's uniforms for `view` (a camera cut resets the
    /// history, and TSAA jitters the rays); `own_depth`: the cloud pass
    /// reads the terrain's depth buffer (stored flipped under reversed
    /// depth).
    fn write_uniforms(&mut self, view: &View, own_depth: bool, sea_in_layer: bool) {
        if let Some(sky) = &mut self.inputs.sky {
            // The sky view for this camera's altitude, submitted now (before
            // the caller's encoder); nothing is built unless the sun's
            // elevation or the camera's altitude changed.
            let sun_dir = self.settings.sun_dir();
            sky.update_sky_view(&self.device, &self.queue, sun_dir, view.eye().y);
        }
        let cut = self.prev_view.is_none_or(|p| is_cut(&p, view));
        let (jit, blend) = match &mut self.tsaa {
            Some(t) => {
                if cut {
                    t.frames = 0;
                }
                (jitter(self.frame_index), t.blend())
            }
            None => ([0.0; 3], 1.0),
        };
        let view_proj = view.view_projection();
        let terrain = self.terrain.as_ref().map_or([0.0; 3], |t| {
            let stride = t.stride(self.settings.quality.max_distance_m);
            [t.extent_m, t.max_m, stride as f32]
        });
        let u = FrameUniforms::new(&FrameInputs {
            view: *view,
            depth_flipped: own_depth && view.reversed_depth(),
            prev_view_proj: if cut { view_proj } else { self.prev_view_proj },
            width: self.width,
            height: self.height,
            sun_elevation_deg: self.settings.sun_elevation_deg,
            sun_azimuth_deg: self.settings.sun_azimuth_deg,
            density: self.settings.density,
            quality: self.settings.quality,
            jitter: jit,
            blend,
            frame_index: self.frame_index,
            terrain,
            p_size: self.inputs.p_size,
            mask: self.inputs.mask_info,
            map_size: self.inputs.map_size,
            sea_in_layer,
            cloud_cover: self.cloud_cover,
        });
        self.queue
            .write_buffer(&self.inputs.uniforms, 0, bytemuck::bytes_of(&u));
        self.prev_view = Some(*view);
        self.prev_view_proj = view_proj;
    }
}
