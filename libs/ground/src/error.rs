//! Why a ground tool of the partition could not do its job (one line each).

use crate::launcher::LaunchError;
use std::path::Path;

/// The latency bench's and the hop-cost measurement's errors.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error(transparent)]
    Launch(#[from] LaunchError),
    /// SIGINT/SIGTERM stopped the run: no report (a partial one would pass for a
    /// qualification measurement).
    #[error("interrupted by SIGINT/SIGTERM before the {planned} ticks were measured")]
    Interrupted { planned: u64 },
    #[error(transparent)]
    Bus(#[from] sc_bus::BusError),
    #[error(transparent)]
    Plot(#[from] sc_plots::PlotError),
    #[error("cannot read {path}: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("cannot write {path}: {source}")]
    Write {
        path: String,
        source: std::io::Error,
    },
    /// A file of the run, or a measurement, is not what it should be.
    #[error("{0}")]
    Data(String),
}

impl BenchError {
    pub(crate) fn read(path: &Path) -> impl Fn(std::io::Error) -> Self + '_ {
        move |source| BenchError::Read {
            path: path.display().to_string(),
            source,
        }
    }

    pub(crate) fn write(path: &Path) -> impl Fn(std::io::Error) -> Self + '_ {
        move |source| BenchError::Write {
            path: path.display().to_string(),
            source,
        }
    }
}
