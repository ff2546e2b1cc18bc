// Shared by every pass: the per-frame uniform block, its constants, the lookup tables and
// small helpers. Mirrored in core/src/gpu/uniforms.rs (FrameUniforms); a unit test checks
// the layouts agree. The constants shared with Rust (BLEND_*, FLAG_*, MAX_LIGHTS, MAX_CLIP,
// TABLE_N: entries per lookup table) are declared from gpu/uniforms.rs when a pass is
// composed.

// Nearest-neighbour interpolation, a pipeline constant: the transfer-function tables are
// read at the nearest entry, as VTK's InterpolationType applies to the tables too (the
// volume itself is read through the brick's nearest sampler; on lavapipe a sampler fetch
// measured faster than textureLoad).
override NEAREST: bool = false;
// Components of the volume a pass reads (one unless it says otherwise).
override NCOMP: u32 = 1u;

struct Light {
    // xyz: world position (positional) or unit vector toward the light (directional);
    // w: 1 positional, 0 directional, 2 headlight (lights each sample along its ray)
    position: vec4<f32>,
    // xyz: unit spot axis (from the light toward its focal point); w: cos(cone angle),
    // -2 when the light has no cone
    spot: vec4<f32>,
    // diffuse colour × intensity; w: spot exponent
    diffuse: vec4<f32>,
    // specular colour × intensity
    specular: vec4<f32>,
    // ambient colour × intensity
    ambient: vec4<f32>,
    // constant, linear, quadratic attenuation
    attenuation: vec4<f32>,
}

struct Frame {
    camera: array<mat4x4<f32>, 2>, // clip → world, world → clip (read in lib/ray.wgsl only)
    world_to_index: mat4x4<f32>,  // world → volume index space (i, j, k)
    index_to_data: mat4x4<f32>,   // index → data coordinates (for cropping)
    gradient_to_world: mat4x4<f32>, // index-space gradient → world gradient (inverse transpose)
    dims: vec4<f32>,              // points per axis; w: components
    scalar_scale: vec4<f32>,      // texel value → scalar, per component
    scalar_shift: vec4<f32>,
    tf_lo: vec4<f32>,             // per component: scalar at the first table entry
    tf_inv_width: vec4<f32>,      // per component: 1 / table scalar width
    go_lo: vec4<f32>,             // gradient-opacity table range, per component
    go_inv_width: vec4<f32>,
    weights: vec4<f32>,           // component weights (independent components)
    material: vec4<f32>,          // ambient, diffuse, specular, specular power
    crop_lo: vec4<f32>,           // cropping planes, data coordinates
    crop_hi: vec4<f32>,
    sample_distance: f32,         // world distance between samples
    termination: f32,             // early ray termination: the opacity a ray stops at
    depth_threshold: f32,         // the opacity at which a ray's depth is taken
    gradient_epsilon: f32,        // shorter gradients shade as having no normal (lib/shading.wgsl)
    average_range: vec4<f32>,     // xy: scalar range the average blend mode keeps
    additive_scale: vec4<f32>,    // per component: sample distance / unit distance
    scatter: vec4<f32>,           // volumetric shadows: x blending (0 off), y anisotropy, z reach (texture units), w 2 / data range
    clip: array<vec4<f32>, 8>,    // index-space planes: keep dot(xyz, p) + w >= 0
    clipped_value: vec4<f32>,     // per component: what gradients read beyond a clipping plane (CLIPPED_VOXEL)
    whole_lo: vec4<f32>,          // FLAG_PIECE: the whole volume's box in this piece's index space
    whole_hi: vec4<f32>,
    lights: array<Light, 8>,
    width: u32,                   // the image's pixels
    height: u32,
    camera_index: u32,            // 0, not a constant to the compiler (lib/ray.wgsl)
    jitter_seed: u32,
    blend: u32,                   // BLEND_* (a pass's BLEND pipeline constant where it has one)
    flags: u32,                   // FLAG_* bits
    crop_regions: u32,            // VTK's cropping region flags (27 bits)
    unused: u32,
    clip_planes: u32,             // clipping planes in `clip`
    light_count: u32,             // lights in `lights`
    block_size: u32,              // points per edge of an occupancy block
    components: u32,              // the volume's components
    occupancy_dims: vec4<u32>,    // blocks per axis
    rect: vec4<u32>,              // pixels the passes cover: x0, y0, x1, y1 (exclusive)
    component_materials: array<vec4<f32>, 4>, // each independent component's material
    slice: vec4<f32>,             // BLEND_SLICE: the index-space plane dot(xyz, p) + w = 0
    mask: vec4<f32>,              // x: label-map blend factor, y: highest label with own tables
    labels: vec4<f32>,            // labels' tables: scalar lo, 1 / width, gradient lo, 1 / width
    t2d_lo: vec4<f32>,            // per component, its 2D table: scalar at the first column's edge,
    t2d_inv_width: vec4<f32>,     // 1 / scalar range,
    t2d_inv_gmax: vec4<f32>,      // 1 / gradient magnitude at the last row's edge (0: first row)
}

@group(0) @binding(SLOT_FRAME) var<uniform> frame_ubo: Frame;
// The passes read the frame's uniforms from this private copy, which each entry point
// fills first (`frame = frame_ubo;`). Lavapipe reads a uniform inside a loop or a branch
// with a masked per-lane gather and a bounds check per lane; the copy is read once per
// invocation, outside all control flow, and what the loop needs stays in registers.
var<private> frame: Frame;
// Per component c, two rows of N entries: row 2·c holds (r, g, b, alpha corrected for the
// step), row 2·c + 1 holds (alpha as given, gradient opacity, 0, 0). Composite reads one
// entry per sample. A texture rather than a storage buffer: lavapipe reads storage buffers
// at per-lane indices one lane at a time.
@group(0) @binding(SLOT_TABLES) var tables: texture_2d<f32>;

// Per-pixel ray state: the first-hit pass's layer counts, and a streamed ray's state between
// the passes of its frame (shaders/dvr.wgsl).
struct PixelState {
    color: vec4<f32>,   // premultiplied RGBA accumulated front to back
    value: vec4<f32>,   // per component: max (MIP), min (MinIP), sum (average, additive)
    misc: vec4<f32>,    // x: samples counted, y: window depth of the depth sample, z: 1 once depth is set, w: next sample of a streamed ray (−1: done)
}

fn has_flag(f: u32) -> bool {
    return (frame.flags & f) != 0u;
}

// Linear lookup into table `which` (0: colour + corrected alpha, 1: alpha & gradient opacity)
// of component `c` at normalised coordinate u in [0, 1] (clamped, like VTK's tables).
fn table_lookup(c: u32, which: u32, u: f32) -> vec4<f32> {
    return row_lookup(tables, i32(2u * c + which), u, NEAREST);
}

// Row `row` of a table texture of TABLE_N entries per row at normalised coordinate u
// (clamped): its nearest entry, or linear between the two around it.
fn row_lookup(t: texture_2d<f32>, row: i32, u: f32, nearest: bool) -> vec4<f32> {
    let x = clamp(u, 0.0, 1.0) * f32(TABLE_N - 1u);
    if (nearest) {
        return textureLoad(t, vec2<i32>(i32(x + 0.5), row), 0);
    }
    let i0 = u32(x);
    let i1 = min(i0 + 1u, TABLE_N - 1u);
    let t0 = textureLoad(t, vec2<i32>(i32(i0), row), 0);
    let t1 = textureLoad(t, vec2<i32>(i32(i1), row), 0);
    return mix(t0, t1, x - f32(i0));
}

fn scalar_coord(c: u32, s: f32) -> f32 {
    return (s - frame.tf_lo[c]) * frame.tf_inv_width[c];
}

// Colour and opacity corrected for the sample distance of scalar s for component c.
fn classify(c: u32, s: f32) -> vec4<f32> {
    return table_lookup(c, 0u, scalar_coord(c, s));
}

// Opacity of scalar s as the transfer function gives it (no step correction).
fn raw_alpha(c: u32, s: f32) -> f32 {
    return table_lookup(c, 1u, scalar_coord(c, s)).x;
}

// Gradient-opacity factor for gradient magnitude m of component c.
fn gradient_opacity(c: u32, m: f32) -> f32 {
    return table_lookup(c, 1u, (m - frame.go_lo[c]) * frame.go_inv_width[c]).y;
}

// Hash of a pixel index to [0, 1): deterministic jitter (PCG).
fn hash01(v: u32) -> f32 {
    var s = v * 747796405u + 2891336453u;
    s = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    s = (s >> 22u) ^ s;
    return f32(s >> 8u) / 16777216.0;
}
