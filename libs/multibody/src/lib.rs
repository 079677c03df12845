//! The servicer as a free-flying multibody system loaded from URDF.
