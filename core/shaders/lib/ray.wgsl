// Rays: one per pixel through the pixel centre, in world space and in the volume's index
// space, parameterised by world distance from the near plane.
#include "lib/common.wgsl"

struct Ray {
    origin: vec3<f32>,      // world, on the near plane
    dir: vec3<f32>,         // world, unit
    far: f32,               // world distance to the far plane
    index_origin: vec3<f32>,
    index_dir: vec3<f32>,   // index-space change per world unit along the ray
}

// The camera's matrices, read at an index that is always 0 but not a constant to the
// compiler: lavapipe (Mesa 22.3) inlines uniform values that feed branches into the
// shader and recompiles it whenever one of them changes, and it picked the camera — a full
// LLVM compile at every camera move (docs/PERFORMANCE.md has the figures).
fn inv_view_proj() -> mat4x4<f32> {
    return frame_ubo.camera[frame_ubo.camera_index];
}

fn view_proj() -> mat4x4<f32> {
    return frame_ubo.camera[frame_ubo.camera_index + 1u];
}

fn unproject(ndc: vec3<f32>) -> vec3<f32> {
    let p = inv_view_proj() * vec4<f32>(ndc, 1.0);
    return p.xyz / p.w;
}

// NDC of the point p of the image (pixels, from the top left corner).
fn image_ndc(p: vec2<f32>) -> vec2<f32> {
    let size = vec2<f32>(f32(frame.width), f32(frame.height));
    let uv = p / size;
    return vec2<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0);
}

fn pixel_ndc(px: vec2<u32>) -> vec2<f32> {
    return image_ndc(vec2<f32>(px) + 0.5);
}

fn make_ray(px: vec2<u32>) -> Ray {
    return ray_through(pixel_ndc(px));
}

// The ray through the point ndc of the image, from the near to the far plane.
fn ray_through(ndc: vec2<f32>) -> Ray {
    let near = unproject(vec3<f32>(ndc, -1.0));
    let far = unproject(vec3<f32>(ndc, 1.0));
    var r: Ray;
    r.origin = near;
    r.far = length(far - near);
    r.dir = (far - near) / r.far;
    r.index_origin = (frame.world_to_index * vec4<f32>(near, 1.0)).xyz;
    r.index_dir = (frame.world_to_index * vec4<f32>(r.dir, 0.0)).xyz;
    return r;
}

// Entry and exit distances of the line origin + t·dir through the box [lo, hi] (slabs).
fn slab_interval(origin: vec3<f32>, dir: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> vec2<f32> {
    let inv = 1.0 / dir;
    let t0 = (lo - origin) * inv;
    let t1 = (hi - origin) * inv;
    let tmin = min(t0, t1);
    let tmax = max(t0, t1);
    return vec2<f32>(max(max(tmin.x, tmin.y), tmin.z), min(min(tmax.x, tmax.y), tmax.z));
}

// Entry and exit distances of the ray through the box [lo, hi] (index space).
fn box_interval(r: Ray, lo: vec3<f32>, hi: vec3<f32>) -> vec2<f32> {
    return slab_interval(r.index_origin, r.index_dir, lo, hi);
}

// A piece of a whole volume (FLAG_PIECE): the ray's path through the whole's box, from the
// eye to the far plane.
fn whole_interval(r: Ray) -> vec2<f32> {
    let whole = box_interval(r, frame.whole_lo.xyz, frame.whole_hi.xyz);
    return vec2<f32>(max(whole.x, 0.0), min(whole.y, r.far));
}

// The whole ray's samples lie at tg + (k + jit) dt: the origin, on that lattice, of the
// first of them at or after t (that sample is the origin + jit dt).
fn whole_lattice_from(tg: f32, t: f32, dt: f32, jit: f32) -> f32 {
    return tg + max(ceil((t - tg) / dt - jit), 0.0) * dt;
}

// Distance along the ray of a window depth value (0 near … 1 far).
fn depth_to_distance(r: Ray, px: vec2<u32>, depth: f32) -> f32 {
    let p = unproject(vec3<f32>(pixel_ndc(px), depth * 2.0 - 1.0));
    return dot(p - r.origin, r.dir);
}

fn distance_to_depth(r: Ray, t: f32) -> f32 {
    let c = view_proj() * vec4<f32>(r.origin + t * r.dir, 1.0);
    return clamp(0.5 * c.z / c.w + 0.5, 0.0, 1.0);
}

// Narrows [t.x, t.y] by the clipping planes.
fn clip_interval(r: Ray, t_in: vec2<f32>) -> vec2<f32> {
    var t = t_in;
    for (var i = 0u; i < frame.clip_planes; i = i + 1u) {
        let pl = frame.clip[i];
        let dist = dot(pl.xyz, r.index_origin) + pl.w;   // signed, at t = 0
        let rate = dot(pl.xyz, r.index_dir);
        if (abs(rate) < 1e-12) {
            if (dist < 0.0) { t.y = t.x; }
        } else {
            let th = -dist / rate;
            if (rate > 0.0) { t.x = max(t.x, th); } else { t.y = min(t.y, th); }
        }
    }
    return t;
}

// A ray from a world point in a world direction (secondary rays).
fn ray_from(origin: vec3<f32>, dir: vec3<f32>) -> Ray {
    var r: Ray;
    r.origin = origin;
    r.dir = dir;
    r.far = 3.0e38;
    r.index_origin = (frame.world_to_index * vec4<f32>(origin, 1.0)).xyz;
    r.index_dir = (frame.world_to_index * vec4<f32>(dir, 0.0)).xyz;
    return r;
}
