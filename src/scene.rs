//! Scene files (TOML): the atmosphere, the physics and the projection.
//! Every key is listed with unit and default in `docs/scene.md` (a test
//! checks that none is missing). Errors name the file, line and key.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::sim::lift::surface_lcl_height;
use crate::sim::{Atmosphere, Band, ParametricProfile, PhysicsConfig, Sounding, SoundingError};

/// What went wrong with a scene.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{path}: cannot read scene: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}:{line}:{column}: {message}")]
    Parse {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{path}{}: `{key}`: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Invalid {
        path: PathBuf,
        line: Option<usize>,
        key: String,
        message: String,
    },
    #[error(transparent)]
    Sounding(#[from] SoundingError),
}

/// `[atmosphere]`: a sounding file, or a parametric profile (the default).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AtmosphereSection {
    /// Sounding CSV, relative to the scene file. Excludes `parametric`.
    pub sounding: Option<PathBuf>,
    /// Ground pressure for a sounding without pressures, hPa. Default 1013.25.
    pub surface_pressure_hpa: Option<f64>,
    /// Height of the inversion base, m; default from the profile.
    pub inversion_base_m: Option<f64>,
    /// Parametric profile (`[atmosphere.parametric]`).
    pub parametric: Option<ParametricProfile>,
}

/// `[projection]`: the texture P.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ProjectionSection {
    /// Width of P, texels (1..=4096). Default 128.
    pub width: usize,
    /// Height of P, texels (1..=4096). Default 128.
    pub height: usize,
    /// Cloud-band bottom, m. Default: LCL of the surface air.
    pub band_bottom_m: Option<f64>,
    /// Cloud-band top, m. Default: the inversion base (else LCL + 1500 m).
    pub band_top_m: Option<f64>,
}

impl Default for ProjectionSection {
    fn default() -> Self {
        Self {
            width: 128,
            height: 128,
            band_bottom_m: None,
            band_top_m: None,
        }
    }
}

/// A scene.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Scene {
    /// Display name.
    pub name: String,
    /// One line on what the scene shows.
    pub description: String,
    pub atmosphere: AtmosphereSection,
    pub physics: PhysicsConfig,
    pub projection: ProjectionSection,
    pub render: crate::render::cpu::renderer::RenderSettings,
    /// Where the scene was read from (not a key).
    #[serde(skip)]
    pub source: Option<PathBuf>,
    #[serde(skip)]
    text: Option<String>,
}

/// A range check for one key.
struct Check<'a> {
    key: std::borrow::Cow<'a, str>,
    ok: bool,
    expected: &'a str,
    value: String,
}

impl Scene {
    /// Reads, parses and validates a scene file.
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
            path: path.to_owned(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Parses and validates scene text; `path` names it in errors and
    /// anchors relative sounding paths.
    pub fn parse(text: &str, path: &Path) -> Result<Self, SceneError> {
        let mut scene: Scene = toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map(|s| line_col(text, s.start)).unwrap_or((1, 1));
            SceneError::Parse {
                path: path.to_owned(),
                line,
                column,
                message: e.message().trim().to_owned(),
            }
        })?;
        scene.source = Some(path.to_owned());
        scene.text = Some(text.to_owned());
        scene.validate()?;
        Ok(scene)
    }

    /// Checks every value against its domain; the error names the key and,
    /// when the scene came from a file, the line.
    pub fn validate(&self) -> Result<(), SceneError> {
        let p = &self.physics;
        let c = |key: &'static str, ok, expected, value: f64| Check {
            key: key.into(),
            ok,
            expected,
            value: value.to_string(),
        };
        let finite_in = |v: f64, lo: f64, hi: f64| v.is_finite() && v >= lo && v <= hi;
        let mut checks = vec![
            c(
                "physics.dt_s",
                finite_in(p.dt_s, 1e-3, 600.0),
                "1e-3..=600 s",
                p.dt_s,
            ),
            c(
                "physics.parcels",
                p.parcels <= 200_000,
                "0..=200000",
                p.parcels as f64,
            ),
            c(
                "physics.domain_size_m",
                finite_in(p.domain_size_m, 1.0, 1e7),
                "1..=1e7 m",
                p.domain_size_m,
            ),
            c(
                "physics.radius_m",
                finite_in(p.radius_m, 1e-3, 1e5),
                "a radius > 0 m",
                p.radius_m,
            ),
            c(
                "physics.radius_jitter",
                finite_in(p.radius_jitter, 0.0, 0.99),
                "0..<1",
                p.radius_jitter,
            ),
            c(
                "physics.release_height_m",
                finite_in(p.release_height_m, 0.0, 1e5),
                ">= 0 m",
                p.release_height_m,
            ),
            c(
                "physics.release_stagger_s",
                finite_in(p.release_stagger_s, 0.0, 1e7),
                ">= 0 s",
                p.release_stagger_s,
            ),
            c(
                "physics.initial_excess_k",
                finite_in(p.initial_excess_k, -50.0, 50.0),
                "-50..=50 K",
                p.initial_excess_k,
            ),
            c(
                "physics.initial_excess_qt_gkg",
                finite_in(p.initial_excess_qt_gkg, -50.0, 50.0),
                "-50..=50 g/kg",
                p.initial_excess_qt_gkg,
            ),
            c(
                "physics.virtual_mass",
                finite_in(p.virtual_mass, 0.0, 2.0),
                "0..=2",
                p.virtual_mass,
            ),
            c(
                "physics.drag_coefficient",
                finite_in(p.drag_coefficient, 0.0, 5.0),
                "0..=5",
                p.drag_coefficient,
            ),
            c(
                "physics.fill_full_condensed_fraction",
                finite_in(p.fill_full_condensed_fraction, 1e-6, 1.0),
                "(0, 1]",
                p.fill_full_condensed_fraction,
            ),
            c(
                "physics.entrainment.coefficient",
                finite_in(p.entrainment.coefficient, 0.0, 2.0),
                "0..=2",
                p.entrainment.coefficient,
            ),
            c(
                "physics.detrainment.rate_per_s",
                finite_in(p.detrainment.rate_per_s, 0.0, 1.0),
                "0..=1 1/s",
                p.detrainment.rate_per_s,
            ),
            c(
                "physics.detrainment.sorting_factor",
                finite_in(p.detrainment.sorting_factor, 0.0, 100.0),
                "0..=100",
                p.detrainment.sorting_factor,
            ),
            c(
                "physics.recycling.spent_fraction_of_peak",
                finite_in(p.recycling.spent_fraction_of_peak, 0.0, 1.0),
                "0..=1",
                p.recycling.spent_fraction_of_peak,
            ),
            c(
                "physics.recycling.max_age_s",
                finite_in(p.recycling.max_age_s, 1e-3, 1e9),
                "> 0 s",
                p.recycling.max_age_s,
            ),
            c(
                "physics.sph.smoothing_radii",
                finite_in(p.sph.smoothing_radii, 1e-3, 100.0)
                    && (!p.sph.enabled
                        || p.sph.smoothing_radii * p.radius_m <= 0.5 * p.domain_size_m),
                "> 0, with smoothing_radii * radius_m <= domain_size_m / 2",
                p.sph.smoothing_radii,
            ),
            c(
                "physics.sph.sound_speed_mps",
                finite_in(p.sph.sound_speed_mps, 1e-6, 1e3),
                "> 0 m/s",
                p.sph.sound_speed_mps,
            ),
            c(
                "physics.sph.viscosity_m2ps",
                finite_in(p.sph.viscosity_m2ps, 0.0, 1e7),
                ">= 0 m²/s",
                p.sph.viscosity_m2ps,
            ),
            c(
                "physics.wind.speed_mps",
                finite_in(p.wind.speed_mps, 0.0, 200.0),
                "0..=200 m/s",
                p.wind.speed_mps,
            ),
            c(
                "physics.wind.direction_deg",
                p.wind.direction_deg.is_finite(),
                "a finite angle",
                p.wind.direction_deg,
            ),
            c(
                "physics.wind.shear_per_km",
                finite_in(p.wind.shear_per_km, -1.0, 10.0),
                "-1..=10 1/km",
                p.wind.shear_per_km,
            ),
            c(
                "physics.substeps.max_buoyancy_phase",
                finite_in(p.substeps.max_buoyancy_phase, 1e-6, 1.0),
                "(0, 1]",
                p.substeps.max_buoyancy_phase,
            ),
            c(
                "physics.substeps.max_rise_m",
                finite_in(p.substeps.max_rise_m, 1e-3, 1e5),
                "> 0 m",
                p.substeps.max_rise_m,
            ),
            c(
                "physics.substeps.sph_courant",
                finite_in(p.substeps.sph_courant, 1e-6, 1.0),
                "(0, 1]",
                p.substeps.sph_courant,
            ),
            c(
                "physics.substeps.max_per_frame",
                (1..=1_000_000).contains(&p.substeps.max_per_frame),
                "1..=1000000",
                p.substeps.max_per_frame as f64,
            ),
            c(
                "projection.width",
                (1..=4096).contains(&self.projection.width),
                "1..=4096 texels",
                self.projection.width as f64,
            ),
            c(
                "projection.height",
                (1..=4096).contains(&self.projection.height),
                "1..=4096 texels",
                self.projection.height as f64,
            ),
        ];
        let r = &self.render;
        let f = |v: f32| v as f64;
        checks.extend([
            c(
                "render.width",
                (1..=8192).contains(&r.width),
                "1..=8192 pixels",
                f(r.width as f32),
            ),
            c(
                "render.height",
                (1..=8192).contains(&r.height),
                "1..=8192 pixels",
                f(r.height as f32),
            ),
            c(
                "render.camera_position_m",
                r.camera_position_m.iter().all(|x| x.is_finite()),
                "three finite numbers [x, y, z] in m",
                f(r.camera_position_m[1]),
            ),
            c(
                "render.camera_yaw_deg",
                r.camera_yaw_deg.is_finite(),
                "a finite angle",
                f(r.camera_yaw_deg),
            ),
            c(
                "render.camera_pitch_deg",
                finite_in(f(r.camera_pitch_deg), -89.0, 89.0),
                "-89..=89 degrees",
                f(r.camera_pitch_deg),
            ),
            c(
                "render.fov_deg",
                finite_in(f(r.fov_deg), 1.0, 170.0),
                "1..=170 degrees",
                f(r.fov_deg),
            ),
            c(
                "render.sun_elevation_deg",
                finite_in(f(r.sun_elevation_deg), -10.0, 90.0),
                "-10..=90 degrees",
                f(r.sun_elevation_deg),
            ),
            c(
                "render.sun_azimuth_deg",
                r.sun_azimuth_deg.is_finite(),
                "a finite angle",
                f(r.sun_azimuth_deg),
            ),
            c(
                "render.coverage",
                finite_in(f(r.coverage), 0.0, 1.0),
                "0..=1",
                f(r.coverage),
            ),
            c(
                "render.extinction_per_m",
                finite_in(f(r.extinction_per_m), 1e-6, 10.0),
                "> 0 1/m",
                f(r.extinction_per_m),
            ),
            c(
                "render.steps",
                (1..=4096).contains(&r.steps),
                "1..=4096",
                r.steps as f64,
            ),
            c(
                "render.shadow_steps",
                r.shadow_steps <= 64,
                "0..=64",
                r.shadow_steps as f64,
            ),
            c("render.octaves", r.octaves <= 3, "0..=3", r.octaves as f64),
            c(
                "render.haze_distance_m",
                finite_in(f(r.haze_distance_m), 1.0, 1e7),
                "> 0 m",
                f(r.haze_distance_m),
            ),
            c(
                "render.max_distance_m",
                finite_in(f(r.max_distance_m), 1.0, 1e7),
                "> 0 m",
                f(r.max_distance_m),
            ),
            c(
                "render.exposure",
                finite_in(f(r.exposure), 1e-3, 1e3),
                "> 0",
                f(r.exposure),
            ),
            c(
                "render.time_s",
                finite_in(r.time_s, 0.0, 1e7),
                "0..=1e7 s",
                r.time_s,
            ),
            c(
                "render.tsaa_blend",
                finite_in(f(r.tsaa_blend), 1e-3, 1.0),
                "0.001..=1",
                f(r.tsaa_blend),
            ),
            c(
                "render.cloud_map.size",
                (16..=2048).contains(&r.cloud_map.size),
                "16..=2048 texels",
                r.cloud_map.size as f64,
            ),
            c(
                "render.cloud_map.cells",
                finite_in(r.cloud_map.cells, 1.0, 64.0),
                "1..=64",
                r.cloud_map.cells,
            ),
            c(
                "render.cloud_map.detail",
                finite_in(r.cloud_map.detail, 1.0, 256.0),
                "1..=256",
                r.cloud_map.detail,
            ),
            c(
                "render.terrain.relief_m",
                finite_in(f(r.terrain.relief_m), 0.0, 5000.0),
                "0..=5000 m",
                f(r.terrain.relief_m),
            ),
            c(
                "render.terrain.extent_m",
                finite_in(f(r.terrain.extent_m), 1.0, 1e7),
                "> 0 m",
                f(r.terrain.extent_m),
            ),
            c(
                "render.terrain.hills",
                finite_in(r.terrain.hills, 1.0, 64.0),
                "1..=64",
                r.terrain.hills,
            ),
            c(
                "render.terrain.size",
                (16..=2048).contains(&r.terrain.size),
                "16..=2048 texels",
                r.terrain.size as f64,
            ),
            c(
                "render.cloud_map.octaves",
                (1..=8).contains(&r.cloud_map.octaves),
                "1..=8",
                r.cloud_map.octaves as f64,
            ),
        ]);
        let opt = |key, v: Option<f64>, lo, hi, expected| {
            v.map(|v| c(key, finite_in(v, lo, hi), expected, v))
        };
        checks.extend(opt(
            "atmosphere.surface_pressure_hpa",
            self.atmosphere.surface_pressure_hpa,
            300.0,
            1100.0,
            "300..=1100 hPa",
        ));
        checks.extend(opt(
            "atmosphere.inversion_base_m",
            self.atmosphere.inversion_base_m,
            0.0,
            1e5,
            ">= 0 m",
        ));
        checks.extend(opt(
            "projection.band_bottom_m",
            self.projection.band_bottom_m,
            0.0,
            1e5,
            ">= 0 m",
        ));
        checks.extend(opt(
            "projection.band_top_m",
            self.projection.band_top_m,
            0.0,
            1e5,
            ">= 0 m and above band_bottom_m",
        ));
        if let (Some(b), Some(t)) = (self.projection.band_bottom_m, self.projection.band_top_m) {
            checks.push(Check {
                key: "projection.band_top_m".into(),
                ok: t > b,
                expected: "above band_bottom_m",
                value: t.to_string(),
            });
        }
        if let Some(pp) = &self.atmosphere.parametric {
            let k = "atmosphere.parametric.";
            let list = [
                (
                    "surface_temperature_k",
                    pp.surface_temperature_k,
                    180.0,
                    340.0,
                    "180..=340 K",
                ),
                (
                    "surface_pressure_hpa",
                    pp.surface_pressure_hpa,
                    300.0,
                    1100.0,
                    "300..=1100 hPa",
                ),
                (
                    "surface_relative_humidity",
                    pp.surface_relative_humidity,
                    0.0,
                    1.2,
                    "0..=1.2",
                ),
                (
                    "lapse_rate_k_per_km",
                    pp.lapse_rate_k_per_km,
                    -20.0,
                    20.0,
                    "-20..=20 K/km",
                ),
                (
                    "inversion_base_m",
                    pp.inversion_base_m,
                    0.0,
                    20_000.0,
                    "0..=20000 m",
                ),
                (
                    "inversion_thickness_m",
                    pp.inversion_thickness_m,
                    1.0,
                    5000.0,
                    "1..=5000 m",
                ),
                (
                    "inversion_strength_k",
                    pp.inversion_strength_k,
                    0.0,
                    40.0,
                    "0..=40 K",
                ),
                (
                    "lapse_rate_above_k_per_km",
                    pp.lapse_rate_above_k_per_km,
                    -20.0,
                    20.0,
                    "-20..=20 K/km",
                ),
                (
                    "humidity_scale_height_m",
                    pp.humidity_scale_height_m,
                    1.0,
                    1e6,
                    ">= 1 m",
                ),
                (
                    "humidity_drop_above_inversion",
                    pp.humidity_drop_above_inversion,
                    0.0,
                    1.0,
                    "0..=1",
                ),
                ("top_m", pp.top_m, 100.0, 30_000.0, "100..=30000 m"),
            ];
            for (name, v, lo, hi, expected) in list {
                checks.push(Check {
                    key: format!("{k}{name}").into(),
                    ok: finite_in(v, lo, hi),
                    expected,
                    value: v.to_string(),
                });
            }
            if self.atmosphere.sounding.is_some() {
                checks.push(Check {
                    key: "atmosphere.sounding".into(),
                    ok: false,
                    expected: "either a sounding or [atmosphere.parametric], not both",
                    value: "both given".into(),
                });
            }
        }
        match checks.into_iter().find(|c| !c.ok) {
            None => Ok(()),
            Some(c) => {
                Err(self.invalid(&c.key, format!("is {}, expected {}", c.value, c.expected)))
            }
        }
    }

    /// An error about `key`, located in the scene text when there is one.
    pub fn invalid(&self, key: &str, message: String) -> SceneError {
        SceneError::Invalid {
            path: self
                .source
                .clone()
                .unwrap_or_else(|| PathBuf::from("<scene>")),
            line: self.text.as_deref().and_then(|t| locate_key(t, key)),
            key: key.to_owned(),
            message,
        }
    }

    /// The scene as TOML text for a file at `path`: a sounding path is
    /// rewritten so that it still names the same file from there
    /// (absolute when the scene's own directory is unknown).
    pub fn to_toml(&self, path: &Path) -> Result<String, SceneError> {
        let mut out = self.clone();
        if let Some(rel) = &self.atmosphere.sounding {
            let here = self
                .source
                .as_deref()
                .and_then(Path::parent)
                .map(|d| d.join(rel))
                .unwrap_or_else(|| rel.clone());
            let abs = std::fs::canonicalize(&here).unwrap_or(here);
            let dir = path.parent().and_then(|d| std::fs::canonicalize(d).ok());
            out.atmosphere.sounding = Some(
                match dir.and_then(|d| abs.strip_prefix(&d).ok().map(Path::to_owned)) {
                    Some(r) => r,
                    None => abs,
                },
            );
        }
        toml::to_string_pretty(&out).map_err(|e| SceneError::Invalid {
            path: path.to_owned(),
            line: None,
            key: "scene".into(),
            message: format!("cannot be written as TOML: {e}"),
        })
    }

    /// Writes the scene to `path` atomically ([`Self::to_toml`]); it loads
    /// back with the same settings ([`Self::same_settings`]).
    pub fn save(&self, path: &Path) -> Result<(), SceneError> {
        let text = self.to_toml(path)?;
        crate::io::write_atomically(path, |out| out.write_all(text.as_bytes())).map_err(|source| {
            SceneError::Io {
                path: path.to_owned(),
                source,
            }
        })
    }

    /// Whether two scenes describe the same sky (every section equal, the
    /// sounding compared by the file it resolves to; the file they came
    /// from is not compared).
    pub fn same_settings(&self, other: &Scene) -> bool {
        let resolve = |s: &Scene| {
            s.atmosphere.sounding.as_ref().map(|rel| {
                let p = s
                    .source
                    .as_deref()
                    .and_then(Path::parent)
                    .map(|d| d.join(rel))
                    .unwrap_or_else(|| rel.clone());
                std::fs::canonicalize(&p).unwrap_or(p)
            })
        };
        let strip = |s: &Scene| AtmosphereSection {
            sounding: None,
            ..s.atmosphere.clone()
        };
        self.name == other.name
            && self.description == other.description
            && strip(self) == strip(other)
            && resolve(self) == resolve(other)
            && self.physics == other.physics
            && self.projection == other.projection
            && self.render == other.render
    }

    /// Builds the atmosphere (reading the sounding, relative to the scene
    /// file, if the scene names one). `sounding_override` replaces it.
    pub fn atmosphere(&self, sounding_override: Option<&Path>) -> Result<Atmosphere, SceneError> {
        let a = &self.atmosphere;
        let surface = a.surface_pressure_hpa.unwrap_or(1013.25) * 100.0;
        let sounding_path = match (sounding_override, &a.sounding) {
            (Some(p), _) => Some(p.to_owned()),
            (None, Some(rel)) => Some(
                self.source
                    .as_deref()
                    .and_then(Path::parent)
                    .map(|d| d.join(rel))
                    .unwrap_or_else(|| rel.clone()),
            ),
            (None, None) => None,
        };
        let atm = match sounding_path {
            Some(p) => {
                let s = Sounding::load(&p, surface)?;
                Atmosphere::from_sounding(&s)
            }
            None => Atmosphere::from_parametric(&a.parametric.unwrap_or_default()),
        };
        Ok(match a.inversion_base_m {
            Some(z) => atm.with_inversion_base(z),
            None => atm,
        })
    }

    /// The cloud band: the scene's values, else the surface air's LCL to the
    /// inversion base (LCL + 1500 m without an inversion).
    pub fn band(&self, atm: &Atmosphere) -> Band {
        let lcl = surface_lcl_height(atm).unwrap_or(500.0);
        let bottom = self.projection.band_bottom_m.unwrap_or(lcl);
        let top = self
            .projection
            .band_top_m
            .or(atm.inversion_base_m().filter(|&z| z > bottom + 50.0))
            .unwrap_or(bottom + 1500.0);
        Band {
            bottom_m: bottom,
            top_m: top.max(bottom + 1.0),
        }
    }
}

/// 1-based line and column of byte `offset` in `text`.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, column)
}

/// 1-based line of the dotted `key` (e.g. `physics.sph.sound_speed_mps`) in
/// TOML text: the line `name = ...` under the table header of its parent
/// (or written dotted from a parent table).
pub fn locate_key(text: &str, key: &str) -> Option<usize> {
    let parts: Vec<&str> = key.split('.').collect();
    let mut table: Vec<String> = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if let Some(h) = line.strip_prefix('[') {
            let h = h.trim_start_matches('[').split(']').next().unwrap_or("");
            table = h.split('.').map(|s| s.trim().to_owned()).collect();
            continue;
        }
        let Some((lhs, _)) = line.split_once('=') else {
            continue;
        };
        let mut full: Vec<String> = table.clone();
        full.extend(
            lhs.split('.')
                .map(|s| s.trim().trim_matches('"').to_owned()),
        );
        if full.len() == parts.len() && full.iter().zip(&parts).all(|(a, b)| a == b) {
            return Some(n + 1);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locate_key_finds_table_and_dotted_keys() {
        let t = "name = \"x\"\n[physics]\ndt_s = 1\nsph.sound_speed_mps = 2\n[physics.wind]\nspeed_mps = -1\n";
        assert_eq!(locate_key(t, "physics.dt_s"), Some(3));
        assert_eq!(locate_key(t, "physics.sph.sound_speed_mps"), Some(4));
        assert_eq!(locate_key(t, "physics.wind.speed_mps"), Some(6));
        assert_eq!(locate_key(t, "physics.radius_m"), None);
    }

    #[test]
    fn negative_radius_names_key_and_line() {
        let e = Scene::parse(
            "[physics]\nparcels = 3\nradius_m = -5\n",
            Path::new("s.toml"),
        )
        .expect_err("negative");
        assert_eq!(
            e.to_string(),
            "s.toml:3: `physics.radius_m`: is -5, expected a radius > 0 m"
        );
    }

    #[test]
    fn unknown_key_names_line() {
        let e = Scene::parse("[physics]\nparcels = 3\nradius = 5\n", Path::new("s.toml"))
            .expect_err("unknown");
        let msg = e.to_string();
        assert!(msg.starts_with("s.toml:3:"), "{msg}");
        assert!(msg.contains("unknown field `radius`"), "{msg}");
    }
}
