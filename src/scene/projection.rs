//! `[projection]`: the size of the texture P and the cloud band the
//! parcels are projected over.

use serde::{Deserialize, Serialize};

use crate::sim::Check;

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

impl ProjectionSection {
    /// P's size against its domain.
    pub fn size_checks(&self) -> Vec<Check> {
        vec![
            Check::new(
                "projection.width",
                (1..=4096).contains(&self.width),
                "1..=4096 texels",
                self.width as f64,
            ),
            Check::new(
                "projection.height",
                (1..=4096).contains(&self.height),
                "1..=4096 texels",
                self.height as f64,
            ),
        ]
    }

    /// The band's bottom and top, when given, against their domains.
    pub fn band_checks(&self) -> Vec<Check> {
        let mut checks: Vec<Check> = [
            ("projection.band_bottom_m", self.band_bottom_m, "0..=1e5 m"),
            (
                "projection.band_top_m",
                self.band_top_m,
                "0..=1e5 m and above band_bottom_m",
            ),
        ]
        .into_iter()
        .filter_map(|(key, v, expected)| v.map(|v| Check::range(key, v, 0.0, 1e5, expected)))
        .collect();
        if let (Some(b), Some(t)) = (self.band_bottom_m, self.band_top_m) {
            checks.push(Check::new(
                "projection.band_top_m",
                t > b,
                "above band_bottom_m",
                t,
            ));
        }
        checks
    }
}
