//! Rendering: the cloud map, the terrain, the wgpu renderer and its twin,
//! the CPU reference renderer (the oracle the GPU is tested against and
//! the fallback without a GPU). Sees the simulation only through P
//! (`sim::ProjectedField`, `sim::Band`).

pub mod camera;
pub mod cloud_map;
pub mod coverage_mask;
pub mod cpu;
pub mod gpu;
pub mod noise_volume;
pub mod sampling;
pub mod soft_field;
pub mod terrain;
