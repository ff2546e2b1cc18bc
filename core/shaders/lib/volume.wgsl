// The volume as the ray-casting passes see it (group 1): bricks in slots of a pool texture
// and a page table that maps each brick to its slot, sampled in index space and converted
// back to scalar units. A sample first makes the brick holding it current (`locate`): the
// page table is read when a ray enters a brick, not at every sample. A brick the frame does
// not need (nothing in it is visible) is not resident and reads as a constant from its own
// range, which is as invisible as every value of the brick. A volume of one brick
// (SINGLE_BRICK) is its own texture and is sampled directly.
#include "lib/common.wgsl"

struct Pool {
    brick: vec4<f32>,     // x: cells per brick edge, y: apron points around a brick's core,
                          // z: 1 when rays report the bricks they read (a preview frame)
    grid: vec4<u32>,      // bricks per axis
    slot: vec4<f32>,      // points per slot, per axis
    inv_size: vec4<f32>,  // 1 / the pool texture's size in points, per axis
}

@group(1) @binding(SLOT_POOL) var<uniform> pool_ubo: Pool;
// A private copy filled by each entry point (`enter_volume`), as lib/common.wgsl's `frame`.
var<private> pool: Pool;
@group(1) @binding(SLOT_VOLUME) var volume_tex: texture_3d<f32>;
@group(1) @binding(SLOT_VOLUME_SAMPLER) var volume_sampler: sampler;
// The first component's central differences per texel of the pool (shaders/gradient.wgsl),
// where the upload made them (PRECOMPUTED_GRADIENT); otherwise the pool again, unused.
@group(1) @binding(SLOT_GRADIENTS) var gradient_tex: texture_3d<f32>;
// Per brick, x: its slot's position in the pool (PAGE_SLOT_BITS bits per axis, x lowest),
// or PAGE_EMPTY when it is not resident, or PAGE_MISSING when a later pass of a streamed
// frame brings it; y: 0, or, in a preview frame where the brick is not resident, the
// log2 of the factor of the coarser level whose brick in that slot stands in for it.
@group(1) @binding(SLOT_PAGE_TABLE) var page_table: texture_3d<u32>;
// Per brick: the texel value a non-resident brick reads as (each component's lowest value).
@group(1) @binding(SLOT_BRICK_CONSTANTS) var brick_constants: texture_3d<f32>;
// Per brick, in a preview frame: READ_STAND_IN when a ray sampled it from a coarser level's
// stand-in, READ_FINE when from the brick itself (what the next preview frame brings and
// keeps, resources/lod.rs).
@group(1) @binding(SLOT_BRICK_REQUESTS) var<storage, read_write> brick_requests: array<u32>;

// The volume is one brick, its texture the pool: no page-table lookups (a pipeline
// constant each pass sets from the volume).
override SINGLE_BRICK: bool = true;

// The current brick.
struct Brick {
    core_lo: vec3<f32>,   // index-space box of the brick's own cells
    core_hi: vec3<f32>,
    tex_lo: vec3<f32>,    // index-space point at the pool's texel 0 (p − tex_lo: pool texels)
    slot_lo: vec3<f32>,   // the brick's slot: first and last texel in the pool
    slot_hi: vec3<f32>,
    empty: bool,          // not resident: every sample reads `constant`
    constant: vec4<f32>,
    missing: bool,        // needed, resident in a later pass of a streamed frame
    inv_scale: f32,       // 1, or 1 / the factor of the coarser level standing in for it
}

var<private> brick: Brick;

fn enter_brick(cell: vec3<u32>) {
    let page = textureLoad(page_table, vec3<i32>(cell), 0).xy;
    let e = page.x;
    brick.empty = (e & PAGE_EMPTY) != 0u;
    brick.missing = (e & PAGE_MISSING) != 0u;
    brick.constant = textureLoad(brick_constants, vec3<i32>(cell), 0);
    let m = (1u << PAGE_SLOT_BITS) - 1u;
    let s = vec3<u32>(e & m, (e >> PAGE_SLOT_BITS) & m, e >> (2u * PAGE_SLOT_BITS));
    let slot = vec3<f32>(s) * pool.slot.xyz;
    brick.core_lo = vec3<f32>(cell) * pool.brick.x;
    brick.core_hi = min(brick.core_lo + pool.brick.x, frame.dims.xyz - 1.0);
    // A stand-in is the brick of the coarser level holding this one, sampled at p / factor.
    brick.inv_scale = 1.0 / f32(1u << page.y);
    brick.tex_lo = vec3<f32>(cell >> vec3<u32>(page.y)) * pool.brick.x - pool.brick.y - slot;
    if (pool.brick.z != 0.0) {
        brick_requests[cell.x + pool.grid.x * (cell.y + pool.grid.y * cell.z)] =
            select(READ_FINE, READ_STAND_IN, page.y != 0u);
    }
    brick.slot_lo = slot;
    brick.slot_hi = slot + pool.slot.xyz - 1.0;
}

// Called by each entry point after `frame = frame_ubo;`.
fn enter_volume() {
    pool = pool_ubo;
    enter_brick(vec3<u32>(0u));
}

// How far past its core (index units) the current brick keeps serving samples: 0, or up to
// one point less than the apron, which still holds every point trilinear interpolation
// and central differences read (shaders/dvr.wgsl sets it when streaming, so that a sample
// just behind a brick face is read from the brick ahead).
var<private> locate_slack: f32 = 0.0;

// Index-space point p clamped to the volume (as a clamping sampler reads a point outside),
// with a brick serving it made current: the current one if p lies within `slack` of its
// core, otherwise the one holding it.
fn locate_within(p: vec3<f32>, slack: f32) -> vec3<f32> {
    if (SINGLE_BRICK) {
        return p;
    }
    let q = clamp(p, vec3<f32>(0.0), frame.dims.xyz - 1.0);
    if (any(q < brick.core_lo - slack) || any(q > brick.core_hi + slack)) {
        enter_brick(min(vec3<u32>(q / pool.brick.x), pool.grid.xyz - 1u));
    }
    return q;
}

fn locate(p: vec3<f32>) -> vec3<f32> {
    return locate_within(p, locate_slack);
}

// Streamed frames: whether the sample at p, on a ray going along d, waits for a brick a
// later pass brings, leaving a brick that serves it current. The brick just ahead along
// the ray serves it when resident (a sample on a face is served by either brick, whose
// aprons overlap, and the one behind may be gone); failing that, the brick `locate_slack`
// ahead, whose apron holds p too (a ray resuming a step behind a face whose brick is gone).
fn waits(p: vec3<f32>, d: vec3<f32>) -> bool {
    let u = d / max(length(d), 1e-30);
    locate_within(p + 1e-3 * u, 0.0);
    if (!brick.missing) {
        return false;
    }
    locate_within(p + locate_slack * u, 0.0);
    return brick.missing;
}

// Read gradients from gradient_tex (one fetch) instead of six volume fetches: the same
// values (a pipeline constant; single-component volumes only).
override PRECOMPUTED_GRADIENT: bool = false;
// Forward differences (3 samples) instead of central ones (6). A pipeline constant, not a
// flag: lavapipe runs both sides of a branch on a uniform value, so a flag would cost the
// 6 samples and the 3.
override FORWARD_DIFF: bool = false;
// VTK's UseClippedVoxelIntensity: a gradient's neighbour beyond a clipping plane reads
// frame.clipped_value instead of the data (a pipeline constant of the DVR pass).
override CLIPPED_VOXEL: bool = false;

// Pool texture coordinate of index-space point p (in the brick that holds it).
fn pool_coord(p: vec3<f32>) -> vec3<f32> {
    return (locate(p) * brick.inv_scale - brick.tex_lo + 0.5) * pool.inv_size.xyz;
}

// The cubic B-spline of the points instead of trilinear interpolation (Interpolation::Cubic;
// a pipeline constant, with the linear sampler).
override CUBIC: bool = false;

// The cubic B-spline at pool texture coordinate tc, from eight trilinear fetches: along each
// axis the four weights of the points around it fold into two linear fetches (Sigg and
// Hadwiger, GPU Gems 2, ch. 20).
fn cubic_bspline(tc: vec3<f32>) -> vec4<f32> {
    let size = 1.0 / pool.inv_size.xyz;
    let x = tc * size - 0.5;
    let i = floor(x);
    let f = x - i;
    let g = 1.0 - f;
    let w0 = g * g * g / 6.0;
    let w1 = (4.0 - 6.0 * f * f + 3.0 * f * f * f) / 6.0;
    let w3 = f * f * f / 6.0;
    let w2 = 1.0 - w0 - w1 - w3;
    let s0 = w0 + w1;
    let s1 = w2 + w3;
    // the two fetch positions per axis (texel centres at i + 0.5)
    let h0 = (i - 0.5 + w1 / s0) * pool.inv_size.xyz;
    let h1 = (i + 1.5 + w3 / s1) * pool.inv_size.xyz;
    var out = vec4<f32>(0.0);
    for (var c = 0u; c < 8u; c = c + 1u) {
        let pick = vec3<bool>((c & 1u) != 0u, (c & 2u) != 0u, (c & 4u) != 0u);
        let at = select(h0, h1, pick);
        let w = select(s0, s1, pick);
        out = out + w.x * w.y * w.z * textureSampleLevel(volume_tex, volume_sampler, at, 0.0);
    }
    return out;
}

// Raw texel value (normalised storage) at index-space point p.
fn sample_texel(p: vec3<f32>) -> vec4<f32> {
    let tc = pool_coord(p);
    var v: vec4<f32>;
    if (CUBIC) {
        v = cubic_bspline(tc);
    } else {
        v = textureSampleLevel(volume_tex, volume_sampler, tc, 0.0);
    }
    if (SINGLE_BRICK) {
        return v;
    }
    return select(v, brick.constant, brick.empty);
}

// Scalars (data units) of every component at texture coordinate tc.
fn scalars_at(tc: vec3<f32>) -> vec4<f32> {
    return textureSampleLevel(volume_tex, volume_sampler, tc, 0.0) * frame.scalar_scale + frame.scalar_shift;
}

// Scalars (data units) of every component at index-space point p.
fn sample_scalars(p: vec3<f32>) -> vec4<f32> {
    return sample_texel(p) * frame.scalar_scale + frame.scalar_shift;
}

struct Gradient {
    x: vec4<f32>,  // d/di of each component
    y: vec4<f32>,
    z: vec4<f32>,
}

// Index-space gradient of every component at p: central differences (6 samples) or forward
// differences from the centre value s (3 samples).
fn brick_gradient(p: vec3<f32>, s: vec4<f32>) -> Gradient {
    return gradient_tc(pool_coord(p), p, s);
}

// Whether index-space point q lies beyond a clipping plane.
fn beyond_clip(q: vec3<f32>) -> bool {
    for (var i = 0u; i < frame.clip_planes; i = i + 1u) {
        let pl = frame.clip[i];
        if (dot(pl.xyz, q) + pl.w < 0.0) {
            return true;
        }
    }
    return false;
}

// Scalars of a gradient's neighbour at pool texture coordinate tc, index-space point q.
fn neighbour(tc: vec3<f32>, q: vec3<f32>) -> vec4<f32> {
    if (CLIPPED_VOXEL && beyond_clip(q)) {
        return frame.clipped_value;
    }
    return scalars_at(tc);
}

// Index-space gradient of every component at pool texture coordinate tc (index-space point
// p), whose scalars are s: the neighbours one voxel away, offset directly in texture
// coordinates.
fn gradient_tc(tc: vec3<f32>, p: vec3<f32>, s: vec4<f32>) -> Gradient {
    if (PRECOMPUTED_GRADIENT && !FORWARD_DIFF && !CLIPPED_VOXEL) {
        let d = textureSampleLevel(gradient_tex, volume_sampler, tc, 0.0).xyz * brick.inv_scale;
        var g: Gradient;
        g.x = vec4<f32>(d.x, 0.0, 0.0, 0.0);
        g.y = vec4<f32>(d.y, 0.0, 0.0, 0.0);
        g.z = vec4<f32>(d.z, 0.0, 0.0, 0.0);
        return g;
    }
    let dx = vec3<f32>(pool.inv_size.x, 0.0, 0.0);
    let dy = vec3<f32>(0.0, pool.inv_size.y, 0.0);
    let dz = vec3<f32>(0.0, 0.0, pool.inv_size.z);
    var g: Gradient;
    let ex = vec3<f32>(1.0, 0.0, 0.0);
    let ey = vec3<f32>(0.0, 1.0, 0.0);
    let ez = vec3<f32>(0.0, 0.0, 1.0);
    if (FORWARD_DIFF) {
        g.x = neighbour(tc + dx, p + ex) - s;
        g.y = neighbour(tc + dy, p + ey) - s;
        g.z = neighbour(tc + dz, p + ez) - s;
    } else {
        g.x = 0.5 * (neighbour(tc + dx, p + ex) - neighbour(tc - dx, p - ex));
        g.y = 0.5 * (neighbour(tc + dy, p + ey) - neighbour(tc - dy, p - ey));
        g.z = 0.5 * (neighbour(tc + dz, p + ez) - neighbour(tc - dz, p - ez));
    }
    // (per pool texel: a coarser level's texel spans 1 / inv_scale index units)
    g.x = g.x * brick.inv_scale;
    g.y = g.y * brick.inv_scale;
    g.z = g.z * brick.inv_scale;
    return g;
}

// Index-space gradient of every component at p (zero in a non-resident brick, whose
// values are all invisible).
fn gradient_at(p: vec3<f32>, s: vec4<f32>) -> Gradient {
    var g = brick_gradient(p, s);
    if (!SINGLE_BRICK && brick.empty) {
        g.x = vec4<f32>(0.0);
        g.y = vec4<f32>(0.0);
        g.z = vec4<f32>(0.0);
    }
    return g;
}

// The index-space change per unit of the lattice rays march, per axis, at the current
// sample: 1 on a uniform grid; dvr.wgsl's grid_point sets it on a rectilinear one.
var<private> index_slope: vec3<f32> = vec3<f32>(1.0);

// World-space gradient of component c.
fn world_gradient(g: Gradient, c: u32) -> vec3<f32> {
    let d = vec3<f32>(g.x[c], g.y[c], g.z[c]) * index_slope;
    return (frame.gradient_to_world * vec4<f32>(d, 0.0)).xyz;
}

// A mask's value (Renderer::set_mask, one per point of the grid) at the point nearest to
// index-space point p: VTK reads its mask texture with nearest filtering.
fn mask_value(mask: texture_3d<u32>, p: vec3<f32>) -> u32 {
    let q = clamp(p, vec3<f32>(0.0), frame.dims.xyz - 1.0);
    return textureLoad(mask, vec3<i32>(floor(q + 0.5)), 0).x;
}

// MASK_LABELS: label l's table row (after the `components` components' rows), and whether
// the label has rows (1 to the highest label with functions of its own, frame.mask.y).
fn label_row(components: u32, l: u32) -> u32 {
    return components + l - 1u;
}

fn labelled(l: u32) -> bool {
    return l > 0u && f32(l) <= frame.mask.y;
}

// The labels' tables are read at scalar s here.
fn label_coord(s: f32) -> f32 {
    return (s - frame.labels.x) * frame.labels.y;
}
