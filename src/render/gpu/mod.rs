//! The wgpu renderer: the cloud band ray-cast in WGSL with TSAA, as a
//! library to embed in a wgpu application ([`CloudRenderer`]), plus a
//! headless path for `cumulus render --backend gpu` and the tests.

mod bind;
mod cloud_pass;
mod composite_pass;
pub mod context;
mod frame_checks;
pub mod headless;
mod inputs;
pub mod light_volume_pass;
pub mod renderer;
pub mod requirements;
pub mod settings;
pub mod shaders;
pub mod sky_luts_pass;
pub mod spheroids;
mod standalone;
pub mod terrain_pass;
pub mod textures;
pub mod timer;
pub mod tsaa;
pub mod uniforms;
pub mod volume_pass;

pub use composite_pass::is_hdr;
pub use context::{GpuContext, GpuError};
pub use headless::Headless;
pub use renderer::{CloudRenderer, FrameUse, RenderError};
pub use settings::GpuSettings;
pub use tsaa::TsaaSettings;
