// Precomputed gradients: per texel of a brick, the central differences of the first
// component in scalar units per index step, g = (s(v + e) − s(v − e)) / 2 (coordinates
// clamped to the brick's texture, as the sampler's clamp-to-edge does). Trilinear
// interpolation is linear and commutes with the shift by e, so the interpolated texture
// gives exactly what lib/volume.wgsl's gradient_at computes on the fly (six fetches) with
// one fetch: (s(p + e) − s(p − e)) / 2 of the interpolated field.

struct GradientBuild {
    scale: vec4<f32>,   // x: texel value → scalar scale, y: shift
}

@group(0) @binding(0) var<uniform> gb: GradientBuild;
@group(0) @binding(1) var volume_in: texture_3d<f32>;
@group(0) @binding(2) var gradient_out: texture_storage_3d<rgba16float, write>;

fn scalar(v: vec3<i32>) -> f32 {
    let size = vec3<i32>(textureDimensions(volume_in));
    let c = clamp(v, vec3<i32>(0), size - 1);
    return textureLoad(volume_in, c, 0).x * gb.scale.x + gb.scale.y;
}

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(volume_in);
    if (any(gid >= size)) {
        return;
    }
    let v = vec3<i32>(gid);
    let g = 0.5 * vec3<f32>(
        scalar(v + vec3<i32>(1, 0, 0)) - scalar(v - vec3<i32>(1, 0, 0)),
        scalar(v + vec3<i32>(0, 1, 0)) - scalar(v - vec3<i32>(0, 1, 0)),
        scalar(v + vec3<i32>(0, 0, 1)) - scalar(v - vec3<i32>(0, 0, 1)),
    );
    textureStore(gradient_out, v, vec4<f32>(g, 0.0));
}
