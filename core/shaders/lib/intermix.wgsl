// Volumes intermixed with the main one (Renderer::set_intermixed_volumes, VTK's
// vtkMultiVolume), INTERMIX of them (one component each): their points in one atlas,
// stacked along z from dims.w, classified by tables of their own (two rows each, as
// lib/common.wgsl lays a component's out: colour with the step-corrected opacity, then the
// opacity as given). dvr.wgsl composites them per sample, pathtrace.wgsl adds their media.
#include "lib/common.wgsl"
override INTERMIX: u32 = 0u;

struct IntermixedVolume {
    world_to_index: mat4x4<f32>,
    gradient_to_world: mat4x4<f32>,
    dims: vec4<f32>,
    // x the tables' first scalar, y 1 / their width, z 1 where read at the nearest point
    // and entry, w 1 / the unit distance of its opacity
    range: vec4<f32>,
}

struct Intermix {
    box_lo: vec4<f32>,
    box_hi: vec4<f32>,
    volumes: array<IntermixedVolume, MAX_INTERMIXED>,
}

@group(0) @binding(SLOT_INTERMIX) var<uniform> intermix: Intermix;
@group(0) @binding(SLOT_INTERMIX_ATLAS) var intermix_atlas: texture_3d<f32>;
@group(0) @binding(SLOT_INTERMIX_TABLES) var intermix_tables: texture_2d<f32>;
// Linear where r32float is filterable (INTERMIX_FILTERED: one fetch per value, weighted as
// VTK's textures are), else nearest and unused (the shader interpolates eight loads).
@group(0) @binding(SLOT_INTERMIX_SAMPLER) var intermix_sampler: sampler;
override INTERMIX_FILTERED: bool = false;

// Intermixed volume j's index-space point at world point pos.
fn intermixed_point(j: u32, pos: vec3<f32>) -> vec3<f32> {
    return (intermix.volumes[j].world_to_index * vec4<f32>(pos, 1.0)).xyz;
}

// Intermixed volume j's value at index-space point p (clamped to its grid, as a clamping
// sampler reads): its nearest point where the volume says so (range.z), else trilinear
// between its points.
fn intermixed_value(j: u32, p: vec3<f32>) -> f32 {
    let d = intermix.volumes[j].dims;
    let hi = d.xyz - 1.0;
    let q = clamp(p, vec3<f32>(0.0), hi);
    let z0 = vec3<i32>(0, 0, i32(d.w));
    if (intermix.volumes[j].range.z > 0.0) {
        return textureLoad(intermix_atlas, vec3<i32>(floor(q + 0.5)) + z0, 0).x;
    }
    if (INTERMIX_FILTERED) {
        // (q is clamped to the volume's points: a texel of the next volume in the atlas
        // gets weight 0)
        let size = vec3<f32>(textureDimensions(intermix_atlas));
        let c = (q + vec3<f32>(0.0, 0.0, d.w) + 0.5) / size;
        return textureSampleLevel(intermix_atlas, intermix_sampler, c, 0.0).x;
    }
    let lo = floor(q);
    let f = q - lo;
    let a = vec3<i32>(lo) + z0;
    let b = vec3<i32>(min(lo + 1.0, hi)) + z0;
    let c000 = textureLoad(intermix_atlas, a, 0).x;
    let c100 = textureLoad(intermix_atlas, vec3<i32>(b.x, a.y, a.z), 0).x;
    let c010 = textureLoad(intermix_atlas, vec3<i32>(a.x, b.y, a.z), 0).x;
    let c110 = textureLoad(intermix_atlas, vec3<i32>(b.x, b.y, a.z), 0).x;
    let c001 = textureLoad(intermix_atlas, vec3<i32>(a.x, a.y, b.z), 0).x;
    let c101 = textureLoad(intermix_atlas, vec3<i32>(b.x, a.y, b.z), 0).x;
    let c011 = textureLoad(intermix_atlas, vec3<i32>(a.x, b.y, b.z), 0).x;
    let c111 = textureLoad(intermix_atlas, b, 0).x;
    let x0 = mix(mix(c000, c100, f.x), mix(c010, c110, f.x), f.y);
    let x1 = mix(mix(c001, c101, f.x), mix(c011, c111, f.x), f.y);
    return mix(x0, x1, f.z);
}

// Intermixed volume j's table row `row` (0: colour and step-corrected opacity, 1: opacity
// as given in x) at scalar s: the nearest entry or between the two around it.
fn intermixed_entry(j: u32, row: u32, s: f32) -> vec4<f32> {
    let v = intermix.volumes[j];
    let u = (s - v.range.x) * v.range.y;
    return row_lookup(intermix_tables, i32(2u * j + row), u, v.range.z > 0.0);
}
