//! `[simulation]`: which method animates the clouds. The parcels (the
//! cloud-map paper's physics, `[physics]`) are the default; the cellular
//! automaton (`sim::automaton`, `[simulation.automaton]`) and the endless
//! playback of precomputed volumes (`crate::endless`,
//! `[simulation.endless]`) are the others.

use serde::{Deserialize, Serialize};

use crate::sim::Check;
use crate::sim::automaton::AutomatonConfig;

/// The animation method (`[simulation] method`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Rising air parcels with SPH (Goswami 2019), projected into P.
    #[default]
    Parcels,
    /// Dobashi's cellular automaton (after Qin & Lv), projected into P.
    Automaton,
    /// The parcels simulated ahead into a database of density volumes,
    /// played back endlessly (Iwasaki, Nishino & Dobashi 2011).
    Endless,
}

impl Method {
    /// The name the scene file uses.
    pub fn name(self) -> &'static str {
        match self {
            Method::Parcels => "parcels",
            Method::Automaton => "automaton",
            Method::Endless => "endless",
        }
    }
}

/// `[simulation]`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimulationSection {
    /// `"parcels"` (default), `"automaton"` or `"endless"`.
    pub method: Method,
    /// The automaton's settings (read only by `method = "automaton"`).
    pub automaton: AutomatonConfig,
    /// The volume database's settings (read only by `method = "endless"`).
    pub endless: EndlessConfig,
}

/// `[simulation.endless]`: the database of volumes and its playback.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EndlessConfig {
    /// Volumes in the database (2..=256). Default 24.
    pub volumes: usize,
    /// Seconds of sky between stored volumes (1..=600); playback blends
    /// between them. Default 30.
    pub interval_s: f64,
    /// Voxels of each volume along x, y (up) and z (each 2..=512, and
    /// `y · volumes` at most 2048: they are stacked in one 3D texture).
    /// Default `[192, 32, 192]`.
    pub cells: [u32; 3],
    /// The transition temperature σ as a multiple of the mean distance
    /// between consecutive volumes (> 0): small, only near-identical
    /// volumes follow each other (few jumps, short loops); large, any
    /// volume may follow any (visible jumps). Default 0.5.
    pub similarity: f64,
    /// Where the database is kept, relative to the scene file: read when
    /// it was made for these settings, else built and written there.
    /// Default: none (built in memory each run).
    pub database: Option<std::path::PathBuf>,
}

impl Default for EndlessConfig {
    fn default() -> Self {
        Self {
            volumes: 24,
            interval_s: 30.0,
            cells: [192, 32, 192],
            similarity: 0.5,
            database: None,
        }
    }
}

impl EndlessConfig {
    /// The database file, relative to the scene file's directory.
    pub fn database_path(
        &self,
        scene_file: Option<&std::path::Path>,
    ) -> Option<std::path::PathBuf> {
        self.database.as_ref().map(|rel| {
            scene_file
                .and_then(std::path::Path::parent)
                .map(|d| d.join(rel))
                .unwrap_or_else(|| rel.clone())
        })
    }

    /// Every field against its domain.
    pub fn checks(&self) -> Vec<Check> {
        let [x, y, z] = self.cells;
        vec![
            Check::new(
                "simulation.endless.volumes",
                (2..=256).contains(&self.volumes),
                "2..=256 volumes",
                self.volumes as f64,
            ),
            Check::range(
                "simulation.endless.interval_s",
                self.interval_s,
                1.0,
                600.0,
                "1..=600 s",
            ),
            Check::new(
                "simulation.endless.cells",
                [x, y, z].iter().all(|n| (2..=512).contains(n))
                    && (y as usize).saturating_mul(self.volumes) <= 2048,
                "2..=512 voxels each, with cells[1] * volumes <= 2048",
                (x as f64) * (y as f64) * (z as f64),
            ),
            Check::new(
                "simulation.endless.similarity",
                self.similarity.is_finite() && self.similarity > 0.0,
                "a multiple > 0",
                self.similarity,
            ),
        ]
    }
}

impl SimulationSection {
    /// Every key against its domain.
    pub fn checks(&self) -> Vec<Check> {
        let mut c = self.automaton.checks("simulation.automaton");
        c.extend(self.endless.checks());
        c
    }
}
