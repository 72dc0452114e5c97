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

//! The crate's features: the physics ([`sim`], [`io`]) is always there;
//! `render` adds the renderers, the scene files, the preparation of a
//! frame and the endless player; `images` the PNG and OpenEXR writers;
//! `cli` (the default) all of it with the reports and the `cumulus`
//! binary.

#[cfg(feature = "render")]
pub mod endless;
pub mod io;
#[cfg(feature = "render")]
pub mod panel;
#[cfg(feature = "render")]
pub mod prepare;
#[cfg(feature = "render")]
pub mod render;
#[cfg(feature = "cli")]
pub mod report;
#[cfg(feature = "render")]
pub mod scene;
pub mod sim;
