//! Reference nominal controllers.
