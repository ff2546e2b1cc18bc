//! The GPU layer: the device context, binding helpers, shader composition, pipelines and
//! their cache, the Rust mirrors of the WGSL uniforms and constants, texture uploads,
//! readback (waiting, or one frame late through a ring), the device time of submissions and
//! the memory export that shares the output with OpenGL. It knows nothing of
//! volumes or passes. Without the `gpu` feature only the uniforms' constants are compiled:
//! the data model's limits come from them.

#[cfg(feature = "gpu")]
pub(crate) mod binding;
#[cfg(feature = "gpu")]
pub(crate) mod buffers;
#[cfg(feature = "gpu")]
pub(crate) mod context;
#[cfg(feature = "gpu")]
pub(crate) mod disk_cache;
#[cfg(feature = "gpu")]
pub mod interop;
#[cfg(feature = "gpu")]
pub(crate) mod pipeline;
#[cfg(feature = "gpu")]
pub(crate) mod readback;
#[cfg(feature = "gpu")]
pub(crate) mod shaders;
#[cfg(feature = "gpu")]
pub(crate) mod slots;
#[cfg(feature = "gpu")]
pub(crate) mod specialise;
#[cfg(feature = "gpu")]
pub(crate) mod texture;
#[cfg(feature = "gpu")]
pub(crate) mod timing;
pub(crate) mod uniforms;

#[cfg(feature = "gpu")]
pub use context::{Context, DeviceInfo, DeviceMemory};
