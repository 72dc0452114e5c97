//! Reports built on the simulator and the renderer: parcel curves (the
//! paper's Fig. 5) as CSV, error against run time and against render
//! cost, GPU benchmarks, field statistics, and the density volume for
//! offline renderers.

pub mod convergence;
pub mod curves;
pub mod field_stats;
pub mod gpu_bench;
pub mod plot;
pub mod render_quality;
pub mod still_quality;
pub mod vdb;
pub mod volume_export;

/// What went wrong writing a report.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("{path}: cannot write: {source}")]
    Write {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    #[error("plot {path}: {message}")]
    Plot {
        path: std::path::PathBuf,
        message: String,
    },
}

impl ReportError {
    /// The error constructor for a failed write of `path` (for `map_err`).
    pub fn writing(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> Self + use<> {
        let path = path.to_owned();
        move |source| Self::Write { path, source }
    }
}
