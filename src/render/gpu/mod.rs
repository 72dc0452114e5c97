//! The wgpu renderer: the cloud band ray-cast in WGSL with TSAA, as a
//! library to embed in a wgpu application ([`CloudRenderer`]), plus a
//! headless path for `cumulus render --backend gpu` and the tests.

pub mod renderer;
pub mod shaders;
pub mod textures;
pub mod timer;
pub mod tsaa;
pub mod uniforms;

pub use renderer::{CloudRenderer, GpuSettings, RenderError};
pub use tsaa::TsaaSettings;
pub mod baseline;
pub mod context;
pub mod headless;

pub use context::{GpuContext, GpuError};
pub use headless::Headless;
