//! The public parameter and data types: the volume, the transfer function, the view
//! (camera, lights), per-frame render parameters, isosurfaces, path tracing, the
//! environment. Plain data with validation; nothing here touches the GPU.

pub mod camera;
mod check;
pub(crate) mod downsample;
pub mod environment;
pub mod intermix;
pub mod iso;
pub mod light;
pub mod pathtrace;
pub mod render;
pub mod transfer;
pub mod unstructured;
pub mod view;
pub mod volume;

pub use camera::Camera;
pub use environment::{CubeImage, Environment, EnvironmentSource, Sky};
pub use intermix::{IntermixedVolume, MAX_INTERMIXED_VOLUMES};
pub use iso::{
    AmbientOcclusion, GBuffer, Hit, IsoParams, IsoScatterMode, IsoScattering, IsoValue, Shininess,
    SpecularMode, MAX_ISO_VALUES, MAX_SCATTER_SAMPLES,
};
pub use light::{Light, LightSpace};
pub use pathtrace::{BsdfParams, Convergence, PathTraceParams, ScatterRegions};
pub use render::{
    BlendMode, ClipPlane, Cropping, GradientMethod, Interpolation, Quadrature, RenderParams,
    Shading, ADAPTIVE_STEP_TOLERANCE, MAX_CLIP_PLANES, MAX_LIGHTS,
};
pub(crate) use transfer::{build_preintegration, build_tables, build_tables_over};
pub use transfer::{
    ComponentTransfer, LabelTransfer, Piecewise, Table2D, TransferFunction, MAX_TRANSFER_POSITION,
    TABLE_SIZE,
};
pub use unstructured::{vtk_cell_type_name, CellType, ScalarLocation, UnstructuredVolume};
pub use view::{Image, Residency, Stats, StreamProgress, UploadOptions, View};
pub use volume::{
    Direction, MaskKind, ScalarSource, ScalarType, Scalars, VolumeData, IDENTITY_DIRECTION,
};
