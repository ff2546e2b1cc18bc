// Edge-aware à-trous denoising of the path tracer's progressive image, the per-pixel means
// pathtrace_show.wgsl wrote (Dammertz et al., "Edge-Avoiding À-Trous Wavelet Transform for fast Global Illumination Filtering", HPG
// 2010): a few iterations of a 5×5 B3-spline kernel whose taps spread 1, 2, 4, ... pixels
// apart, each tap weighted down where the guide differs: the mean normal at the paths' first
// collision, their mean depth there, and the colour itself. The guide comes from the path
// tracer (pathtrace.wgsl: guide); the accumulation is never changed, only what is shown.

struct Denoise {
    // the pixels filtered: x0, y0, x1, y1 (exclusive; the path tracer's rectangle)
    rect: vec4<u32>,
    // x: image width, y: unused, z: tap spacing (pixels), w: 1 in the last iteration (write
    // the output image as well)
    size: vec4<u32>,
    // x: unused, y: colour edge-stopping scale, z: normal exponent, w: depth edge-stopping
    // scale (world units)
    params: vec4<f32>,
}

@group(0) @binding(0) var<uniform> dn: Denoise;
@group(0) @binding(1) var<storage, read> src: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> dst: array<vec4<f32>>;
// Per pixel, summed over the paths: xyz the first collision's normal, w its distance.
@group(0) @binding(3) var<storage, read> guide: array<vec4<f32>>;
// Per pixel, summed over the paths: rgb radiance, a coverage (to turn guide.w into a mean).
@group(0) @binding(4) var<storage, read> accum: array<vec4<f32>>;
@group(0) @binding(5) var out_color: texture_storage_2d<rgba8unorm, write>;

// The guide of pixel i: unit mean normal (0 where no path met the medium) and mean depth.
fn guide_at(i: u32) -> vec4<f32> {
    let g = guide[i];
    let hits = accum[i].a;
    let l = length(g.xyz);
    let n = select(vec3<f32>(0.0), g.xyz / l, l > 1e-6);
    return vec4<f32>(n, select(0.0, g.w / hits, hits > 0.0));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let w = dn.size.x;
    let r = dn.rect;
    let px = gid.xy + r.xy;
    if (px.x >= r.z || px.y >= r.w) {
        return;
    }
    let i = px.y * w + px.x;
    let c = src[i];
    let gc = guide_at(i);
    let step = i32(dn.size.z);
    var kernel = array<f32, 3>(0.375, 0.25, 0.0625);
    var sum = vec4<f32>(0.0);
    var wsum = 0.0;
    for (var dy = -2; dy <= 2; dy = dy + 1) {
        for (var dx = -2; dx <= 2; dx = dx + 1) {
            let q = vec2<i32>(i32(px.x) + dx * step, i32(px.y) + dy * step);
            if (q.x < i32(r.x) || q.y < i32(r.y) || q.x >= i32(r.z) || q.y >= i32(r.w)) {
                continue;
            }
            let j = u32(q.y) * w + u32(q.x);
            let cq = src[j];
            let gq = guide_at(j);
            var wt = kernel[abs(dx)] * kernel[abs(dy)];
            // normals and depths where both pixels met the medium (a pixel that did not is
            // told apart by its colour and coverage alone)
            let hit_c = dot(gc.xyz, gc.xyz) > 0.0;
            let hit_q = dot(gq.xyz, gq.xyz) > 0.0;
            if (hit_c && hit_q) {
                wt = wt * pow(max(dot(gc.xyz, gq.xyz), 0.0), dn.params.z);
                wt = wt * exp(-abs(gc.w - gq.w) / (dn.params.w * f32(step) + 1e-6));
            }
            let dc = c - cq;
            wt = wt * exp(-dot(dc, dc) / (dn.params.y * dn.params.y + 1e-12));
            sum = sum + wt * cq;
            wsum = wsum + wt;
        }
    }
    let v = sum / max(wsum, 1e-12);
    dst[i] = v;
    if (dn.size.w != 0u) {
        let a = clamp(v.a, 0.0, 1.0);
        textureStore(out_color, vec2<i32>(px), vec4<f32>(clamp(v.rgb, vec3<f32>(0.0), vec3<f32>(a)), a));
    }
}
