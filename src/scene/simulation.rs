//! `[simulation]`: which method animates the clouds. The parcels (the
//! cloud-map paper's physics, `[physics]`) are the default; the cellular
//! automaton (`sim::automaton`, `[simulation.automaton]`) is the other.

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
}

impl Method {
    /// The name the scene file uses.
    pub fn name(self) -> &'static str {
        match self {
            Method::Parcels => "parcels",
            Method::Automaton => "automaton",
        }
    }
}

/// `[simulation]`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimulationSection {
    /// `"parcels"` (default) or `"automaton"`.
    pub method: Method,
    /// The automaton's settings (read only by `method = "automaton"`).
    pub automaton: AutomatonConfig,
}

impl SimulationSection {
    /// Every key against its domain.
    pub fn checks(&self) -> Vec<Check> {
        self.automaton.checks("simulation.automaton")
    }
}
