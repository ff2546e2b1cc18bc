//! ferrovol-core: GPU volume ray casting on wgpu.
//!
//! Knows nothing of VTK, C or files: volumes arrive as [`VolumeData`], images leave as
//! premultiplied RGBA ([`Image`]) or stay on the GPU ([`Renderer::output_texture`]).
//!
//! ```no_run
//! use ferrovol_core::*;
//! let vol = synth::marschner_lobb(41);
//! let mut r = Renderer::new(Context::new()?)?;
//! r.set_volume(&vol)?;
//! r.set_transfer_function(&TransferFunction::ramp([0.0, 1.0], 0.3))?;
//! let view = View::fit(vol.bounds(), 256, 256);
//! let img = r.render_image(&view, &RenderParams::default())?;
//! assert_eq!(img.rgba.len(), 4 * 256 * 256);
//! # Ok::<(), ferrovol_core::Error>(())
//! ```

//!
//! Without the default feature `gpu` the crate is its data model alone (the [`params`] and
//! [`synth`] modules), with no GPU stack to build.

// Without the renderer, the data model's GPU-facing helpers (the uniforms' mirrors, table
// builders, shader codes) have no caller; the default build lints them all.
#![cfg_attr(not(feature = "gpu"), allow(dead_code, unused_imports))]

pub mod error;
mod gpu;
pub mod params;
#[cfg(feature = "gpu")]
mod passes;
#[cfg(feature = "gpu")]
pub mod renderer;
#[cfg(feature = "gpu")]
mod resources;
pub mod synth;

pub use error::{Error, Result};
#[cfg(feature = "gpu")]
pub use gpu::interop::{self, DeviceUuids, OutputPath, SharedImage, SharedTargets};
#[cfg(feature = "gpu")]
pub use gpu::{Context, DeviceInfo, DeviceMemory};
pub use params::environment::{cube_direction, cube_face_coords, FACE_NAMES};
pub use params::*;
#[cfg(feature = "gpu")]
pub use renderer::Renderer;
#[cfg(feature = "gpu")]
pub use resources::mesh::{tetrahedralize, Tetrahedra};
