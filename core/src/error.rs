//! The one error type of ferrovol-core. Every message says what was wrong and, where it
//! helps, what to do.

/// Errors from the renderer core.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// No wgpu adapter matched (or none exists at all).
    #[error("no GPU adapter found{0}; install a Vulkan driver (Debian: mesa-vulkan-drivers libvulkan1 for the CPU device lavapipe) or relax FERROVOL_ADAPTER / FERROVOL_BACKEND")]
    NoAdapter(String),
    /// The adapter refused to create a device.
    #[error("could not create a GPU device on adapter '{adapter}': {message}")]
    RequestDevice { adapter: String, message: String },
    /// The volume description is inconsistent or not renderable.
    #[error("invalid volume: {0}")]
    InvalidVolume(String),
    /// A volume's scalar source failed to read (a file that shrank, an I/O error).
    #[error("reading the volume's data failed: {0}")]
    Source(String),
    /// A transfer function is malformed.
    #[error("invalid transfer function: {0}")]
    InvalidTransferFunction(String),
    /// A render parameter is out of range.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// The device lacks something this request needs.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// The GPU reported an error other than the two below (validation, shader compilation).
    #[error("GPU error: {0}")]
    Gpu(String),
    /// A GPU allocation failed: use a smaller volume, image or brick size.
    #[error("out of GPU memory: {0}")]
    OutOfMemory(String),
    /// The device was lost (driver reset, GPU removed): create a new context.
    #[error("GPU device lost: {0}; create a new context")]
    DeviceLost(String),
}

pub type Result<T> = std::result::Result<T, Error>;
