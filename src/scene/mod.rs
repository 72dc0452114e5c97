//! Scene files (TOML): the atmosphere, the physics, the animation method,
//! the projection and the picture, one section type each (`atmosphere.rs`,
//! `sim::PhysicsConfig`, `simulation.rs`, `projection.rs`, `render.rs`),
//! each checking its own values. Every key
//! is listed with unit and default in `docs/scene.md` (a test checks that
//! none is missing). Errors name the file, line and key.

mod atmosphere;
mod locate;
mod projection;
mod render;
mod simulation;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use atmosphere::AtmosphereSection;
pub use locate::locate_key;
use locate::{key_at_line, line_col, plain_types};
pub use projection::ProjectionSection;
pub use render::{CpuSampling, RenderMethod, RenderSettings};
pub use simulation::{EndlessConfig, Method, SimulationSection};

use crate::sim::lift::surface_lcl_height;
use crate::sim::{Atmosphere, Band, PhysicsConfig, Sounding, SoundingError};

/// What went wrong with a scene.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    // The OS error is part of the message, not a `source`, so a report
    // that prints the error chain does not print it twice.
    #[error("{path}: cannot read scene: {err}")]
    Io { path: PathBuf, err: std::io::Error },
    #[error("{path}: cannot write scene: {err}")]
    Write { path: PathBuf, err: std::io::Error },
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
    #[error(
        "{path}: no such file; the built-in copy of this shipped scene is `--scene {name}` (a name, no path)"
    )]
    MissingShipped { path: PathBuf, name: String },
    #[error(
        "`{name}`: no scene file of that name here, and no built-in scene of it; built-in scenes: {known}"
    )]
    UnknownBuiltin { name: String, known: String },
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
    pub simulation: SimulationSection,
    pub projection: ProjectionSection,
    pub render: RenderSettings,
    /// Where the scene was read from (not a key).
    #[serde(skip)]
    pub source: Option<PathBuf>,
    #[serde(skip)]
    text: Option<String>,
}

/// The shipped scenes that need no other file, built into the library so
/// the tools also run outside the repository (BOMEX needs its sounding CSV
/// and is not among them).
pub const BUILTIN: &[(&str, &str)] = &[
    (
        "fair_weather.toml",
        include_str!("../../scenes/fair_weather.toml"),
    ),
    ("evening.toml", include_str!("../../scenes/evening.toml")),
    (
        "strong_inversion.toml",
        include_str!("../../scenes/strong_inversion.toml"),
    ),
];

impl Scene {
    /// The built-in copy of the shipped scene named `file_name` (e.g.
    /// `fair_weather.toml`), if there is one.
    pub fn builtin(file_name: &str) -> Option<Result<Self, SceneError>> {
        BUILTIN
            .iter()
            .find(|(n, _)| *n == file_name)
            .map(|(n, text)| Self::parse(text, Path::new(&format!("(built-in) scenes/{n}"))))
    }

    /// The scene a command line names: the file at `arg` when there is
    /// one; else, when `arg` is a bare name (no folder, no extension, e.g.
    /// `fair_weather`), the built-in copy of that shipped scene
    /// ([`BUILTIN`]), so the tools run outside the repository. The flag
    /// says which it was. A path that names no file is an error, never a
    /// built-in copy in its place: it says so, and names the built-in
    /// scene of the same name where there is one.
    pub fn load_or_builtin(arg: &Path) -> Result<(Self, bool), SceneError> {
        if arg.is_file() {
            return Ok((Self::load(arg)?, false));
        }
        let bare = arg.components().count() == 1 && arg.extension().is_none();
        if bare && let Some(name) = arg.to_str() {
            return match Self::builtin(&format!("{name}.toml")) {
                Some(b) => Ok((b?, true)),
                None => Err(SceneError::UnknownBuiltin {
                    name: name.to_owned(),
                    known: Self::builtin_names().join(", "),
                }),
            };
        }
        if !arg.exists()
            && let Some(stem) = arg.file_stem().and_then(|s| s.to_str())
            && arg.extension().is_some_and(|e| e == "toml")
            && Self::builtin(&format!("{stem}.toml")).is_some()
        {
            return Err(SceneError::MissingShipped {
                path: arg.to_owned(),
                name: stem.to_owned(),
            });
        }
        Ok((Self::load(arg)?, false))
    }

    /// The names of the built-in scenes, for `--scene NAME`.
    pub fn builtin_names() -> Vec<&'static str> {
        BUILTIN
            .iter()
            .map(|(n, _)| n.trim_end_matches(".toml"))
            .collect()
    }

    /// Reads, parses and validates a scene file.
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|err| SceneError::Io {
            path: path.to_owned(),
            err,
        })?;
        Self::parse(&text, path)
    }

    /// Parses and validates scene text; `path` names it in errors and
    /// anchors relative sounding paths.
    pub fn parse(text: &str, path: &Path) -> Result<Self, SceneError> {
        let mut scene: Scene = toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map(|s| line_col(text, s.start)).unwrap_or((1, 1));
            let message = plain_types(e.message().trim());
            // A type error names the key it is about (an unknown key's
            // message names the key already).
            let message = match key_at_line(text, line) {
                Some(key) if !message.contains("unknown field") => format!("`{key}`: {message}"),
                _ => message.to_owned(),
            };
            SceneError::Parse {
                path: path.to_owned(),
                line,
                column,
                message,
            }
        })?;
        scene.source = Some(path.to_owned());
        scene.text = Some(text.to_owned());
        scene.sky_as_drawn();
        scene.validate()?;
        Ok(scene)
    }

    /// The pseudo-spheroids and the endless volumes draw the analytic sky
    /// (their passes bind no sky tables), so their scenes' sky model is
    /// the analytic one whatever `[render.atmosphere] model` says: the
    /// auto-exposure meters the sky that is drawn. Metered from the
    /// physical sky, which darkens below the horizon while the analytic
    /// one does not, a sun 10° down opened the exposure 12.7 stops and
    /// burnt 83 % of the picture to white.
    fn sky_as_drawn(&mut self) {
        if self.render.renderer == RenderMethod::Spheroids
            || self.simulation.method == Method::Endless
        {
            self.render.atmosphere.model = crate::render::cpu::sky::SkyModel::Analytic;
        }
    }

    /// Checks every value against its domain, each section with its own
    /// checks; the error names the first key that fails and, when the
    /// scene came from a file, its line.
    pub fn validate(&self) -> Result<(), SceneError> {
        let checks = [
            self.physics.checks(),
            self.simulation.checks(),
            self.projection.size_checks(),
            self.render.checks(),
            self.atmosphere.override_checks(),
            self.projection.band_checks(),
            self.atmosphere.profile_checks(),
        ];
        if self.simulation.method != Method::Parcels
            && self.render.renderer == RenderMethod::Spheroids
        {
            return Err(self.invalid(
                "render.renderer",
                format!(
                    "is \"spheroids\", which draws parcels, but simulation.method = \"{}\" \
                     has none to draw: use \"cloud_map\"",
                    self.simulation.method.name()
                ),
            ));
        }
        match checks.into_iter().flatten().find(|c| !c.ok) {
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
        if let Some(here) = self.atmosphere.sounding_path(self.source.as_deref()) {
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
        crate::io::write_atomically(path, |out| out.write_all(text.as_bytes())).map_err(|err| {
            SceneError::Write {
                path: path.to_owned(),
                err,
            }
        })
    }

    /// Whether two scenes describe the same sky (every section equal, the
    /// sounding compared by the file it resolves to; the file they came
    /// from is not compared).
    pub fn same_settings(&self, other: &Scene) -> bool {
        let resolve = |s: &Scene| {
            s.atmosphere
                .sounding_path(s.source.as_deref())
                .map(|p| std::fs::canonicalize(&p).unwrap_or(p))
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
            && self.simulation == other.simulation
            && self.projection == other.projection
            && self.render == other.render
    }

    /// Builds the atmosphere (reading the sounding, relative to the scene
    /// file, if the scene names one). `sounding_override` replaces it.
    pub fn atmosphere(&self, sounding_override: Option<&Path>) -> Result<Atmosphere, SceneError> {
        let a = &self.atmosphere;
        let surface = a.surface_pressure_hpa.unwrap_or(1013.25) * 100.0;
        let sounding_path = match sounding_override {
            Some(p) => Some(p.to_owned()),
            None => a.sounding_path(self.source.as_deref()),
        };
        let from_sounding = sounding_path.is_some();
        let atm = match sounding_path {
            Some(p) => {
                let s = Sounding::load(&p, surface).map_err(|e| match e {
                    // A file that cannot be read: say which key named it.
                    SoundingError::Io { path, err } if sounding_override.is_none() => self.invalid(
                        "atmosphere.sounding",
                        format!("names {}: cannot read sounding: {err}", path.display()),
                    ),
                    e => e.into(),
                })?;
                Atmosphere::from_sounding(&s)
            }
            None => Atmosphere::from_parametric(&a.parametric.unwrap_or_default()),
        };
        let atm = match a.inversion_base_m {
            Some(z) => atm.with_inversion_base(z),
            None => atm,
        };
        self.check_within(&atm, from_sounding)?;
        Ok(atm)
    }

    /// The parcels' release and the cloud band lie within the atmosphere
    /// `atm`, below its top, where its table ends and the parcels stop:
    /// parcels released above it, or a band above it, simulated quietly
    /// into a sky without clouds (a sounding that ends at 100 m, a
    /// parametric `top_m` under the inversion). The error names the key
    /// the user wrote where there is one, else the atmosphere's
    /// (`from_sounding`: a sounding's, the scene's or `--sounding`'s).
    fn check_within(&self, atm: &Atmosphere, from_sounding: bool) -> Result<(), SceneError> {
        let top = atm.top_m();
        let (atm_key, atm_top) = if from_sounding {
            ("atmosphere.sounding", "the sounding's highest level")
        } else {
            (
                "atmosphere.parametric.top_m",
                "`atmosphere.parametric.top_m`",
            )
        };
        if self.physics.release_height_m >= top {
            return Err(self.invalid(
                "physics.release_height_m",
                format!(
                    "is {}, expected below the atmosphere's top at {top} m ({atm_top})",
                    crate::sim::check::number(self.physics.release_height_m)
                ),
            ));
        }
        // A parametric inversion at or above the parametric top is not in
        // the table at all: the band would quietly fall back to its
        // default. Blamed on whichever of the two keys the file sets.
        let written = |k| {
            self.text
                .as_deref()
                .and_then(|t| locate_key(t, k))
                .is_some()
        };
        if let (false, None, Some(pp)) = (
            from_sounding,
            self.atmosphere.inversion_base_m,
            self.atmosphere.parametric,
        ) && pp.inversion_base_m >= pp.top_m
        {
            let key = if written("atmosphere.parametric.top_m")
                || !written("atmosphere.parametric.inversion_base_m")
            {
                "atmosphere.parametric.top_m"
            } else {
                "atmosphere.parametric.inversion_base_m"
            };
            return Err(self.invalid(
                key,
                format!(
                    "the inversion (inversion_base_m {} m) lies at or above the atmosphere's \
                     top (top_m {} m): lower the inversion or raise the top",
                    pp.inversion_base_m, pp.top_m
                ),
            ));
        }
        let band = self.band(atm);
        let bottom_key = match self.projection.band_bottom_m {
            Some(_) => "projection.band_bottom_m",
            None => atm_key,
        };
        if band.bottom_m >= top {
            return Err(self.invalid(
                bottom_key,
                format!(
                    "the cloud band starts at {} m, at or above the atmosphere's top at {top} m \
                     ({atm_top}): the parcels cannot rise into it",
                    band.bottom_m
                ),
            ));
        }
        if band.top_m > top {
            // The key that set the band's top ([`Self::band`]): the
            // band's own, else the inversion's (the scene's override, the
            // parametric profile's, a sounding's own); the default top
            // is held within the atmosphere.
            let key = match (self.projection.band_top_m, self.atmosphere.inversion_base_m) {
                (Some(_), _) => "projection.band_top_m",
                (None, Some(_)) => "atmosphere.inversion_base_m",
                (None, None) => atm_key,
            };
            return Err(self.invalid(
                key,
                format!(
                    "the cloud band reaches {} m, above the atmosphere's top at {top} m \
                     ({atm_top}), where the parcels stop",
                    band.top_m
                ),
            ));
        }
        Ok(())
    }

    /// The cloud band: the scene's values, else the surface air's LCL to the
    /// inversion base (LCL + 1500 m without an inversion, at most to the
    /// atmosphere's top: a short sounding's band ends with it).
    pub fn band(&self, atm: &Atmosphere) -> Band {
        let lcl = surface_lcl_height(atm).unwrap_or(500.0);
        let bottom = self.projection.band_bottom_m.unwrap_or(lcl);
        let top = self
            .projection
            .band_top_m
            .or(atm.inversion_base_m().filter(|&z| z > bottom + 50.0))
            .unwrap_or((bottom + 1500.0).min(atm.top_m()));
        Band {
            bottom_m: bottom,
            top_m: top.max(bottom + 1.0),
        }
    }
}

#[cfg(test)]
mod tests;
