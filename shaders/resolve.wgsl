// Resolve: the last pass over a bricked volume, writing each pixel from the ray state the
// brick passes accumulated (lib/output.wgsl).
#include "lib/common.wgsl"
#include "lib/output.wgsl"

@group(0) @binding(2) var<storage, read> state: array<PixelState>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    frame = frame_ubo;
    let px = gid.xy + frame.rect.xy;
    if (px.x >= frame.rect.z || px.y >= frame.rect.w) {
        return;
    }
    write_pixel(px, state[px.y * frame.viewport.x + px.x]);
}
