// VTK's blanking (ghost arrays, vtkUniformGrid): per point of the grid, non-zero where the
// point is hidden (Renderer::set_blanking); BLANKING is on when the volume has one. Ray
// casting, isosurfaces and the path tracer leave blanked samples out.
#include "lib/common.wgsl"
@group(0) @binding(SLOT_BLANKING) var blanking_mask: texture_3d<u32>;
override BLANKING: bool = false;

// Whether the sample at index-space point p is blanked: vtkGPUVolumeRayCastMapper skips it
// when the point nearest to it, or either point around it along an axis (the others
// rounded), is hidden.
fn blanked(p: vec3<f32>) -> bool {
    if (!BLANKING) {
        return false;
    }
    let hi = vec3<i32>(frame.dims.xyz) - 1;
    let q = clamp(p, vec3<f32>(0.0), vec3<f32>(hi));
    let r = vec3<i32>(floor(q + 0.5));
    let lo = vec3<i32>(floor(q));
    let up = min(lo + 1, hi);
    var any = textureLoad(blanking_mask, r, 0).x != 0u;
    for (var a = 0; a < 3; a = a + 1) {
        var below = r;
        var above = r;
        below[a] = lo[a];
        above[a] = up[a];
        any = any || textureLoad(blanking_mask, below, 0).x != 0u
                  || textureLoad(blanking_mask, above, 0).x != 0u;
    }
    return any;
}
