//! Binding slots, named once: the Rust layouts and bind groups use these constants, and
//! every pass's WGSL is composed with them as `SLOT_*` constants (`@binding(SLOT_FRAME)`),
//! so that the two sides cannot disagree on a number. `passes::layout_tests` checks each
//! pass's WGSL bindings against its Rust layout.
//!
//! Group 0 holds a pass's own resources; the slots here are the ones the shared WGSL files
//! (shaders/lib) and the ray-casting pass declare. Group 1 is a volume's bricks.

/// Group 0: the frame's uniforms (lib/common.wgsl).
pub const FRAME: u32 = 0;
/// The transfer functions' tables (lib/common.wgsl).
pub const TABLES: u32 = 1;
/// The ray caster's per-block scalar ranges (dvr.wgsl, RANGE_SKIP).
pub const BLOCK_RANGE: u32 = 2;
/// The occupancy grid (lib/march.wgsl).
pub const OCCUPANCY: u32 = 3;
/// The host's opaque depth (lib/march.wgsl).
pub const DEPTH_IN: u32 = 4;
/// The output colour and depth (lib/output.wgsl).
pub const OUT_COLOR: u32 = 5;
pub const OUT_DEPTH: u32 = 6;
/// The ray caster's per-pixel ray state (dvr.wgsl).
pub const RAY_STATE: u32 = 7;
/// The isosurface uniforms (lib/iso.wgsl; the isosurface passes have no ray state).
pub const ISO: u32 = 7;
/// The pre-integration tables and the mask (lib/classify.wgsl).
pub const PREINT_TABLES: u32 = 9;
pub const MASK: u32 = 10;
/// An unstructured volume (unstructured.wgsl): its uniforms, points, tetrahedra,
/// neighbours, cell scalars, boundary hierarchy and boundary triangles.
pub const MESH: u32 = 11;
pub const MESH_POINTS: u32 = 12;
pub const MESH_TETS: u32 = 13;
pub const MESH_NEIGHBOURS: u32 = 14;
pub const MESH_CELL_SCALARS: u32 = 15;
pub const MESH_NODES: u32 = 16;
pub const MESH_BOUNDARY: u32 = 17;
/// The intermixed volumes (lib/intermix.wgsl).
pub const INTERMIX: u32 = 18;
pub const INTERMIX_ATLAS: u32 = 19;
pub const INTERMIX_TABLES: u32 = 20;
pub const INTERMIX_SAMPLER: u32 = 21;
/// The blanking mask (lib/blanking.wgsl).
pub const BLANKING: u32 = 22;
/// A rectilinear grid's coordinate lookup (lib/rectilinear.wgsl).
pub const GRID_LOOKUP: u32 = 23;
/// The 2D transfer functions (lib/table2d.wgsl).
pub const TABLES_2D: u32 = 24;
/// Where each pixel's ray starts in a depth range (dvr.wgsl).
pub const DEPTH_NEAR: u32 = 25;
/// An unstructured volume's gradient per point (unstructured.wgsl).
pub const MESH_GRADIENTS: u32 = 26;
/// The second binding of an unstructured volume's tetrahedra and neighbours (lib/mesh.wgsl),
/// where one binding of the device holds fewer than the mesh's.
pub const MESH_TETS_HI: u32 = 31;
pub const MESH_NEIGHBOURS_HI: u32 = 32;
/// The running integral of a mesh's opacity row (lib/mesh.wgsl `segment_depth`).
pub const MESH_DEPTH: u32 = 33;
/// The path tracers' own (lib/pathtrace.wgsl): the accumulated sums and moments, the
/// uniforms (one block per dispatch), the environment's cube, its sampler and its sampling
/// distribution, the denoiser's guide sums.
pub const PT_ACCUM: u32 = 2;
pub const PT_MOMENTS: u32 = 5;
pub const PT_UNIFORMS: u32 = 7;
pub const PT_ENV_CUBE: u32 = 27;
pub const PT_ENV_SAMPLER: u32 = 28;
pub const PT_ENV_CDF: u32 = 29;
pub const PT_GUIDE: u32 = 30;

/// Group 1, a volume's bricks (lib/volume.wgsl): the pool's uniforms, the pool texture and
/// its sampler, the precomputed gradients, the page table, the non-resident bricks'
/// constants and the preview frames' brick requests.
pub const POOL: u32 = 0;
pub const VOLUME: u32 = 1;
pub const VOLUME_SAMPLER: u32 = 2;
pub const GRADIENTS: u32 = 3;
pub const PAGE_TABLE: u32 = 4;
pub const BRICK_CONSTANTS: u32 = 5;
pub const BRICK_REQUESTS: u32 = 6;

/// Every slot above by its WGSL name.
pub const WGSL_SLOTS: &[(&str, u32)] = &[
    ("SLOT_FRAME", FRAME),
    ("SLOT_TABLES", TABLES),
    ("SLOT_BLOCK_RANGE", BLOCK_RANGE),
    ("SLOT_OCCUPANCY", OCCUPANCY),
    ("SLOT_DEPTH_IN", DEPTH_IN),
    ("SLOT_OUT_COLOR", OUT_COLOR),
    ("SLOT_OUT_DEPTH", OUT_DEPTH),
    ("SLOT_RAY_STATE", RAY_STATE),
    ("SLOT_ISO", ISO),
    ("SLOT_PREINT_TABLES", PREINT_TABLES),
    ("SLOT_MASK", MASK),
    ("SLOT_MESH", MESH),
    ("SLOT_MESH_POINTS", MESH_POINTS),
    ("SLOT_MESH_TETS", MESH_TETS),
    ("SLOT_MESH_NEIGHBOURS", MESH_NEIGHBOURS),
    ("SLOT_MESH_CELL_SCALARS", MESH_CELL_SCALARS),
    ("SLOT_MESH_NODES", MESH_NODES),
    ("SLOT_MESH_BOUNDARY", MESH_BOUNDARY),
    ("SLOT_MESH_GRADIENTS", MESH_GRADIENTS),
    ("SLOT_MESH_TETS_HI", MESH_TETS_HI),
    ("SLOT_MESH_NEIGHBOURS_HI", MESH_NEIGHBOURS_HI),
    ("SLOT_MESH_DEPTH", MESH_DEPTH),
    ("SLOT_PT_ACCUM", PT_ACCUM),
    ("SLOT_PT_MOMENTS", PT_MOMENTS),
    ("SLOT_PT_UNIFORMS", PT_UNIFORMS),
    ("SLOT_PT_ENV_CUBE", PT_ENV_CUBE),
    ("SLOT_PT_ENV_SAMPLER", PT_ENV_SAMPLER),
    ("SLOT_PT_ENV_CDF", PT_ENV_CDF),
    ("SLOT_PT_GUIDE", PT_GUIDE),
    ("SLOT_INTERMIX", INTERMIX),
    ("SLOT_INTERMIX_ATLAS", INTERMIX_ATLAS),
    ("SLOT_INTERMIX_TABLES", INTERMIX_TABLES),
    ("SLOT_INTERMIX_SAMPLER", INTERMIX_SAMPLER),
    ("SLOT_BLANKING", BLANKING),
    ("SLOT_GRID_LOOKUP", GRID_LOOKUP),
    ("SLOT_TABLES_2D", TABLES_2D),
    ("SLOT_DEPTH_NEAR", DEPTH_NEAR),
    ("SLOT_POOL", POOL),
    ("SLOT_VOLUME", VOLUME),
    ("SLOT_VOLUME_SAMPLER", VOLUME_SAMPLER),
    ("SLOT_GRADIENTS", GRADIENTS),
    ("SLOT_PAGE_TABLE", PAGE_TABLE),
    ("SLOT_BRICK_CONSTANTS", BRICK_CONSTANTS),
    ("SLOT_BRICK_REQUESTS", BRICK_REQUESTS),
];
