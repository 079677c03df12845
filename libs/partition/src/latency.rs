//! Latency statistics of a partition run (filled in by `bench latency`).
