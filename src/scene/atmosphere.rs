//! `[atmosphere]`: a sounding file or a parametric profile, and what
//! overrides them.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::sim::{Check, ParametricProfile};

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

impl AtmosphereSection {
    /// The optional overrides, when given, against their domains.
    pub fn override_checks(&self) -> Vec<Check> {
        [
            (
                "atmosphere.surface_pressure_hpa",
                self.surface_pressure_hpa,
                300.0,
                1100.0,
                "300..=1100 hPa",
            ),
            (
                "atmosphere.inversion_base_m",
                self.inversion_base_m,
                0.0,
                1e5,
                "0..=1e5 m",
            ),
        ]
        .into_iter()
        .filter_map(|(key, v, lo, hi, expected)| v.map(|v| Check::range(key, v, lo, hi, expected)))
        .collect()
    }

    /// The parametric profile's fields, and that it is not given together
    /// with a sounding.
    pub fn profile_checks(&self) -> Vec<Check> {
        let Some(pp) = &self.parametric else {
            return Vec::new();
        };
        let mut checks = pp.checks("atmosphere.parametric.");
        if self.sounding.is_some() {
            checks.push(Check {
                key: "atmosphere.sounding".into(),
                ok: false,
                expected: "either a sounding or [atmosphere.parametric], not both".into(),
                value: "both given".into(),
            });
        }
        checks
    }

    /// The sounding's path as the scene names it, resolved against the
    /// directory of the scene file `scene_file` (when known).
    pub fn sounding_path(&self, scene_file: Option<&Path>) -> Option<PathBuf> {
        self.sounding.as_ref().map(|rel| {
            scene_file
                .and_then(Path::parent)
                .map(|d| d.join(rel))
                .unwrap_or_else(|| rel.clone())
        })
    }
}
