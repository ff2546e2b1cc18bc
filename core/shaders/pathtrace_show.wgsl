// What the path tracer shows: each pixel's mean over its accumulated paths (pathtrace.wgsl:
// accum, moments) as premultiplied colour and window depth, and as linear radiance and
// coverage for the denoiser (denoise.wgsl). While the first pass is under way (the
// rectangle traced in 16 interleaved subsets: every 4th pixel first, then every 2nd, ...) a
// pixel without paths shows the nearest traced pixel of its 2×2 cell, else of its 4×4 cell
// (corners relative to the rectangle, traced first).

struct Show {
    // the pixels shown: x0, y0, x1, y1 (exclusive; the path tracer's rectangle)
    rect: vec4<u32>,
    // x: image width, yzw: unused
    size: vec4<u32>,
}

@group(0) @binding(0) var<uniform> sh: Show;
@group(0) @binding(1) var<storage, read> accum: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> moments: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> image: array<vec4<f32>>;
@group(0) @binding(4) var out_color: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(5) var out_depth: texture_storage_2d<r32float, write>;

fn index(p: vec2<u32>) -> u32 {
    return p.y * sh.size.x + p.x;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let r = sh.rect;
    let px = gid.xy + r.xy;
    if (px.x >= r.z || px.y >= r.w) {
        return;
    }
    var j = index(px);
    if (moments[j].x == 0.0) {
        let rel = px - r.xy;
        j = index(r.xy + (rel & vec2<u32>(~1u)));
        if (moments[j].x == 0.0) {
            j = index(r.xy + (rel & vec2<u32>(~3u)));
        }
    }
    let m = moments[j];
    var mean = vec4<f32>(0.0);
    var depth = 1.0;
    if (m.x > 0.0) {
        mean = accum[j] / m.x;
        depth = m.z;
    }
    image[index(px)] = mean;
    // Premultiplied output: radiance beyond the coverage is clipped, as an 8-bit image must.
    let a = clamp(mean.a, 0.0, 1.0);
    textureStore(out_color, vec2<i32>(px), vec4<f32>(clamp(mean.rgb, vec3<f32>(0.0), vec3<f32>(a)), a));
    textureStore(out_depth, vec2<i32>(px), vec4<f32>(depth, 0.0, 0.0, 0.0));
}
