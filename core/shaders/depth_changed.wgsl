// Whether the host's depth input (opaque geometry) changed since the path tracer last saw
// it: each pixel compares it with the copy kept in `seen`, raises `changed` where they
// differ, and keeps the new value.

struct DepthCompare {
    // x: width, y: height (pixels), zw: unused
    size: vec4<u32>,
}

@group(0) @binding(0) var<uniform> dc: DepthCompare;
@group(0) @binding(1) var depth_in: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> seen: array<f32>;
@group(0) @binding(3) var<storage, read_write> changed: atomic<u32>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= dc.size.x || gid.y >= dc.size.y) {
        return;
    }
    let i = gid.y * dc.size.x + gid.x;
    let d = textureLoad(depth_in, vec2<i32>(gid.xy), 0).r;
    if (seen[i] != d) {
        atomicStore(&changed, 1u);
        seen[i] = d;
    }
}
