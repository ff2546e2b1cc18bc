//! Plain-data structs and enums crossing the C ABI, and their conversion into core types.
//! Enum-valued fields travel as `uint32_t` so that a value outside the enum is an
//! FV_STATUS_INVALID_ARGUMENT, not undefined behaviour.

use crate::status::{FfiError, FfiResult};
use ferrovol_core::{
    BlendMode, Camera, ClipPlane, Cropping, GradientMethod, Interpolation, Light, LightSpace,
    MaskKind, Quadrature, RenderParams, Shading,
};
use glam::{DMat4, DVec3};

/// Where a renderer's frames go (fv_renderer_set_output_path).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvOutputPath {
    /// Frames stay in GPU memory private to ferrovol; read them with fv_renderer_read_frame.
    Readback = 0,
    /// Frames are drawn into memory exported to the host's graphics API (zero copy).
    Shared = 1,
}

/// The images of the shared output path (fv_renderer_shared_image).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvTarget {
    /// Premultiplied RGBA8 colour (GL_RGBA8).
    Color = 0,
    /// Window depth of the volume, 1 where transparent (GL_R32F).
    Depth = 1,
    /// Window depth of the host's opaque geometry, written by the host (GL_R32F), read by
    /// fv_renderer_render_with_shared_depth.
    DepthInput = 2,
}

/// One exported image, for glCreateMemoryObjectsEXT + glImportMemoryFdEXT(size,
/// GL_HANDLE_TYPE_OPAQUE_FD_EXT, fd) + glTexStorageMem2DEXT(GL_TEXTURE_2D, 1,
/// gl_internal_format, width, height, memory, 0) with GL_TEXTURE_TILING_EXT =
/// GL_OPTIMAL_TILING_EXT and GL_DEDICATED_MEMORY_OBJECT_EXT = GL_TRUE when `dedicated`.
/// Rows are top to bottom (row 0 is the top of the frame). Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct FvSharedImage {
    /// A new file descriptor owned by the caller: glImportMemoryFdEXT takes it over on
    /// success; otherwise close() it.
    pub fd: i32,
    /// Allocation size in bytes (pass it to glImportMemoryFdEXT).
    pub size: u64,
    pub width: u32,
    pub height: u32,
    /// GL_RGBA8 (0x8058) or GL_R32F (0x822E).
    pub gl_internal_format: u32,
    pub dedicated: bool,
    /// Changes whenever the images are reallocated (new size, path switched): the host
    /// then deletes its imported textures and memory objects and imports again.
    pub generation: u64,
}

/// Scalar types of volume data (VTK's VTK_UNSIGNED_CHAR … VTK_DOUBLE). 64-bit integers
/// are converted to double on upload (exact up to 2^53).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvScalarType {
    U8 = 0,
    I8 = 1,
    U16 = 2,
    I16 = 3,
    U32 = 4,
    I32 = 5,
    F32 = 6,
    F64 = 7,
    I64 = 8,
    U64 = 9,
}

/// How samples along a ray combine (vtkVolumeMapper's blend modes).
/// What a mask's values mean (vtkGPUVolumeRayCastMapper's MaskType).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvMaskType {
    /// Ray casting leaves out the samples whose nearest point holds 0 (every blend mode).
    Binary = 0,
    /// Each point's value is its label: composite ray casting of a one-component volume
    /// classifies a sample labelled 1 to 255 with that label's functions, as VTK does.
    LabelMap = 1,
}

/// The mask kind an FvMaskType value (as a C caller passes it) names.
pub fn mask_kind(v: u32) -> FfiResult<MaskKind> {
    enum_value("mask type", v, &[MaskKind::Binary, MaskKind::LabelMap])
}

#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvBlendMode {
    Composite = 0,
    Maximum = 1,
    Minimum = 2,
    Average = 3,
    Additive = 4,
    /// Isosurfaces (fv_renderer_set_isosurface): first hit with bisection, deferred
    /// shading with environment light and ambient occlusion.
    Isosurface = 5,
    /// Progressive Monte Carlo path tracing of the volume as a scattering medium
    /// (fv_renderer_set_path_tracing; each frame adds paths to the ones before).
    PathTrace = 6,
    /// VTK's slice blend mode: each pixel shows where its ray meets
    /// FvRenderParams::slice_plane (world coordinates), the transfer function's colour and
    /// opacity there without step correction, and that point's depth.
    Slice = 7,
}

/// Volume interpolation (vtkVolumeProperty::InterpolationType).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvInterpolation {
    Nearest = 0,
    Linear = 1,
    /// The cubic B-spline of the points (not prefiltered: smooths at the scale of a voxel),
    /// in ray casting and isosurfaces; path tracing answers FV_STATUS_UNSUPPORTED.
    Cubic = 2,
}

/// How ray casting places its samples along a ray (FvRenderParams.quadrature).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvQuadrature {
    /// VTK 9.2's lattice: the first sample one step in, each standing for a whole step.
    Vtk = 0,
    /// Samples in the middle of their steps and the path through the volume exact (the
    /// last, shorter step sampled at its middle): second order in the step. Not with
    /// jittering or whole_box_enabled (FV_STATUS_INVALID_ARGUMENT), nor with intermixed
    /// volumes (FV_STATUS_UNSUPPORTED).
    Midpoint = 1,
    /// Midpoints with a step per min–max block: unshaded composite rays take 1, 2 or 4
    /// sample distances per step where the transfer function barely changes per step in
    /// the block (ferrovol's Quadrature::Adaptive); shaded rays and the other blend modes
    /// as FV_QUADRATURE_MIDPOINT. The same refusals.
    Adaptive = 2,
}

/// Gradient estimator for shading and gradient opacity.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvGradientMethod {
    /// Central differences (6 extra samples).
    Central = 0,
    /// Forward differences (3 extra samples).
    Forward = 1,
}

/// Where a light is defined (vtkLight's light types).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FvLightSpace {
    /// At the camera, shining at the focal point; position and focal point ignored.
    Headlight = 0,
    /// In camera coordinates (camera at the origin looking down −z, unit distance).
    Camera = 1,
    /// In world coordinates.
    World = 2,
}

/// A volume's geometry and scalar layout. Point (i, j, k) sits at
/// origin + direction · (spacing ⊙ (i, j, k)), as vtkImageData places it.
/// Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct FvVolumeDesc {
    /// Points along x, y, z (each ≥ 1).
    pub dims: [u32; 3],
    /// Components per point, 1–4, interleaved.
    pub components: u32,
    /// One of FvScalarType.
    pub scalar_type: u32,
    pub spacing: [f64; 3],
    pub origin: [f64; 3],
    /// Row-major 3×3 direction matrix (vtkImageData::GetDirectionMatrix).
    pub direction: [f64; 9],
}

/// A VTK camera. Matrices are column-major (OpenGL order: element (row r, column c) at
/// index 4·c + r). Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct FvCamera {
    pub position: [f64; 3],
    pub focal_point: [f64; 3],
    pub view_up: [f64; 3],
    /// Vertical view angle in degrees (perspective).
    pub view_angle: f64,
    pub parallel: bool,
    /// Half the viewport height in world units (parallel projection).
    pub parallel_scale: f64,
    /// Near and far clipping distances from the camera.
    pub clipping_range: [f64; 2],
    /// Use view_matrix and projection_matrix instead of the fields above (e.g. VTK's
    /// vtkCamera::GetCompositeProjectionTransformMatrix split into its two parts).
    pub use_matrices: bool,
    /// World → view.
    pub view_matrix: [f64; 16],
    /// View → clip (OpenGL clip space, depth −1…1).
    pub projection_matrix: [f64; 16],
}

/// A light (vtkLight). Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct FvLight {
    /// One of FvLightSpace.
    pub space: u32,
    pub positional: bool,
    pub position: [f64; 3],
    pub focal_point: [f64; 3],
    pub ambient: [f32; 3],
    pub diffuse: [f32; 3],
    pub specular: [f32; 3],
    pub intensity: f32,
    /// Constant, linear, quadratic (positional lights).
    pub attenuation: [f32; 3],
    /// Spotlight half-angle in degrees; ≥ 180 means no cone.
    pub cone_angle: f32,
    pub exponent: f32,
}

/// A clipping plane: points with dot(normal, p − origin) ≥ 0 are kept (VTK's convention).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct FvPlane {
    pub origin: [f64; 3],
    pub normal: [f64; 3],
}

/// Maximum number of clipping planes in FvRenderParams (vtkGPUVolumeRayCastMapper's 8).
pub const FV_MAX_CLIP_PLANES: usize = 8;
/// Maximum number of lights with shading on.
pub const FV_MAX_LIGHTS: usize = 8;

/// Everything about a frame that is neither the volume, the transfer function, the camera
/// nor the lights. Fill with fv_render_params_default() and change what you need.
/// Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct FvRenderParams {
    /// sizeof(this struct) as the caller's header declares it, written by
    /// fv_render_params_default; fields added in later minor versions take their defaults
    /// when it is smaller.
    pub size: usize,
    /// One of FvBlendMode.
    pub blend_mode: u32,
    /// One of FvInterpolation.
    pub interpolation: u32,
    /// World distance between samples; 0 = the smallest voxel spacing (VTK's automatic choice).
    pub sample_distance: f64,
    /// Offset each ray's first sample by a per-pixel fraction of a step (hides wood grain).
    pub jitter: bool,
    /// Early ray termination opacity, (0, 1]; VTK's is 1 − 1/255.
    pub termination_threshold: f32,
    /// One of FvGradientMethod.
    pub gradient_method: u32,
    pub shade: bool,
    pub ambient: f32,
    pub diffuse: f32,
    pub specular: f32,
    pub specular_power: f32,
    pub two_sided_lighting: bool,
    pub cropping: bool,
    /// xmin, xmax, ymin, ymax, zmin, zmax in data coordinates.
    pub cropping_planes: [f64; 6],
    /// vtkVolumeMapper::CroppingRegionFlags (27 bits).
    pub cropping_regions: u32,
    pub clip_plane_count: u32,
    pub clip_planes: [FvPlane; FV_MAX_CLIP_PLANES],
    /// Gradients read clipped_voxel_value (per component, data units) at neighbours beyond a
    /// clipping plane (vtkVolumeProperty::UseClippedVoxelIntensity): composite mode.
    pub clipped_voxel_enabled: bool,
    pub clipped_voxel_value: [f64; 4],
    /// Average blend mode: ignore samples outside average_range (AverageIPScalarRange).
    pub average_range_enabled: bool,
    pub average_range: [f64; 2],
    /// Skip blocks the transfer function makes fully transparent (composite mode).
    pub empty_space_skipping: bool,
    /// Depth output: first sample where accumulated opacity exceeds this, [0, 1).
    pub depth_threshold: f32,
    /// The vtkVolume's matrix (data → world), column-major.
    pub volume_matrix: [f64; 16],
    /// Volumetric shadows blended with the gradient shading (composite, shade on), as
    /// vtkGPUVolumeRayCastMapper::VolumetricScatteringBlending: 0 off … 2 volumetric only.
    pub volumetric_scattering_blending: f32,
    /// How far shadow rays reach, [0, 1] (GlobalIlluminationReach).
    pub global_illumination_reach: f32,
    /// Henyey–Greenstein anisotropy of the volumetric term, [−1, 1]
    /// (vtkVolumeProperty::ScatteringAnisotropy).
    pub scattering_anisotropy: f32,
    /// Shading normals from the gradient of the opacity instead of the scalar's
    /// (vtkVolumeMapper::ComputeNormalFromOpacity): composite, one or independent components.
    pub normal_from_opacity: bool,
    /// MIP and MinIP: write the extremum's place in the colour table's range as depth,
    /// 0.5·(1 − u) for MIP and 0.5·u for MinIP, so that compositing the frames of several
    /// pieces of one volume by depth keeps the extremum over all of them (ParaView's IceT
    /// under MPI); pixels without samples keep depth 1.
    pub extremum_depth: bool,
    /// The volume is a piece of a whole (ParaView under MPI): whole_box is the whole
    /// volume's box in this volume's index space (point indices: x, y, z low, then x, y, z
    /// high). Rays sample on the whole's lattice, a shared face once, and additive and
    /// average frames become nearly transparent sums (alpha 1/255) that compositing the
    /// pieces back to front with "over" adds up (see RenderParams::whole_box in
    /// ferrovol-core).
    pub whole_box_enabled: bool,
    pub whole_box: [f64; 6],
    /// Pre-integrated classification (Engel, Kraus, Ertl 2001): composite ray casting
    /// classifies the segment between consecutive samples from a table of its integrated
    /// colour and opacity, so thin opacity peaks show at the default step; one or
    /// independent components, without volumetric shadows (see RenderParams::preintegration
    /// in ferrovol-core). Off by default.
    pub preintegration: bool,
    /// An interactive frame: when the bricks it needs exceed the memory budget, draw in one
    /// pass rather than stream the volume itself in several (false, the default: the frame
    /// streams and equals the in-core image). Ray casting and isosurfaces (without ambient
    /// occlusion or scattering) draw the fine bricks resident and a coarser level's bricks
    /// where they are missing, and bring some of those their rays read for the next
    /// preview frame (FvResidency.stand_ins: 0 once complete).
    pub preview_level: bool,
    /// The plane FV_BLEND_MODE_SLICE draws, world coordinates (a non-zero normal; its sign
    /// does not matter); ignored by the other blend modes.
    pub slice_plane: FvPlane,
    /// vtkGPUVolumeRayCastMapper's MaskBlendFactor, in [0, 1] (default 1): with a label-map
    /// mask (fv_renderer_set_mask), how much of a labelled sample's colour and opacity come
    /// from its label's functions (fv_transfer_function_set_label_*) rather than the
    /// components'; 0 reads no label.
    pub mask_blend_factor: f32,
    /// One of FvQuadrature (default FV_QUADRATURE_VTK).
    pub quadrature: u32,
}

/// Counters that show what the renderer re-uploaded. Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct FvStats {
    pub volume_uploads: u32,
    pub table_uploads: u32,
    pub frames: u32,
    /// Bricks the volume was split into (1 when it fits in one texture).
    pub bricks: u32,
    /// Times the path tracer's accumulation started over (anything it converges to
    /// changed, or the first path-traced frame).
    pub accumulation_restarts: u32,
}

/// How much of the volume is on the device. A volume too large for one texture is split
/// into bricks of which only those a frame needs (something visible, an iso-value) are
/// resident. Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct FvResidency {
    /// Bricks the volume is split into, and how many of them are resident.
    pub bricks: u32,
    pub resident: u32,
    /// Bricks read into the device so far.
    pub brick_uploads: u32,
    /// Bytes of the resident bricks' pool (with its apron and precomputed gradients), and
    /// of the whole volume as one texture.
    pub pool_bytes: u64,
    pub dense_bytes: u64,
    /// Fine points per point, along each axis, of the level the last frame drew: 1 for the
    /// volume itself; 2, 4, … when the bricks of a frame whose rays go anywhere (path
    /// tracing, volumetric shadows, ambient occlusion, scattering between isosurfaces)
    /// exceed the memory budget and it drew a level downsampled that much (the finest that
    /// fits).
    pub level: u32,
    /// That level's points per axis.
    pub level_dims: [u32; 3],
    /// Bricks the last frame's rays read from a coarser level standing in for them: a
    /// preview frame (FvRenderParams.preview_level) of ray casting past the budget draws
    /// the fine bricks resident and a coarser level's where they are missing, and brings
    /// some of those for the next preview frame; 0 when every sample came from the volume
    /// itself (the frame is complete).
    pub stand_ins: u32,
}

/// What a context holds on its device now (every renderer on it together), from wgpu's
/// own counters: live buffers, texture views and bind groups, and the device memory bound
/// to buffers and textures (images exported to the host not included). A host watches
/// these stay flat over a long session. Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct FvDeviceMemory {
    pub buffers: u64,
    pub texture_views: u64,
    pub bind_groups: u64,
    pub buffer_bytes: u64,
    pub texture_bytes: u64,
}

/// How far the path tracer's accumulation has come. Thread use: plain data.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct FvConvergence {
    /// Paths every pixel has (the passes completed).
    pub paths_per_pixel: u32,
    /// Paths per pixel on average, counting the pixels of the pass under way.
    pub mean_paths_per_pixel: f32,
    /// Estimated relative error of the shown image: each covered pixel's standard error of
    /// its mean luminance, RMS over the covered pixels, over their mean luminance; −1 before
    /// every pixel has two paths.
    pub relative_error: f32,
}

/// A C description that converts, validated, into its core type.
pub trait ToCore {
    type Core;
    fn to_core(&self) -> FfiResult<Self::Core>;
}

fn enum_value<T: Copy>(what: &str, v: u32, table: &[T]) -> FfiResult<T> {
    table.get(v as usize).copied().ok_or_else(|| {
        FfiError::invalid(format!(
            "{what} {v} is out of range (0 to {})",
            table.len() - 1
        ))
    })
}

pub fn column_major(m: &[f64; 16]) -> DMat4 {
    DMat4::from_cols_array(m)
}

crate::sized::sized_params!(FvRenderParams, "FvRenderParams", quadrature: u32, 832);

impl FvRenderParams {
    pub fn defaults() -> Self {
        let d = RenderParams::default();
        FvRenderParams {
            size: std::mem::size_of::<FvRenderParams>(),
            blend_mode: FvBlendMode::Composite as u32,
            interpolation: FvInterpolation::Linear as u32,
            sample_distance: 0.0,
            jitter: d.jitter,
            termination_threshold: d.termination_threshold,
            gradient_method: FvGradientMethod::Central as u32,
            shade: d.shading.enabled,
            ambient: d.shading.ambient,
            diffuse: d.shading.diffuse,
            specular: d.shading.specular,
            specular_power: d.shading.specular_power,
            two_sided_lighting: d.shading.two_sided,
            cropping: false,
            cropping_planes: [0.0; 6],
            cropping_regions: Cropping::SUBVOLUME,
            clip_plane_count: 0,
            clip_planes: [FvPlane::default(); FV_MAX_CLIP_PLANES],
            clipped_voxel_enabled: false,
            clipped_voxel_value: [0.0; 4],
            average_range_enabled: false,
            average_range: [0.0, 0.0],
            empty_space_skipping: d.empty_space_skipping,
            depth_threshold: d.depth_threshold,
            volume_matrix: DMat4::IDENTITY.to_cols_array(),
            volumetric_scattering_blending: d.shading.volumetric_blending,
            global_illumination_reach: d.shading.global_illumination_reach,
            scattering_anisotropy: d.shading.scattering_anisotropy,
            normal_from_opacity: d.shading.normal_from_opacity,
            extremum_depth: d.extremum_depth,
            whole_box_enabled: false,
            whole_box: [0.0; 6],
            preintegration: d.preintegration,
            slice_plane: FvPlane {
                origin: [0.0; 3],
                normal: [0.0, 0.0, 1.0],
            },
            mask_blend_factor: d.mask_blend,
            preview_level: d.preview_level,
            quadrature: FvQuadrature::Vtk as u32,
        }
    }
}

impl ToCore for FvRenderParams {
    type Core = RenderParams;
    fn to_core(&self) -> FfiResult<RenderParams> {
        use BlendMode as B;
        let blend = enum_value(
            "blend_mode",
            self.blend_mode,
            &[
                B::Composite,
                B::Maximum,
                B::Minimum,
                B::Average,
                B::Additive,
                B::Isosurface,
                B::PathTrace,
                B::Slice,
            ],
        )?;
        let interpolation = enum_value(
            "interpolation",
            self.interpolation,
            &[
                Interpolation::Nearest,
                Interpolation::Linear,
                Interpolation::Cubic,
            ],
        )?;
        let gradient = enum_value(
            "gradient_method",
            self.gradient_method,
            &[GradientMethod::Central, GradientMethod::Forward],
        )?;
        if !(self.sample_distance.is_finite() && self.sample_distance >= 0.0) {
            return Err(FfiError::invalid(format!(
                "sample_distance {} must be 0 (automatic) or positive",
                self.sample_distance
            )));
        }
        let n = self.clip_plane_count as usize;
        if n > FV_MAX_CLIP_PLANES {
            return Err(FfiError::invalid(format!(
                "clip_plane_count {n}: at most {FV_MAX_CLIP_PLANES} clipping planes"
            )));
        }
        let p = RenderParams {
            blend,
            interpolation,
            sample_distance: (self.sample_distance > 0.0).then_some(self.sample_distance),
            jitter: self.jitter,
            termination_threshold: self.termination_threshold,
            gradient,
            shading: Shading {
                enabled: self.shade,
                ambient: self.ambient,
                diffuse: self.diffuse,
                specular: self.specular,
                specular_power: self.specular_power,
                two_sided: self.two_sided_lighting,
                volumetric_blending: self.volumetric_scattering_blending,
                global_illumination_reach: self.global_illumination_reach,
                scattering_anisotropy: self.scattering_anisotropy,
                normal_from_opacity: self.normal_from_opacity,
            },
            cropping: self.cropping.then_some(Cropping {
                planes: self.cropping_planes,
                regions: self.cropping_regions,
            }),
            clip_planes: self.clip_planes[..n]
                .iter()
                .map(|p| ClipPlane {
                    origin: DVec3::from_array(p.origin),
                    normal: DVec3::from_array(p.normal),
                })
                .collect(),
            clipped_voxel_value: self
                .clipped_voxel_enabled
                .then_some(self.clipped_voxel_value),
            average_range: self.average_range_enabled.then_some(self.average_range),
            empty_space_skipping: self.empty_space_skipping,
            depth_threshold: self.depth_threshold,
            volume_matrix: column_major(&self.volume_matrix),
            extremum_depth: self.extremum_depth,
            whole_box: self.whole_box_enabled.then_some([
                [self.whole_box[0], self.whole_box[1], self.whole_box[2]],
                [self.whole_box[3], self.whole_box[4], self.whole_box[5]],
            ]),
            preintegration: self.preintegration,
            slice_plane: (blend == B::Slice).then_some(ClipPlane {
                origin: DVec3::from_array(self.slice_plane.origin),
                normal: DVec3::from_array(self.slice_plane.normal),
            }),
            mask_blend: self.mask_blend_factor,
            preview_level: self.preview_level,
            quadrature: enum_value(
                "quadrature",
                self.quadrature,
                &[Quadrature::Vtk, Quadrature::Midpoint, Quadrature::Adaptive],
            )?,
        };
        p.validate()?;
        Ok(p)
    }
}

fn finite3(what: &str, v: [f64; 3]) -> FfiResult<DVec3> {
    let d = DVec3::from_array(v);
    if d.is_finite() {
        Ok(d)
    } else {
        Err(FfiError::invalid(format!("{what} {v:?} is not finite")))
    }
}

impl ToCore for FvCamera {
    type Core = Camera;
    fn to_core(&self) -> FfiResult<Camera> {
        let position = finite3("camera position", self.position)?;
        let focal_point = finite3("camera focal point", self.focal_point)?;
        let view_up = finite3("camera view up", self.view_up)?;
        let raw = if self.use_matrices {
            let v = column_major(&self.view_matrix);
            let p = column_major(&self.projection_matrix);
            for (name, m) in [("view", v), ("projection", p)] {
                if !m.is_finite() || m.determinant().abs() < 1e-300 {
                    return Err(FfiError::invalid(format!(
                        "camera {name} matrix is singular or not finite"
                    )));
                }
            }
            Some((v, p))
        } else {
            if (position - focal_point).length() <= 0.0 {
                return Err(FfiError::invalid(
                    "camera position equals its focal point: no view direction",
                ));
            }
            if view_up.cross(focal_point - position).length() <= 0.0 {
                return Err(FfiError::invalid(
                    "camera view up is zero or parallel to the view direction",
                ));
            }
            let angle_ok = self.view_angle > 0.0 && self.view_angle < 180.0;
            if !self.parallel && !angle_ok {
                return Err(FfiError::invalid(format!(
                    "camera view angle {} must be in (0, 180) degrees",
                    self.view_angle
                )));
            }
            if self.parallel && !(self.parallel_scale.is_finite() && self.parallel_scale > 0.0) {
                return Err(FfiError::invalid(format!(
                    "camera parallel scale {} must be positive",
                    self.parallel_scale
                )));
            }
            let [near, far] = self.clipping_range;
            if !(near.is_finite() && far.is_finite() && near > 0.0 && far > near) {
                return Err(FfiError::invalid(format!(
                    "camera clipping range [{near}, {far}] needs 0 < near < far"
                )));
            }
            None
        };
        Ok(Camera {
            position,
            focal_point,
            view_up,
            view_angle: self.view_angle,
            parallel: self.parallel,
            parallel_scale: self.parallel_scale,
            clipping_range: self.clipping_range,
            raw,
        })
    }
}

impl FvLight {
    pub fn to_core(&self, index: usize) -> FfiResult<Light> {
        let space = enum_value(
            &format!("light {index} space"),
            self.space,
            &[LightSpace::Headlight, LightSpace::Camera, LightSpace::World],
        )?;
        let colours = [self.ambient, self.diffuse, self.specular];
        let scalars = [self.intensity, self.cone_angle, self.exponent];
        if colours
            .iter()
            .flatten()
            .chain(&scalars)
            .chain(&self.attenuation)
            .any(|v| !v.is_finite())
        {
            return Err(FfiError::invalid(format!(
                "light {index} has a non-finite colour, intensity, attenuation or cone"
            )));
        }
        Ok(Light {
            space,
            positional: self.positional,
            position: finite3(&format!("light {index} position"), self.position)?,
            focal_point: finite3(&format!("light {index} focal point"), self.focal_point)?,
            ambient: self.ambient,
            diffuse: self.diffuse,
            specular: self.specular,
            intensity: self.intensity,
            attenuation: self.attenuation,
            cone_angle: self.cone_angle,
            exponent: self.exponent,
        })
    }
}
