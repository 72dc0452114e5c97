//! The CPU parcel simulator. Depends on nothing graphical (no wgpu, winit
//! or egui): researchers can use it on its own.

pub mod atmosphere;
pub mod automaton;
pub mod budget;
pub mod check;
pub mod config;
pub mod constants;
pub mod kernels;
pub mod lift;
pub mod parametric;
pub mod parcels;
pub mod projection;
pub mod records;
pub mod solver;
pub mod sounding;
pub mod sounding_formats;
mod spawn;
pub mod sph;
pub mod thermo;
mod update;

pub use atmosphere::{Atmosphere, EnvSample, ParametricProfile};
pub use budget::WaterBudget;
pub use check::Check;
pub use config::PhysicsConfig;
pub use parcels::Parcels;
pub use projection::{Band, ProjectedField};
pub use records::ParcelRecord;
pub use solver::{FramePlan, Simulation, StepStats, Totals};
pub use sounding::{Sounding, SoundingError};
pub use update::wind_at;
