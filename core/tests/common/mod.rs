//! Test support shared by the GPU test binaries (render, iso, pathtrace,
//! pathtrace_reference, interop): the device and what the tests expect of it, test scenes,
//! the f64 CPU references of the ray caster and the path tracer, image metrics and the test
//! images.
//!
//! Each binary compiles this module for itself and uses only part of it: what one binary
//! leaves unused another uses, hence the `allow`.
#![allow(dead_code)]

pub mod gpu;
pub mod images;
pub mod mesh;
pub mod metrics;
pub mod pathtracer;
pub mod raycast;
pub mod scenes;
