//! Rendering: the cloud map, and the CPU reference renderer (the oracle
//! and fallback that the wgpu renderer will be tested against).

pub mod cloud_map;
pub mod coverage_mask;
pub mod cpu;
pub mod gpu;
pub mod prepare;
pub mod terrain;
