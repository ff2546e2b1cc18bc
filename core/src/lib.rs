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
//! img.save_png("ml.png".as_ref(), [0.0; 3])?;
//! # Ok::<(), ferrovol_core::Error>(())
//! ```

mod binding;
pub mod camera;
pub mod device;
pub mod environment;
pub mod error;
pub mod gpu;
pub mod interop;
pub mod iso;
pub mod light;
pub mod params;
pub mod pathtrace;
mod readback;
pub mod renderer;
pub mod shaders;
pub mod synth;
pub mod transfer;
pub mod upload;
pub mod volume;

pub use camera::Camera;
pub use device::{Context, DeviceInfo};
pub use environment::{CubeImage, Environment, EnvironmentSource, Sky};
pub use error::{Error, Result};
pub use interop::{DeviceUuids, OutputPath, SharedImage, SharedOutput};
pub use iso::{
    AmbientOcclusion, GBuffer, Hit, IsoParams, IsoScatterMode, IsoScattering, IsoValue, Shininess,
    SpecularMode, MAX_SCATTER_SAMPLES,
};
pub use light::{Light, LightSpace};
pub use params::{
    BlendMode, ClipPlane, Cropping, GradientMethod, Interpolation, RenderParams, Shading,
};
pub use pathtrace::{BsdfParams, PathTraceParams, ScatterRegions};
pub use renderer::{Image, Renderer, Stats, UploadOptions, View};
pub use transfer::{ComponentTransfer, Piecewise, TransferFunction};
pub use volume::{Direction, ScalarType, Scalars, VolumeData, IDENTITY_DIRECTION};
