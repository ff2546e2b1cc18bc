//! The passes of a frame. Each owns its pipelines (and any state of its own, such as the
//! path tracer's accumulation) and borrows the renderer's resources for the frame; none
//! reaches back into the renderer.

pub(crate) mod denoise;
pub(crate) mod depth_check;
pub(crate) mod dvr;
pub(crate) mod dvr_variant;
pub(crate) mod frame;
pub(crate) mod iso;
pub(crate) mod iso_variant;
pub(crate) mod medium;
pub(crate) mod pathtrace;
pub(crate) mod pathtrace_variant;
pub(crate) mod scatter_check;
pub(crate) mod unstructured;
pub(crate) mod unstructured_variant;

#[cfg(test)]
mod layout_tests;
