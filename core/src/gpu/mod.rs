//! The GPU layer: the device context, binding helpers, shader composition, pipelines and
//! their cache, the Rust mirrors of the WGSL uniforms and constants, texture uploads,
//! readback (waiting, or one frame late through a ring), the device time of submissions and
//! the memory export that shares the output with OpenGL. It knows nothing of
//! volumes or passes.

pub(crate) mod binding;
pub(crate) mod buffers;
pub(crate) mod context;
pub(crate) mod disk_cache;
pub mod interop;
pub(crate) mod pipeline;
pub(crate) mod readback;
pub(crate) mod shaders;
pub(crate) mod slots;
pub(crate) mod specialise;
pub(crate) mod texture;
pub(crate) mod timing;
pub(crate) mod uniforms;

pub use context::{Context, DeviceInfo, DeviceMemory};
