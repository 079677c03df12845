//! High-fidelity simulator core.
