//! From a scene to what a frame needs: simulate, project P, generate the
//! cloud map (and terrain), place parcels on the map's cells, and turn the
//! scene's `[render]` section into the renderers' settings. This is the
//! one place that sees the scene, the simulation and the renderers
//! together; the renderers see the simulation only through P.

use std::sync::OnceLock;

use glam::DVec2;

use crate::render::cloud_map::CloudMap;
use crate::render::cpu::density::Fields;
use crate::render::cpu::frame::{Frame, Quality};
use crate::render::cpu::light_volume::LightVolume;
use crate::render::cpu::sky::sun_direction;
use crate::render::cpu::sky_luts::SkyLuts;
use crate::render::cpu::spheroids::Spheroid;
use crate::render::gpu::headless::TARGET_FORMAT;
use crate::render::gpu::{GpuContext, GpuError, GpuSettings, Headless};
use crate::render::soft_field::{SPREAD_M, soft_field};
use crate::render::terrain::Heightfield;
use crate::scene::{Method, RenderSettings, Scene, SceneError};
use crate::sim::automaton::Automaton;
use crate::sim::{Band, FramePlan, Parcels, ProjectedField, Simulation};

/// A scene's textures at one moment.
pub struct Prepared {
    /// P as the simulation projected it.
    pub field: ProjectedField,
    /// P spread to the clouds' merging scale ([`soft_field`]): what the
    /// density reads (the GPU renderer makes its own from `field`).
    pub soft: ProjectedField,
    /// The parcels P was projected from (for the spheroid renderer; none
    /// under the automaton).
    pub parcels: Parcels,
    /// The projection's fill scale (`physics.fill_full_condensed_fraction`).
    pub fill_full_condensed_fraction: f64,
    pub cloud_map: CloudMap,
    pub terrain: Option<Heightfield>,
    pub band: Band,
    pub map_extent_m: f64,
    /// The physical sky's CPU tables, built by the first [`Self::frame`]
    /// that needs them (GPU-only runs never do), for that frame's sun and
    /// camera altitude; [`Self::clear_sky`] drops them.
    sky: OnceLock<Option<SkyLuts>>,
    /// The CPU light volume, built by the first [`Self::frame`] with
    /// multiple scattering on, for that frame's sun and density;
    /// [`Self::clear_sky`] drops it too.
    light: OnceLock<LightVolume>,
}

impl Prepared {
    /// Simulates `scene.render.time_s` seconds (calling `progress` after
    /// each frame) with parcels born on the cloud map's cells (the paper's
    /// Alg. 1, line 2), then projects P.
    pub fn from_scene(scene: &Scene, mut progress: impl FnMut()) -> Result<Self, SceneError> {
        let atm = scene.atmosphere(None)?;
        let band = scene.band(&atm);
        let r = &scene.render;
        let cloud_map = CloudMap::generate(&r.cloud_map);
        let terrain = r.terrain.enabled.then(|| Heightfield::generate(&r.terrain));
        let l = scene.physics.domain_size_m;
        let sites = spawn_sites(&cloud_map, l);
        let mut field = ProjectedField::new(scene.projection.width, scene.projection.height);
        let parcels = match scene.simulation.method {
            Method::Parcels | Method::Endless => {
                let mut sim = Simulation::new(scene.physics.clone(), atm);
                sim.set_spawn_sites(sites);
                let plan = FramePlan::new(scene.render.time_s, scene.physics.dt_s);
                for k in 0..plan.frames() {
                    sim.advance(plan.frame_s(k));
                    progress();
                }
                sim.project_into(&mut field, band);
                sim.parcels().clone()
            }
            Method::Automaton => {
                let mut a = Automaton::new(
                    &scene.simulation.automaton,
                    &scene.physics,
                    band,
                    &sites,
                    field.width(),
                    field.height(),
                );
                for _ in 0..Self::frames(scene) {
                    a.step();
                    progress();
                }
                a.project_into(&mut field);
                Parcels::default()
            }
        };
        let soft = soft_field(&field, SPREAD_M, l as f32);
        Ok(Self {
            soft,
            parcels,
            fill_full_condensed_fraction: scene.physics.fill_full_condensed_fraction,
            field,
            cloud_map,
            terrain,
            band,
            map_extent_m: l,
            sky: OnceLock::new(),
            light: OnceLock::new(),
        })
    }

    /// The scene's textures, band and extent with an empty P: nothing
    /// simulated (for what fills the sky another way, or later).
    pub fn unsimulated(scene: &Scene) -> Result<Self, SceneError> {
        let mut bare = scene.clone();
        bare.simulation.method = Method::Parcels;
        bare.render.time_s = 0.0;
        Self::from_scene(&bare, || {})
    }

    /// The scene's parcels (whatever its method) at `count` moments
    /// `interval_s` apart, the first after `render.time_s`: `each` gets
    /// the moment's index and its fields (one simulation, P projected
    /// anew each time). `progress` is called after every physics frame.
    pub fn snapshots(
        scene: &Scene,
        interval_s: f64,
        count: usize,
        mut each: impl FnMut(usize, &Prepared),
        mut progress: impl FnMut(),
    ) -> Result<(), SceneError> {
        let atm = scene.atmosphere(None)?;
        let mut p = Self::unsimulated(scene)?;
        let mut sim = Simulation::new(scene.physics.clone(), atm);
        sim.set_spawn_sites(spawn_sites(&p.cloud_map, p.map_extent_m));
        let plan = FramePlan::new(scene.render.time_s, scene.physics.dt_s);
        for k in 0..plan.frames() {
            sim.advance(plan.frame_s(k));
            progress();
        }
        let step = FramePlan::new(interval_s, scene.physics.dt_s);
        for v in 0..count {
            if v > 0 {
                for k in 0..step.frames() {
                    sim.advance(step.frame_s(k));
                    progress();
                }
            }
            sim.project_into(&mut p.field, p.band);
            p.soft = soft_field(&p.field, SPREAD_M, p.map_extent_m as f32);
            p.parcels = sim.parcels().clone();
            p.light = OnceLock::new();
            each(v, &p);
        }
        Ok(())
    }

    /// Drops the physical sky's CPU tables and the light volume, for a
    /// frame with another sun, camera altitude or density settings than
    /// the first one's (the next [`Self::frame`] builds them anew).
    pub fn clear_sky(&mut self) {
        self.sky = OnceLock::new();
        self.light = OnceLock::new();
    }

    /// Physics frames simulated before the picture (exactly `time_s`: a
    /// short last frame when `dt_s` does not divide it), or the
    /// automaton's steps (`time_s / step_s`, rounded to the nearest).
    pub fn frames(scene: &Scene) -> u64 {
        match scene.simulation.method {
            Method::Parcels | Method::Endless => {
                FramePlan::new(scene.render.time_s, scene.physics.dt_s).frames()
            }
            Method::Automaton => {
                (scene.render.time_s / scene.simulation.automaton.step_s).round() as u64
            }
        }
    }

    /// The GPU renderer's settings for `r` with `quality`.
    pub fn gpu_settings(&self, r: &RenderSettings, quality: Quality) -> GpuSettings {
        r.gpu_settings_at(self.band, self.map_extent_m, quality)
    }

    /// A `width x height` offscreen GPU renderer of these fields.
    pub fn headless(
        &self,
        ctx: &GpuContext,
        settings: &GpuSettings,
        width: u32,
        height: u32,
    ) -> Result<Headless, GpuError> {
        self.headless_with_format(ctx, settings, width, height, TARGET_FORMAT)
    }

    /// [`Self::headless`] with a target of `format` (`HDR_FORMAT`: linear
    /// radiance, for OpenEXR).
    pub fn headless_with_format(
        &self,
        ctx: &GpuContext,
        settings: &GpuSettings,
        width: u32,
        height: u32,
        format: wgpu::TextureFormat,
    ) -> Result<Headless, GpuError> {
        Headless::with_format(
            ctx,
            &self.field,
            &self.cloud_map,
            self.terrain.as_ref(),
            settings,
            (width, height),
            format,
        )
    }

    /// The CPU frame for `settings` with `quality`. Under the physical sky
    /// (`quality.atmosphere`) the first call builds its tables for `r`'s
    /// sun and camera altitude (about 0.1 s on two cores), and with
    /// multiple scattering on the light volume for `r`'s sun and density
    /// (about 0.3 s); later calls reuse them: call [`Self::clear_sky`]
    /// before a frame with another sun, camera altitude or density
    /// settings.
    pub fn frame<'a>(&'a self, r: &RenderSettings, quality: Quality) -> Frame<'a> {
        self.frame_with(r, quality, true, &|_| {})
    }

    /// [`Self::frame`], calling `progress` with the share of the light
    /// volume's build done (0 to 1) while it is built; not at all when it
    /// is not built (no light volume, or built already).
    pub fn frame_reporting<'a>(
        &'a self,
        r: &RenderSettings,
        quality: Quality,
        progress: &dyn Fn(f32),
    ) -> Frame<'a> {
        self.frame_with(r, quality, true, progress)
    }

    /// [`Self::frame`] without the light volume, for what reads only the
    /// density (a volume export, the field's statistics, the endless
    /// volumes) or lights itself (the spheroid and volume renderers'
    /// CPU twins): nothing is built for the light.
    pub fn density_frame<'a>(&'a self, r: &RenderSettings, quality: Quality) -> Frame<'a> {
        self.frame_with(r, quality, false, &|_| {})
    }

    fn frame_with<'a>(
        &'a self,
        r: &RenderSettings,
        quality: Quality,
        lit: bool,
        progress: &dyn Fn(f32),
    ) -> Frame<'a> {
        let sky = quality.atmosphere.sky_params().and_then(|params| {
            self.sky
                .get_or_init(|| {
                    let sun = sun_direction(r.sun_elevation_deg, r.sun_azimuth_deg);
                    Some(SkyLuts::build(params, sun, r.camera_position_m[1]))
                })
                .as_ref()
        });
        let fields = Fields {
            p: &self.soft,
            cloud_map: &self.cloud_map,
        };
        let density = r.density(self.band, self.map_extent_m);
        let light =
            (lit && quality.octaves > 0 && quality.light_photons > 0 && !quality.single_scattering)
                .then(|| {
                    self.light.get_or_init(|| {
                        let sun = sun_direction(r.sun_elevation_deg, r.sun_azimuth_deg);
                        LightVolume::build_reporting(
                            &fields,
                            &density,
                            sun,
                            quality.light_photons,
                            progress,
                        )
                    })
                });
        Frame {
            view: r.camera().view(
                r.width as f32 / r.height.max(1) as f32,
                quality.max_distance_m,
            ),
            sun_elevation_deg: r.sun_elevation_deg,
            sun_azimuth_deg: r.sun_azimuth_deg,
            fields,
            density,
            quality,
            terrain: self.terrain.as_ref(),
            sky,
            cloud_cover: self.field.covered_fraction() as f32,
            light,
        }
    }

    /// The cloudy parcels as the spheroid renderer's primitives.
    pub fn spheroids(&self) -> Vec<Spheroid> {
        spheroids(&self.parcels, self.fill_full_condensed_fraction)
    }
}

/// Where parcels are born: the centres of the cloud map's cells (up to 64)
/// in the physics domain of side `extent_m`.
pub fn spawn_sites(cloud_map: &CloudMap, extent_m: f64) -> Vec<DVec2> {
    cloud_map
        .cell_centres(64)
        .into_iter()
        .map(|(u, v)| DVec2::new(u as f64 * extent_m, v as f64 * extent_m))
        .collect()
}

/// Vertical semi-axis of a parcel's spheroid over its horizontal one: a
/// cumulus element is wider than tall (their Fig. 12 flattens its
/// spheroids about this much).
pub const SPHEROID_ASPECT: f32 = 0.6;

/// The cloudy, released parcels as pseudo-spheroids in the world frame (the
/// physics' `(x, y, z)` is the world's `(x, z, y)`), with the fill the
/// projection gives them. The spheroids are not tiled: the domain is drawn
/// once.
pub fn spheroids(parcels: &Parcels, fill_full_condensed_fraction: f64) -> Vec<Spheroid> {
    let full = fill_full_condensed_fraction.max(1e-12);
    (0..parcels.len())
        .filter(|&i| parcels.diag[i].qc > 0.0 && parcels.life[i].released())
        .map(|i| {
            let p = parcels.pos[i];
            let qt = parcels.qt[i];
            let fill = if qt > 0.0 {
                (parcels.diag[i].qc / qt / full).clamp(0.0, 1.0)
            } else {
                0.0
            };
            Spheroid {
                centre_radius: [
                    p.x as f32,
                    p.z as f32,
                    p.y as f32,
                    parcels.life[i].radius_m as f32,
                ],
                shape: [fill as f32, SPHEROID_ASPECT, 0.0, 0.0],
            }
        })
        .collect()
}

/// What in the scene's view leaves its picture empty though every key is
/// in its domain, one line each (the CLI prints them as warnings before
/// it simulates): a camera under the ground, and a cloud band or a
/// ground farther from the camera than `render.max_distance_m`, where
/// every ray stops.
pub fn view_warnings(scene: &Scene) -> Result<Vec<String>, SceneError> {
    let atm = scene.atmosphere(None)?;
    let band = scene.band(&atm);
    let r = &scene.render;
    let terrain = r.terrain.enabled.then(|| Heightfield::generate(&r.terrain));
    let [x, y, z] = r.camera_position_m;
    let ground = terrain.as_ref().map_or(0.0, |t| t.height_at(x, z));
    Ok(warnings_for(
        y,
        ground,
        (band.bottom_m as f32, band.top_m as f32),
        r.max_distance_m,
        terrain.is_some(),
    ))
}

/// [`view_warnings`] for a camera `y` m high over ground at `ground` m,
/// a cloud band from `band.0` to `band.1` m and rays of at most
/// `max_distance` m.
fn warnings_for(
    y: f32,
    ground: f32,
    band: (f32, f32),
    max_distance: f32,
    terrain: bool,
) -> Vec<String> {
    let mut out = Vec::new();
    let what = if terrain { "terrain" } else { "flat ground" };
    if y < ground {
        out.push(format!(
            "the camera (render.camera_position_m y = {y} m) is {:.0} m under the {what} \
             (at {ground:.0} m): the picture is not what stands above it; raise its y",
            ground - y
        ));
    }
    let to_band = if y > band.1 {
        y - band.1
    } else {
        (band.0 - y).max(0.0)
    };
    if to_band >= max_distance {
        out.push(format!(
            "the cloud band ({:.0}-{:.0} m) is {to_band:.0} m from the camera, beyond \
             render.max_distance_m ({max_distance} m), where rays stop: no cloud can show; \
             raise max_distance_m",
            band.0, band.1
        ));
    }
    if y - ground >= max_distance {
        out.push(format!(
            "the {what} is {:.0} m below the camera, beyond render.max_distance_m \
             ({max_distance} m): it is not drawn; raise max_distance_m",
            y - ground
        ));
    }
    out
}

#[cfg(test)]
mod view_tests {
    use super::*;

    #[test]
    fn empty_pictures_are_foretold() {
        let band = (600.0, 1600.0);
        // A camera in the sky's usual places: nothing to say.
        for y in [2.0, 100.0, 1000.0, 7000.0] {
            assert!(
                warnings_for(y, 0.0, band, 40_000.0, false).is_empty(),
                "{y}"
            );
        }
        // Under the ground (flat, or hills 300 m high under it).
        let w = warnings_for(-500.0, 0.0, band, 40_000.0, false);
        assert_eq!(w.len(), 1);
        assert!(w[0].contains("500 m under the flat ground"), "{w:?}");
        let w = warnings_for(10.0, 300.0, band, 40_000.0, true);
        assert!(w[0].contains("290 m under the terrain (at 300 m)"), "{w:?}");
        // From 50 km up, rays of 40 km reach neither the band nor the
        // ground (the review's flat blue picture).
        let w = warnings_for(50_000.0, 0.0, band, 40_000.0, false);
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(w[0].contains("48400 m from the camera"), "{w:?}");
        assert!(w[1].contains("50000 m below the camera"), "{w:?}");
        // Longer rays reach both.
        assert!(warnings_for(50_000.0, 0.0, band, 1e6, false).is_empty());
    }
}
