// Marching a ray through the volume, shared by the ray-casting passes (dvr, firsthit): the
// ray's segment inside the volume (near/far planes, the host's opaque depth, clipping
// planes), VTK's cropping regions and the occupancy grid for empty-space skipping.
#include "lib/common.wgsl"
#include "lib/ray.wgsl"

// Per block of the occupancy grid (a texture: lavapipe reads storage buffers at per-lane
// indices one lane at a time): non-zero when the block may hold something the pass looks
// for (dvr: some voxel with non-zero opacity, the value then the step multiplier adaptive
// rays take there, 1, 2 or 4; firsthit: some iso-value within the block's range) in the
// low 8 bits, 0 there when the pass can skip it; an empty block's bits 8–31 hold its
// Chebyshev distance in blocks to the nearest occupied one (core/src/resources/tables.rs,
// leap_texels), so that a ray leaps the whole cube of empty blocks around it (leap_exit).
@group(0) @binding(SLOT_OCCUPANCY) var occupancy: texture_3d<u32>;
// The host's opaque depth (window depth per pixel), read when FLAG_DEPTH_INPUT is set.
@group(0) @binding(SLOT_DEPTH_IN) var depth_in: texture_2d<f32>;

// The part of the ray inside the volume, in front of the far plane and the host's opaque
// geometry and on the kept side of every clipping plane.
fn ray_segment(ray: Ray, px: vec2<u32>) -> vec2<f32> {
    return segment_within(ray, px, box_interval(ray, vec3<f32>(0.0), frame.dims.xyz - 1.0));
}

// The part `box` of the ray (its interval in a box) past the camera, in front of the far
// plane and the host's opaque geometry and on the kept side of every clipping plane.
fn segment_within(ray: Ray, px: vec2<u32>, box: vec2<f32>) -> vec2<f32> {
    var seg = box;
    seg.x = max(seg.x, 0.0);
    seg.y = min(seg.y, ray.far);
    if (has_flag(FLAG_DEPTH_INPUT)) {
        let d = textureLoad(depth_in, vec2<i32>(px), 0).x;
        seg.y = min(seg.y, depth_to_distance(ray, px, d));
    }
    return clip_interval(ray, seg);
}

fn in_crop(p: vec3<f32>) -> bool {
    let d = (frame.index_to_data * vec4<f32>(p, 1.0)).xyz;
    let r = select(vec3<u32>(0u), vec3<u32>(1u), d >= frame.crop_lo.xyz)
          + select(vec3<u32>(0u), vec3<u32>(1u), d >= frame.crop_hi.xyz);
    let bit = r.x + 3u * r.y + 9u * r.z;
    return ((frame.crop_regions >> bit) & 1u) != 0u;
}

// The min–max block holding index-space point p (clamped to the grid): its texel in the
// per-block textures (occupancy, majorants).
fn block_coord(p: vec3<f32>) -> vec3<i32> {
    let bs = f32(frame.block_size);
    let b = min(vec3<u32>(max(floor(p / bs), vec3<f32>(0.0))), frame.occupancy_dims.xyz - 1u);
    return vec3<i32>(b);
}

fn block_occupied(p: vec3<f32>) -> bool {
    return block_value(p) != 0u;
}

fn block_value(p: vec3<f32>) -> u32 {
    return block_texel(p) & 0xffu;
}

// The occupancy texel of the block holding p, as it is (value and leap distance).
fn block_texel(p: vec3<f32>) -> u32 {
    return textureLoad(occupancy, block_coord(p), 0).x;
}

// Distance at which the ray leaves the empty space around the empty block holding p, d
// blocks from the nearest occupied one: the cube of the blocks less than d away along
// every axis.
fn leap_exit(r: Ray, p: vec3<f32>, d: u32) -> f32 {
    let bs = f32(frame.block_size);
    let reach = f32(max(d, 1u) - 1u) * bs;
    let lo = floor(p / bs) * bs;
    return box_interval(r, lo - reach, lo + bs + reach).y;
}

// Distance at which the ray leaves the occupancy block holding p.
fn block_exit(r: Ray, p: vec3<f32>) -> f32 {
    return leap_exit(r, p, 1u);
}
