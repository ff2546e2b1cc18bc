//! Per-frame render parameters (the small things that change between frames without
//! touching the volume or the tables).

use super::check::{non_negative, within};
use crate::error::{Error, Result};
use crate::gpu::uniforms::{
    BLEND_ADDITIVE, BLEND_AVERAGE, BLEND_COMPOSITE, BLEND_ISOSURFACE, BLEND_MAXIMUM, BLEND_MINIMUM,
    BLEND_PATHTRACE, BLEND_SLICE,
};
pub use crate::gpu::uniforms::{MAX_CLIP_PLANES, MAX_LIGHTS};
use glam::{DMat4, DVec3};

/// How samples along a ray combine (VTK's vtkVolumeMapper blend modes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BlendMode {
    /// Front-to-back alpha compositing with early ray termination.
    Composite,
    /// Maximum intensity projection.
    Maximum,
    /// Minimum intensity projection.
    Minimum,
    /// Average of the samples inside [`RenderParams::average_range`].
    Average,
    /// Sum of opacity-weighted scalars along the ray.
    Additive,
    /// Isosurfaces: first hit with bisection, deferred shading with environment lighting
    /// and ambient occlusion; the iso-values and their shading come from
    /// [`crate::Renderer::set_isosurface`] (crate::passes::iso), not the transfer function.
    Isosurface,
    /// Progressive Monte Carlo path tracing of the volume as a scattering medium
    /// (crate::passes::pathtrace; settings from [`crate::Renderer::set_path_tracing`]).
    PathTrace,
    /// VTK's slice blend mode (SLICE_BLEND with a vtkPlane as the property's slice
    /// function): each pixel shows the point where its ray meets
    /// [`RenderParams::slice_plane`], with the transfer function's colour and opacity as
    /// given (no step correction), shaded and with gradient opacity as composite applies
    /// them, and that point's depth; nothing where the point lies outside the volume's
    /// box, behind the opaque depth, on the cut side of a clipping plane or in a cropped
    /// region.
    Slice,
}

impl BlendMode {
    /// Every blend mode, in declaration order.
    pub const ALL: [BlendMode; 8] = [
        BlendMode::Composite,
        BlendMode::Maximum,
        BlendMode::Minimum,
        BlendMode::Average,
        BlendMode::Additive,
        BlendMode::Isosurface,
        BlendMode::PathTrace,
        BlendMode::Slice,
    ];

    pub(crate) fn code(self) -> u32 {
        match self {
            BlendMode::Composite => BLEND_COMPOSITE,
            BlendMode::Maximum => BLEND_MAXIMUM,
            BlendMode::Minimum => BLEND_MINIMUM,
            BlendMode::Average => BLEND_AVERAGE,
            BlendMode::Additive => BLEND_ADDITIVE,
            BlendMode::Isosurface => BLEND_ISOSURFACE,
            BlendMode::PathTrace => BLEND_PATHTRACE,
            BlendMode::Slice => BLEND_SLICE,
        }
    }
}

/// How the volume is reconstructed between its points (the transfer-function tables are read
/// linearly, or at the nearest entry with `Nearest`, as VTK's InterpolationType says).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    Nearest,
    Linear,
    /// The cubic B-spline of the points (not prefiltered: it approximates, smoothing at the
    /// scale of a voxel, and reproduces linear fields exactly), evaluated with eight trilinear
    /// fetches per sample (Sigg and Hadwiger 2005). Ray casting (gradients stay the central
    /// differences of the points) and isosurfaces (the B-spline's surfaces and their
    /// normals); path tracing and streamed volumes refuse it.
    Cubic,
}

/// Gradient estimator for shading and gradient opacity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GradientMethod {
    /// Central differences, 6 extra samples (default).
    Central,
    /// Forward differences, 3 extra samples.
    Forward,
}

/// Blinn–Phong material (vtkVolumeProperty's Shade, Ambient, Diffuse, Specular, SpecularPower).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shading {
    pub enabled: bool,
    pub ambient: f32,
    pub diffuse: f32,
    pub specular: f32,
    pub specular_power: f32,
    /// Light the back side of gradients too (VTK renderers default to two-sided lighting).
    pub two_sided: bool,
    /// Volumetric shadows (single scattering) blended with the gradient shading, VTK 9.2's
    /// vtkGPUVolumeRayCastMapper::VolumetricScatteringBlending: 0 off, up to 1 the
    /// volumetric share grows where the gradient is weak, 2 volumetric only. Composite
    /// blend mode with shading and at least one light; one-component volumes.
    pub volumetric_blending: f32,
    /// How far shadow rays reach, 0 (about one step) to 1 (across the whole volume), as
    /// vtkGPUVolumeRayCastMapper::GlobalIlluminationReach.
    pub global_illumination_reach: f32,
    /// Henyey–Greenstein anisotropy of the volumetric term, −1 to 1
    /// (vtkVolumeProperty::ScatteringAnisotropy).
    pub scattering_anisotropy: f32,
    /// Shading normals from the gradient of the step-corrected opacity (the transfer
    /// function's, times gradient opacity when on) instead of the scalar's, as
    /// vtkVolumeMapper::ComputeNormalFromOpacity: composite ray casting, one or independent
    /// components; isosurfaces and path tracing keep the scalar gradient.
    pub normal_from_opacity: bool,
}

impl Default for Shading {
    /// VTK's vtkVolumeProperty defaults, shading off.
    fn default() -> Self {
        Shading {
            enabled: false,
            ambient: 0.1,
            diffuse: 0.7,
            specular: 0.2,
            specular_power: 10.0,
            two_sided: true,
            volumetric_blending: 0.0,
            global_illumination_reach: 0.0,
            scattering_anisotropy: 0.0,
            normal_from_opacity: false,
        }
    }
}

/// VTK's cropping: six planes in data coordinates (xmin, xmax, ymin, ymax, zmin, zmax)
/// splitting space into 27 regions; bit `rx + 3·ry + 9·rz` of `regions` makes region
/// (rx, ry, rz) visible, where r = 0 below the first plane, 1 between, 2 above.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cropping {
    pub planes: [f64; 6],
    pub regions: u32,
}

impl Cropping {
    /// vtkVolumeMapper::CroppingRegionFlags presets.
    pub const SUBVOLUME: u32 = 0x0002000;
    pub const FENCE: u32 = 0x2ebfeba;
    pub const INVERTED_FENCE: u32 = 0x5140145;
    pub const CROSS: u32 = 0x0417410;
    pub const INVERTED_CROSS: u32 = 0x7be8bef;
}

/// A plane through `origin` with `normal`. As a clipping plane it keeps the points with
/// dot(normal, p − origin) ≥ 0 (VTK's convention: the normal points into the kept
/// half-space); as the slice blend mode's plane its normal's sign does not matter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipPlane {
    pub origin: DVec3,
    pub normal: DVec3,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderParams {
    pub blend: BlendMode,
    pub interpolation: Interpolation,
    /// World distance between samples; `None` picks the smallest voxel spacing (after the
    /// volume matrix), VTK's AutoAdjustSampleDistances choice for a still frame.
    pub sample_distance: Option<f64>,
    /// Offset each ray's first sample by a per-pixel deterministic fraction of a step.
    pub jitter: bool,
    /// Early ray termination: stop compositing once opacity reaches this (VTK: 1 − 1/255).
    pub termination_threshold: f32,
    pub gradient: GradientMethod,
    pub shading: Shading,
    pub cropping: Option<Cropping>,
    pub clip_planes: Vec<ClipPlane>,
    /// What each component reads, in data units, at a gradient's neighbour beyond a clipping
    /// plane (vtkVolumeProperty::UseClippedVoxelIntensity / ClippedVoxelIntensity): shading
    /// and gradient opacity of composite ray casting see the cut as a wall of this value.
    /// None: the data beyond the plane.
    pub clipped_voxel_value: Option<[f64; 4]>,
    /// AverageIPScalarRange: samples outside are ignored by the average blend mode.
    pub average_range: Option<[f64; 2]>,
    /// Skip blocks classified empty by the transfer function (composite mode), and blocks
    /// whose scalar range cannot change the extremum (MIP, MinIP; one component).
    pub empty_space_skipping: bool,
    /// Depth output: the first sample where accumulated opacity exceeds this (0: the first
    /// sample with any opacity, as VTK's RenderToImage depth).
    pub depth_threshold: f32,
    /// The vtkVolume's matrix (data → world).
    pub volume_matrix: DMat4,
    /// MIP and MinIP write the extremum's place in the colour table's range as the depth
    /// instead of 1: 0.5·(1 − u) for MIP, 0.5·u for MinIP (u from 0 at the range's low end
    /// to 1 at its high end), so that a depth test keeps the larger maximum or the smaller
    /// minimum. A host that composites the frames of several pieces of one volume by depth
    /// (ParaView's IceT under MPI) then gets the extremum over all pieces; pixels without
    /// samples keep depth 1. One component (with several, component 0 decides).
    pub extremum_depth: bool,
    /// The whole volume this one is a piece of (ParaView under MPI: each rank draws its
    /// piece and IceT composites the ranks' frames), as a box in this volume's index space
    /// (point indices, e.g. the whole extent less this piece's first index): rays sample on
    /// the whole volume's lattice and take a sample on a face two pieces share only once,
    /// so that compositing the pieces back to front ("over") gives the whole's composite
    /// image; additive and average frames are nearly transparent sums (alpha 1/255)
    /// except in the piece where the ray leaves the whole volume (average dividing by the
    /// whole ray's sample count), so that "over" adds them up. `None`: the volume is whole.
    pub whole_box: Option<[[f64; 3]; 2]>,
    /// Pre-integrated classification (Engel, Kraus, Ertl 2001): composite ray casting
    /// classifies the segment between consecutive samples, the scalar taken to run linearly
    /// from one to the next, from a table of its integrated colour and opacity (built from
    /// the transfer function for the step, rebuilt when either changes), instead of the
    /// sample alone; shading and gradient opacity are the back sample's. Thin opacity peaks
    /// then show at the default step without slicing. One component or independent
    /// components, without volumetric shadows; other modes sample as without.
    pub preintegration: bool,
    /// The plane [`BlendMode::Slice`] draws, in world coordinates (the normal's sign does
    /// not matter); required by that blend mode, ignored by the others.
    pub slice_plane: Option<ClipPlane>,
    /// VTK's MaskBlendFactor, in [0, 1]: with a label-map mask ([`crate::MaskKind`]), how
    /// much of a labelled sample's colour and opacity come from its label's functions
    /// rather than the transfer function's components (0: the mask is not read).
    pub mask_blend: f32,
    /// An interactive frame of a volume whose needed bricks exceed the memory budget: draw
    /// in one pass, the fine bricks resident and a coarser level's bricks standing in where
    /// they are missing, rather than stream the volume itself through the pool in several
    /// (a still frame streams, and equals the in-core image); the bricks the rays read from
    /// stand-ins come in the next preview frames ([`crate::Residency::stand_ins`]: 0 once
    /// complete). Ray casting (not the slice mode) and the isosurfaces' first hit, without a
    /// mask or blanking (not downsampled: such a frame streams); the frames whose rays go
    /// anywhere draw a coarser level past the budget anyway.
    pub preview_level: bool,
    /// Where ray casting places its samples along a ray and how long a step each stands for.
    pub quadrature: Quadrature,
}

/// The rule by which ray casting turns a ray's samples into its integral.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Quadrature {
    /// VTK 9.2's lattice (tests/regression/SAMPLING.md): sample k one step past the ray's
    /// entry plus k steps, each standing for a whole step; the first sample taken even past
    /// the exit, up to one step past opaque depth and clipping planes. The error against
    /// the exact integral is first order in the step and largest along silhouettes, where
    /// the path through the volume is shorter than a step or ends between samples.
    #[default]
    Vtk,
    /// Midpoints: each sample in the middle of its step, and the part of the ray past the
    /// last whole step (up to the exit, opaque depth or a clipping plane, exactly) one more
    /// sample at its middle, its opacity corrected for its length: the path length through
    /// the volume is exact, and the rule second order in the step. Average and additive
    /// weigh that last sample by its length, MIP and MinIP take it as any other. With
    /// `preintegration` the samples stay on the steps' ends (each classifying its step, as
    /// on VTK's lattice) and the last, shorter step is classified likewise. Not with
    /// jittering or for pieces of a whole volume (`whole_box`).
    Midpoint,
    /// Midpoints with a step per min–max block: unshaded composite rays take 1, 2 or 4
    /// sample distances per step where the classified function barely changes per step
    /// over the block (its opacity and opacity-weighted colour spread over the block's
    /// value range, times the share of that range one voxel crosses at most, within
    /// [`ADAPTIVE_STEP_TOLERANCE`]), a coarse step ending at its block's exit; only where
    /// the coarse steps save half the occupied blocks' samples (reading the blocks costs
    /// the rest). Shaded rays (their lighting turns with the gradient's direction, which a
    /// block's values do not bound), the other blend modes, pre-integration, gradient
    /// opacity, 2D tables, cropping, masks, blanking, dependent components and rectilinear
    /// grids take every step as [`Quadrature::Midpoint`] does. Not with jittering or
    /// `whole_box`.
    Adaptive,
}

/// How much a block's classified opacity and opacity-weighted colour (per sample distance)
/// may change per step for an adaptive ray to take it: a step of m sample distances where
/// m times the change per sample distance (the block's spread times the share of its range
/// one voxel crosses at most) stays within it.
pub const ADAPTIVE_STEP_TOLERANCE: f32 = 0.1;

impl Quadrature {
    /// Whether samples sit in the middle of their steps (the path length exact).
    pub fn midpoints(self) -> bool {
        self != Quadrature::Vtk
    }

    /// Its name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Quadrature::Vtk => "VTK lattice",
            Quadrature::Midpoint => "midpoint",
            Quadrature::Adaptive => "adaptive",
        }
    }
}

impl Default for RenderParams {
    fn default() -> Self {
        RenderParams {
            blend: BlendMode::Composite,
            interpolation: Interpolation::Linear,
            sample_distance: None,
            jitter: false,
            termination_threshold: 1.0 - 1.0 / 255.0,
            gradient: GradientMethod::Central,
            shading: Shading::default(),
            cropping: None,
            clip_planes: Vec::new(),
            clipped_voxel_value: None,
            average_range: None,
            empty_space_skipping: true,
            depth_threshold: 0.0,
            volume_matrix: DMat4::IDENTITY,
            extremum_depth: false,
            whole_box: None,
            preintegration: false,
            slice_plane: None,
            mask_blend: 1.0,
            preview_level: false,
            quadrature: Quadrature::Vtk,
        }
    }
}

impl RenderParams {
    pub fn validate(&self) -> Result<()> {
        if self.quadrature.midpoints() && (self.jitter || self.whole_box.is_some()) {
            return Err(Error::InvalidParameter(format!(
                "the {} quadrature places samples itself: turn {} off",
                self.quadrature.name(),
                if self.jitter {
                    "jittering"
                } else {
                    "the whole-volume box (pieces)"
                }
            )));
        }
        if let Some(d) = self.sample_distance {
            if !(d.is_finite() && d > 0.0) {
                return Err(Error::InvalidParameter(format!(
                    "sample distance {d} must be positive"
                )));
            }
        }
        if !(self.termination_threshold > 0.0 && self.termination_threshold <= 1.0) {
            return Err(Error::InvalidParameter(format!(
                "early termination threshold {} must be in (0, 1]",
                self.termination_threshold
            )));
        }
        if !(0.0..1.0).contains(&self.depth_threshold) {
            return Err(Error::InvalidParameter(format!(
                "depth threshold {} must be in [0, 1)",
                self.depth_threshold
            )));
        }
        if self.clip_planes.len() > MAX_CLIP_PLANES {
            return Err(Error::InvalidParameter(format!(
                "{} clipping planes; at most {MAX_CLIP_PLANES} are supported",
                self.clip_planes.len()
            )));
        }
        for p in &self.clip_planes {
            if !p.origin.is_finite() || !p.normal.is_finite() || p.normal.length() < 1e-12 {
                return Err(Error::InvalidParameter(format!(
                    "clipping plane {p:?} needs a finite origin and a non-zero normal"
                )));
            }
        }
        match self.slice_plane {
            Some(p)
                if !p.origin.is_finite() || !p.normal.is_finite() || p.normal.length() < 1e-12 =>
            {
                return Err(Error::InvalidParameter(format!(
                    "slice plane {p:?} needs a finite origin and a non-zero normal"
                )));
            }
            None if self.blend == BlendMode::Slice => {
                return Err(Error::InvalidParameter(
                    "the slice blend mode needs a slice plane (RenderParams::slice_plane)".into(),
                ));
            }
            _ => {}
        }
        if let Some(v) = self.clipped_voxel_value {
            if v.iter().any(|x| x.is_nan()) {
                return Err(Error::InvalidParameter(format!(
                    "clipped voxel value {v:?} must not be NaN"
                )));
            }
        }
        if let Some(c) = &self.cropping {
            if c.planes.iter().any(|v| !v.is_finite())
                || c.planes[0] > c.planes[1]
                || c.planes[2] > c.planes[3]
                || c.planes[4] > c.planes[5]
            {
                return Err(Error::InvalidParameter(format!(
                    "cropping planes {:?} must be finite with min ≤ max on each axis",
                    c.planes
                )));
            }
            if c.regions >= 1 << 27 {
                return Err(Error::InvalidParameter(format!(
                    "cropping region flags 0x{:x} use more than 27 bits",
                    c.regions
                )));
            }
        }
        within("mask blend factor", self.mask_blend, 0.0, 1.0)?;
        let s = &self.shading;
        for (n, v) in [
            ("ambient", s.ambient),
            ("diffuse", s.diffuse),
            ("specular", s.specular),
            ("specular power", s.specular_power),
        ] {
            non_negative(&format!("shading {n}"), v)?;
        }
        for (n, v, lo, hi) in [
            (
                "volumetric scattering blending",
                s.volumetric_blending,
                0.0,
                2.0,
            ),
            (
                "global illumination reach",
                s.global_illumination_reach,
                0.0,
                1.0,
            ),
            ("scattering anisotropy", s.scattering_anisotropy, -1.0, 1.0),
        ] {
            within(n, v, lo, hi)?;
        }
        if self.volume_matrix.determinant().abs() < 1e-12 || !self.volume_matrix.is_finite() {
            return Err(Error::InvalidParameter(
                "the volume matrix is singular or not finite".into(),
            ));
        }
        if let Some([lo, hi]) = self.whole_box {
            if !(0..3).all(|i| lo[i].is_finite() && hi[i].is_finite() && lo[i] <= hi[i]) {
                return Err(Error::InvalidParameter(format!(
                    "the whole volume's box {lo:?} - {hi:?} must be finite with each low end \
                     at most its high end"
                )));
            }
        }
        Ok(())
    }
}
