//! The paper's published numbers that our figures and reports set beside ours (Meinert et
//! al., Sec. "Monte Carlo Simulation"): one place, cited by the Monte Carlo report, the
//! runtime and latency figures and `bench filters`.

/// Geometric mean of the whole safety layer's solve time per step [ms].
pub const PAPER_TOTAL_GEOMEAN_MS: f64 = 1.59;
/// Largest solve time of the whole safety layer per step [ms].
pub const PAPER_TOTAL_MAX_MS: f64 = 3.75;
/// Every single filter's QP stays below this [ms].
pub const PAPER_COMPONENT_MAX_MS: f64 = 2.3;
/// Peak synchronisation error during grasping (phase III) over the campaign [rad/s].
pub const PAPER_SYNC_GRASP_RAD_S: (f64, f64) = (0.0432, 0.0457);
/// Synchronisation errors up to this during the synchronisation phase (II) [rad/s].
pub const PAPER_SYNC_SYNC_RAD_S: f64 = 0.3;
