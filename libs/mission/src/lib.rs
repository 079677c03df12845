//! The mission in one process: phases, telemetry, summary.
