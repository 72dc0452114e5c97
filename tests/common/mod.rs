//! What the GPU tests share: one adapter probe with one skip rule.

use cumulus::render::gpu::{GpuContext, GpuError};

/// The first GPU adapter wgpu finds. Without one the test prints
/// `SKIPPED: no GPU adapter` and returns `None`, unless
/// `CUMULUS_REQUIRE_GPU=1` (set by `.ci/run`), which fails it.
pub fn gpu() -> Option<GpuContext> {
    match GpuContext::new(wgpu::Backends::all()) {
        Ok(c) => {
            eprintln!("adapter: {}", c.describe());
            Some(c)
        }
        Err(GpuError::NoAdapter) => {
            if std::env::var("CUMULUS_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("CUMULUS_REQUIRE_GPU=1 but no GPU adapter was found");
            }
            eprintln!("SKIPPED: no GPU adapter");
            None
        }
        Err(e) => panic!("GPU device: {e}"),
    }
}
