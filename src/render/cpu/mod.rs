//! The CPU reference renderer. Each module's functions that the GPU also
//! runs have a WGSL twin of the same name in `shaders/<module>.wgsl`
//! (`tests/shader_twins.rs`): pure functions on plain `f32` data and glam
//! vectors.
//!
//! World frame: `x` east, `y` up, `z` north, metres. The physics domain's
//! `(x, y)` maps to the world's `(x, z)`; P and the cloud map both span
//! `map_extent_m` and repeat to the horizon, looked up through a
//! non-periodic warp outside the simulated domain (`density::domain_warp`).

pub mod cirrus;
pub mod density;
pub mod density_grid;
pub mod exposure;
pub mod frame;
pub mod glare;
pub mod land;
pub mod light_grid;
pub mod light_transport;
pub mod light_volume;
pub mod lighting;
pub mod renderer;
pub mod sea;
pub mod sky;
pub mod sky_luts;
pub mod spheroids;
pub mod standalone;
pub mod still_reconstruction;
pub mod stills;
pub mod tone_map;
pub mod volume;
pub mod waves;
