//! Rust mirrors of the WGSL structs in shaders/lib/common.wgsl and shaders/lib/volume.wgsl.
//! Only 16-byte fields or runs of four 4-byte scalars, so std140/std430 and `repr(C)` agree;
//! `layout_tests` checks every field's name and offset against naga's reflection of the WGSL.

use bytemuck::{Pod, Zeroable};

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuLight {
    pub position: [f32; 4],
    pub spot: [f32; 4],
    pub diffuse: [f32; 4],
    pub specular: [f32; 4],
    pub ambient: [f32; 4],
    pub attenuation: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniforms {
    /// Clip → world and world → clip (the shaders read them at a dynamic index: ray.wgsl).
    pub camera: [[f32; 16]; 2],
    pub world_to_index: [f32; 16],
    pub index_to_data: [f32; 16],
    pub gradient_to_world: [f32; 16],
    pub dims: [f32; 4],
    pub scalar_scale: [f32; 4],
    pub scalar_shift: [f32; 4],
    pub tf_lo: [f32; 4],
    pub tf_inv_width: [f32; 4],
    pub go_lo: [f32; 4],
    pub go_inv_width: [f32; 4],
    pub weights: [f32; 4],
    pub material: [f32; 4],
    pub crop_lo: [f32; 4],
    pub crop_hi: [f32; 4],
    /// World distance between samples.
    pub sample_distance: f32,
    /// Early ray termination: the opacity a ray stops at.
    pub termination: f32,
    /// The opacity at which a ray's depth is taken.
    pub depth_threshold: f32,
    /// Shorter gradients shade as having no normal.
    pub gradient_epsilon: f32,
    pub average_range: [f32; 4],
    pub additive_scale: [f32; 4],
    pub scatter: [f32; 4],
    pub clip: [[f32; 4]; MAX_CLIP_PLANES],
    pub clipped_value: [f32; 4],
    pub whole_lo: [f32; 4],
    pub whole_hi: [f32; 4],
    pub lights: [GpuLight; 8],
    pub width: u32,
    pub height: u32,
    /// Always 0, read by the shaders as the camera matrices' index (lib/ray.wgsl).
    pub camera_index: u32,
    pub jitter_seed: u32,
    /// BlendMode::code.
    pub blend: u32,
    /// FLAG_* bits.
    pub flags: u32,
    /// VTK's cropping region flags.
    pub crop_regions: u32,
    pub unused: u32,
    pub clip_planes: u32,
    pub light_count: u32,
    /// Points per edge of an occupancy block.
    pub block_size: u32,
    pub components: u32,
    pub occupancy_dims: [u32; 4],
    pub rect: [u32; 4],
    /// Each independent component's material (ambient, diffuse, specular, power).
    pub component_materials: [[f32; 4]; 4],
    pub slice: [f32; 4],
    /// A mask: x the label-map blend factor, y the highest label with functions of its own.
    pub mask: [f32; 4],
    /// The labels' tables: scalar at the first entry, 1 / scalar width, the same for
    /// gradient magnitude.
    pub labels: [f32; 4],
    /// Per component, its 2D table's scalar at the first column's edge, 1 / the scalar
    /// range, and 1 / the gradient magnitude at the last row's edge (0: the first row).
    pub t2d_lo: [f32; 4],
    pub t2d_inv_width: [f32; 4],
    pub t2d_inv_gmax: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct PoolUniforms {
    pub brick: [f32; 4],
    pub grid: [u32; 4],
    pub slot: [f32; 4],
    pub inv_size: [f32; 4],
}

/// Per-pixel ray state (PixelState in WGSL), 48 bytes.
pub const PIXEL_STATE_BYTES: u64 = 48;

/// An unstructured volume's uniforms (`Mesh` in shaders/unstructured.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct MeshUniforms {
    /// Tetrahedra, boundary triangles, hierarchy nodes, the most steps a ray takes.
    pub counts: [u32; 4],
    /// x: 1 / the scalar opacity unit distance (attenuation = opacity · x).
    pub unit: [f32; 4],
    /// x: the number of `knots`, or [`MESH_EVERY_ENTRY`].
    pub split: [u32; 4],
    /// Where a segment's pieces end besides its own ends (table coordinates, ascending):
    /// the transfer functions' points and the tables' ends, between which colour and
    /// opacity are linear.
    pub knots: [[f32; 4]; MESH_KNOTS / 4],
    /// Bit i (word i / 32, bit i mod 32) set where table entry i's opacity is above 0:
    /// composite skips the integral of a tetrahedron whose scalars reach no set entry.
    pub opaque: [[u32; 4]; MESH_OPAQUE_WORDS / 4],
    /// x: the tetrahedra the first binding of the tetrahedra and of the neighbours holds;
    /// the rest are in the second (a device whose one binding holds fewer than the mesh's).
    pub halves: [u32; 4],
    /// xyz: 1 / the mesh box's extent per axis (index space → the unit cube, where the
    /// volumetric shadows' reach is measured); w: a typical cell's size (the step whose
    /// opacity weighs the volumetric term).
    pub shadow: [f32; 4],
}

/// The 32-bit words of [`MeshUniforms::opaque`]: a bit per table entry.
pub const MESH_OPAQUE_WORDS: usize = TABLE_SIZE / 32;
/// The most knots [`MeshUniforms`] holds.
pub const MESH_KNOTS: usize = 64;
/// A transfer function of more knots: segments split at every table entry.
pub const MESH_EVERY_ENTRY: u32 = u32::MAX;
/// The deepest boundary hierarchy a ray's search holds on its stack (median splits of 2^32
/// triangles go 31 deep).
pub const MESH_BVH_STACK: usize = 64;

/// The isosurface uniforms (`Iso` in shaders/lib/iso.wgsl), read by the first-hit and
/// deferred passes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct IsoUniforms {
    pub env_rotation: [f32; 16],
    pub values: [[f32; 4]; 2],
    pub colors: [[f32; 4]; 8],
    pub shininess: [f32; 4],
    pub ao: [f32; 4],
    pub env: [f32; 4],
    pub counts: [u32; 4],
    pub options: [u32; 4],
    pub shade_rect: [u32; 4],
    pub scatter: [f32; 4],
}

/// The path tracer's uniforms (`PathTrace` in shaders/pathtrace.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PathTraceUniforms {
    pub env_rotation: [f32; 16],
    pub medium: [f32; 4],
    pub surface: [f32; 4],
    pub lobe: [f32; 4],
    pub counts: [u32; 4],
    pub options: [u32; 4],
    pub rect: [u32; 4],
}

/// The phase-function sampling check's uniforms (`PhaseTest` in shaders/phase_test.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct PhaseTestUniforms {
    pub params: [f32; 4],
    pub bsdf: [f32; 4],
    pub normal: [f32; 4],
    pub counts: [u32; 4],
}

/// Bytes between the uniform blocks of consecutive dispatches bound at dynamic offsets (the
/// path tracer's paths, the denoiser's iterations): 256 is the largest dynamic-offset
/// alignment a device may ask for.
pub const UNIFORM_STRIDE: u64 = 256;

/// The denoiser's uniforms (`Denoise` in shaders/denoise.wgsl), one block per iteration.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct DenoiseUniforms {
    pub rect: [u32; 4],
    pub size: [u32; 4],
    pub params: [f32; 4],
}

/// The uniforms of what the path tracer shows (`Show` in shaders/pathtrace_show.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct ShowUniforms {
    pub rect: [u32; 4],
    pub size: [u32; 4],
}

/// The depth comparison's uniforms (`DepthCompare` in shaders/depth_changed.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct DepthCompareUniforms {
    pub size: [u32; 4],
}

/// The environment passes' uniforms (`EnvBuild` in shaders/environment.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct EnvUniforms {
    pub zenith: [f32; 4],
    pub horizon: [f32; 4],
    pub ground: [f32; 4],
    pub sun: [f32; 4],
    pub sun_color: [f32; 4],
    pub scale: [f32; 4],
    pub params: [u32; 4],
}

/// One intermixed volume as dvr.wgsl reads it (`IntermixedVolume`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct IntermixedVolumeUniforms {
    pub world_to_index: [f32; 16],
    pub gradient_to_world: [f32; 16],
    /// Points per axis, then the first z of the volume's points in the atlas.
    pub dims: [f32; 4],
    /// The transfer tables' scalar at the first entry, 1 / their scalar width, and 1 where
    /// the volume and its tables are read at the nearest point and entry (0: linearly).
    pub range: [f32; 4],
}

/// The intermixed volumes' uniforms (`Intermix` in shaders/dvr.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct IntermixUniforms {
    /// The world box the rays march: every volume's, the main one's included.
    pub box_lo: [f32; 4],
    pub box_hi: [f32; 4],
    pub volumes: [IntermixedVolumeUniforms; MAX_INTERMIXED],
}

pub fn mat(m: glam::DMat4) -> [f32; 16] {
    m.as_mat4().to_cols_array()
}

// ---------------------------------------------------------------------------------------
// Constants shared with WGSL. Defined here only: `shaders::compose` prepends each as a WGSL
// `const` declaration (WGSL_CONSTANTS) to every pass, so the shaders cannot disagree.
// ---------------------------------------------------------------------------------------

/// Blend mode codes (`frame.blend`; BlendMode::code).
pub const BLEND_COMPOSITE: u32 = 0;
pub const BLEND_MAXIMUM: u32 = 1;
pub const BLEND_MINIMUM: u32 = 2;
pub const BLEND_AVERAGE: u32 = 3;
pub const BLEND_ADDITIVE: u32 = 4;
pub const BLEND_ISOSURFACE: u32 = 5;
pub const BLEND_PATHTRACE: u32 = 6;
pub const BLEND_SLICE: u32 = 7;

/// Frame flag bits (`frame.flags`).
pub const FLAG_JITTER: u32 = 2;
pub const FLAG_TWO_SIDED: u32 = 16;
pub const FLAG_INDEPENDENT: u32 = 64;
pub const FLAG_DEPTH_INPUT: u32 = 128;
pub const FLAG_AVERAGE_RANGE: u32 = 1024;
pub const FLAG_EXTREMUM_DEPTH: u32 = 2048;
pub const FLAG_PIECE: u32 = 4096;
pub const FLAG_DEPTH_RANGE: u32 = 8192;

/// Bits per axis of a page-table entry's slot position (lib/volume.wgsl).
pub const PAGE_SLOT_BITS: u32 = 10;
/// A page-table entry with this bit set: the brick is not resident and reads as the constant
/// its texel in the empty bricks' values holds (lib/volume.wgsl).
pub const PAGE_EMPTY: u32 = 1 << 31;
/// A page-table entry with this bit set: the brick is needed but waits for a later pass of
/// a streamed frame (the ray stops there and resumes then; shaders/dvr.wgsl).
pub const PAGE_MISSING: u32 = 1 << 30;

/// What the request buffer holds for a brick a preview frame's rays sampled from a coarser
/// level's stand-in, and from the brick itself (lib/volume.wgsl, resources/lod.rs).
pub const READ_STAND_IN: u32 = 1;
pub const READ_FINE: u32 = 2;

/// What the DVR pass's mask does (its MASK pipeline constant): nothing, leave out the
/// samples at points holding 0, classify labelled samples with their labels' tables.
pub const MASK_NONE: u32 = 0;
pub const MASK_BINARY: u32 = 1;
pub const MASK_LABELS: u32 = 2;

/// Most lights and clipping planes a frame takes (the sizes of Frame's arrays).
pub const MAX_LIGHTS: usize = 8;
pub const MAX_CLIP_PLANES: usize = 8;
/// Most volumes intermixed with the main one (IntermixUniforms' array).
pub const MAX_INTERMIXED: usize = 3;
/// Entries per transfer-function table.
pub const TABLE_SIZE: usize = 1024;

/// Most iso-values per frame, and the isosurface options.
pub const ISO_MAX_VALUES: usize = 8;
pub const SPECULAR_CONE: u32 = 0;
pub const SPECULAR_IMPORTANCE: u32 = 1;
pub const ISO_FLAG_BACKGROUND: u32 = 1;

/// Environment sources of the environment build pass.
pub const ENV_SKY: u32 = 0;
pub const ENV_EQUIRECT: u32 = 1;

/// Path tracing flags (`pt.options.x`) and scattering regions (`pt.counts.z`).
pub const PT_FLAG_BACKGROUND: u32 = 1;
pub const PT_FLAG_ATTENUATION: u32 = 2;
pub const PT_FLAG_GUIDE: u32 = 4;
pub const PT_SCATTER_NONE: u32 = 0;
pub const PT_SCATTER_SURFACES: u32 = 1;
pub const PT_SCATTER_BETWEEN: u32 = 2;
pub const PT_SCATTER_EVERYWHERE: u32 = 3;
/// Largest opacity the path tracer's medium takes, so that extinction stays finite
/// (σ ≤ 9.2 per unit distance).
pub const PT_MAX_OPACITY: f64 = 0.9999;

/// The flag word with each `(on, bit)` pair's bit set where `on`.
pub fn flag_bits(flags: &[(bool, u32)]) -> u32 {
    flags
        .iter()
        .filter(|(on, _)| *on)
        .fold(0, |w, (_, bit)| w | bit)
}

/// A constant's WGSL value.
#[derive(Clone, Copy, Debug)]
pub enum Wgsl {
    U32(u32),
    F32(f32),
}

/// Every constant above by its WGSL name.
pub const WGSL_CONSTANTS: &[(&str, Wgsl)] = &[
    ("BLEND_COMPOSITE", Wgsl::U32(BLEND_COMPOSITE)),
    ("BLEND_MAXIMUM", Wgsl::U32(BLEND_MAXIMUM)),
    ("BLEND_MINIMUM", Wgsl::U32(BLEND_MINIMUM)),
    ("BLEND_AVERAGE", Wgsl::U32(BLEND_AVERAGE)),
    ("BLEND_ADDITIVE", Wgsl::U32(BLEND_ADDITIVE)),
    ("BLEND_ISOSURFACE", Wgsl::U32(BLEND_ISOSURFACE)),
    ("BLEND_PATHTRACE", Wgsl::U32(BLEND_PATHTRACE)),
    ("BLEND_SLICE", Wgsl::U32(BLEND_SLICE)),
    ("FLAG_JITTER", Wgsl::U32(FLAG_JITTER)),
    ("FLAG_TWO_SIDED", Wgsl::U32(FLAG_TWO_SIDED)),
    ("FLAG_INDEPENDENT", Wgsl::U32(FLAG_INDEPENDENT)),
    ("FLAG_DEPTH_INPUT", Wgsl::U32(FLAG_DEPTH_INPUT)),
    ("FLAG_AVERAGE_RANGE", Wgsl::U32(FLAG_AVERAGE_RANGE)),
    ("FLAG_EXTREMUM_DEPTH", Wgsl::U32(FLAG_EXTREMUM_DEPTH)),
    ("FLAG_PIECE", Wgsl::U32(FLAG_PIECE)),
    ("FLAG_DEPTH_RANGE", Wgsl::U32(FLAG_DEPTH_RANGE)),
    ("MASK_NONE", Wgsl::U32(MASK_NONE)),
    ("MASK_BINARY", Wgsl::U32(MASK_BINARY)),
    ("MASK_LABELS", Wgsl::U32(MASK_LABELS)),
    ("MAX_LIGHTS", Wgsl::U32(MAX_LIGHTS as u32)),
    ("MAX_INTERMIXED", Wgsl::U32(MAX_INTERMIXED as u32)),
    ("PAGE_SLOT_BITS", Wgsl::U32(PAGE_SLOT_BITS)),
    ("PAGE_EMPTY", Wgsl::U32(PAGE_EMPTY)),
    ("PAGE_MISSING", Wgsl::U32(PAGE_MISSING)),
    ("READ_STAND_IN", Wgsl::U32(READ_STAND_IN)),
    ("READ_FINE", Wgsl::U32(READ_FINE)),
    ("MAX_CLIP", Wgsl::U32(MAX_CLIP_PLANES as u32)),
    ("MESH_KNOTS", Wgsl::U32(MESH_KNOTS as u32)),
    ("MESH_EVERY_ENTRY", Wgsl::U32(MESH_EVERY_ENTRY)),
    ("MESH_BVH_STACK", Wgsl::U32(MESH_BVH_STACK as u32)),
    ("MESH_OPAQUE_WORDS", Wgsl::U32(MESH_OPAQUE_WORDS as u32)),
    ("TABLE_N", Wgsl::U32(TABLE_SIZE as u32)),
    ("MAX_ISO", Wgsl::U32(ISO_MAX_VALUES as u32)),
    ("SPECULAR_CONE", Wgsl::U32(SPECULAR_CONE)),
    ("SPECULAR_IMPORTANCE", Wgsl::U32(SPECULAR_IMPORTANCE)),
    ("ISO_FLAG_BACKGROUND", Wgsl::U32(ISO_FLAG_BACKGROUND)),
    ("ENV_SKY", Wgsl::U32(ENV_SKY)),
    ("ENV_EQUIRECT", Wgsl::U32(ENV_EQUIRECT)),
    ("PT_FLAG_BACKGROUND", Wgsl::U32(PT_FLAG_BACKGROUND)),
    ("PT_FLAG_ATTENUATION", Wgsl::U32(PT_FLAG_ATTENUATION)),
    ("PT_FLAG_GUIDE", Wgsl::U32(PT_FLAG_GUIDE)),
    ("PT_SCATTER_NONE", Wgsl::U32(PT_SCATTER_NONE)),
    ("PT_SCATTER_SURFACES", Wgsl::U32(PT_SCATTER_SURFACES)),
    ("PT_SCATTER_BETWEEN", Wgsl::U32(PT_SCATTER_BETWEEN)),
    ("PT_SCATTER_EVERYWHERE", Wgsl::U32(PT_SCATTER_EVERYWHERE)),
    ("PT_MAX_OPACITY", Wgsl::F32(PT_MAX_OPACITY as f32)),
];

/// The WGSL declarations of [`WGSL_CONSTANTS`], one line each.
pub fn wgsl_constants() -> String {
    WGSL_CONSTANTS
        .iter()
        .map(|(name, v)| match v {
            Wgsl::U32(x) => format!("const {name}: u32 = {x}u;\n"),
            Wgsl::F32(x) => format!("const {name}: f32 = {x:?};\n"),
        })
        .collect()
}

#[cfg(test)]
mod layout_tests {
    use super::*;
    use std::mem::{offset_of, size_of};

    fn module(pass: &str) -> naga::Module {
        naga::front::wgsl::parse_str(&crate::gpu::shaders::compose(pass)).expect("WGSL parses")
    }

    /// (member name, offset) of a WGSL struct, and its size.
    fn wgsl_struct(m: &naga::Module, name: &str) -> (Vec<(String, u32)>, u32) {
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(m.to_ctx()).unwrap();
        for (h, t) in m.types.iter() {
            if t.name.as_deref() == Some(name) {
                if let naga::TypeInner::Struct { members, span } = &t.inner {
                    let _ = h;
                    return (
                        members
                            .iter()
                            .map(|mm| (mm.name.clone().unwrap(), mm.offset))
                            .collect(),
                        *span,
                    );
                }
            }
        }
        panic!("struct {name} not found");
    }

    macro_rules! check {
        ($m:expr, $wgsl:literal, $rust:ty, [$($field:ident),* $(,)?]) => {{
            let (members, size) = wgsl_struct(&$m, $wgsl);
            let rust: Vec<(String, u32)> = vec![$((stringify!($field).to_string(), offset_of!($rust, $field) as u32)),*];
            assert_eq!(members, rust, "{} field offsets differ between WGSL and Rust", $wgsl);
            assert_eq!(size as usize, size_of::<$rust>(), "{} size differs", $wgsl);
        }};
    }

    #[test]
    fn frame_uniforms_match_wgsl() {
        // lib/common.wgsl's Frame and PixelState, as every pass that includes it composes it
        for pass in [
            "dvr.wgsl",
            "firsthit.wgsl",
            "deferred.wgsl",
            "pathtrace.wgsl",
        ] {
            let m = module(pass);
            check!(
                m,
                "Frame",
                FrameUniforms,
                [
                    camera,
                    world_to_index,
                    index_to_data,
                    gradient_to_world,
                    dims,
                    scalar_scale,
                    scalar_shift,
                    tf_lo,
                    tf_inv_width,
                    go_lo,
                    go_inv_width,
                    weights,
                    material,
                    crop_lo,
                    crop_hi,
                    sample_distance,
                    termination,
                    depth_threshold,
                    gradient_epsilon,
                    average_range,
                    additive_scale,
                    scatter,
                    clip,
                    clipped_value,
                    whole_lo,
                    whole_hi,
                    lights,
                    width,
                    height,
                    camera_index,
                    jitter_seed,
                    blend,
                    flags,
                    crop_regions,
                    unused,
                    clip_planes,
                    light_count,
                    block_size,
                    components,
                    occupancy_dims,
                    rect,
                    component_materials,
                    slice,
                    mask,
                    labels,
                    t2d_lo,
                    t2d_inv_width,
                    t2d_inv_gmax
                ]
            );
            let (_, ps) = wgsl_struct(&m, "PixelState");
            assert_eq!(ps as u64, PIXEL_STATE_BYTES);
        }
        let m = module("dvr.wgsl");
        check!(
            m,
            "Light",
            GpuLight,
            [position, spot, diffuse, specular, ambient, attenuation]
        );
        check!(m, "Pool", PoolUniforms, [brick, grid, slot, inv_size]);
        check!(
            m,
            "IntermixedVolume",
            IntermixedVolumeUniforms,
            [world_to_index, gradient_to_world, dims, range]
        );
        check!(m, "Intermix", IntermixUniforms, [box_lo, box_hi, volumes]);
    }

    #[test]
    fn iso_uniforms_match_wgsl() {
        for pass in ["firsthit.wgsl", "deferred.wgsl"] {
            let m = module(pass);
            check!(
                m,
                "Iso",
                IsoUniforms,
                [
                    env_rotation,
                    values,
                    colors,
                    shininess,
                    ao,
                    env,
                    counts,
                    options,
                    shade_rect,
                    scatter
                ]
            );
        }
        let m = module("environment.wgsl");
        check!(
            m,
            "EnvBuild",
            EnvUniforms,
            [zenith, horizon, ground, sun, sun_color, scale, params]
        );
        let m = module("pathtrace.wgsl");
        check!(
            m,
            "PathTrace",
            PathTraceUniforms,
            [env_rotation, medium, surface, lobe, counts, options, rect]
        );
        let m = module("unstructured.wgsl");
        check!(
            m,
            "Mesh",
            MeshUniforms,
            [counts, unit, split, knots, opaque, halves, shadow]
        );
        let m = module("denoise.wgsl");
        check!(m, "Denoise", DenoiseUniforms, [rect, size, params]);
        let m = module("pathtrace_show.wgsl");
        check!(m, "Show", ShowUniforms, [rect, size]);
        let m = module("depth_changed.wgsl");
        check!(m, "DepthCompare", DepthCompareUniforms, [size]);
        let m = module("phase_test.wgsl");
        check!(
            m,
            "PhaseTest",
            PhaseTestUniforms,
            [params, bsdf, normal, counts]
        );
    }

    #[test]
    fn every_file_is_part_of_a_pass() {
        let used: Vec<String> = crate::gpu::shaders::PASSES
            .iter()
            .flat_map(|p| crate::gpu::shaders::files_of(p))
            .collect();
        for (path, _) in crate::gpu::shaders::FILES {
            assert!(
                used.iter().any(|u| u == path),
                "{path} is listed in shaders::FILES but no pass includes it"
            );
        }
    }

    fn validate(path: &str, m: &naga::Module) {
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(m)
        .unwrap_or_else(|e| panic!("{path} fails validation: {e:?}"));
    }

    #[test]
    fn every_pass_validates_with_naga() {
        for pass in crate::gpu::shaders::PASSES {
            validate(pass, &module(pass));
        }
    }

    /// A library file includes what it uses: composed alone (with its own includes), it
    /// parses and validates, so no pass has to include its dependencies for it, in order.
    #[test]
    fn every_library_file_includes_what_it_uses() {
        let mut failures = Vec::new();
        for (path, _) in crate::gpu::shaders::FILES {
            if path.starts_with("lib/") {
                match naga::front::wgsl::parse_str(&crate::gpu::shaders::compose(path)) {
                    Ok(m) => validate(path, &m),
                    Err(e) => failures.push(format!("{path}: {e}")),
                }
            }
        }
        assert!(
            failures.is_empty(),
            "composed alone:\n{}",
            failures.join("\n")
        );
    }
}
