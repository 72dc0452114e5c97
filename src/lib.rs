//! # cumulus
//!
//! Physics-driven cumulus clouds after Goswami, "Interactive animation of
//! single-layer cumulus clouds using cloud map" (STAG 2019): a CPU SPH parcel
//! simulator ([`sim`]) whose parcels rise by buoyancy against an implicit
//! atmosphere, condense, entrain and detrain, and are projected each step
//! into a small 2D texture P ([`sim::ProjectedField`]) that a renderer reads.
//!
//! ```
//! use cumulus::sim::{Atmosphere, ParametricProfile, PhysicsConfig, ProjectedField, Simulation};
//!
//! let atm = Atmosphere::from_parametric(&ParametricProfile::FAIR_WEATHER);
//! let mut sim = Simulation::new(PhysicsConfig::default(), atm);
//! for _ in 0..10 {
//!     sim.step();
//! }
//! let mut p = ProjectedField::new(64, 64);
//! let band = cumulus::sim::Band { bottom_m: 600.0, top_m: 1500.0 };
//! sim.project_into(&mut p, band);
//! assert!(sim.parcels().pos.iter().all(|x| x.is_finite()));
//! ```

pub mod endless;
pub mod io;
pub mod panel;
pub mod prepare;
pub mod render;
pub mod report;
pub mod scene;
pub mod sim;
