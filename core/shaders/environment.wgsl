// Environment lighting, computed once per environment map (core/src/resources/environment.rs):
//   build       the source (procedural sky or equirectangular image) → level 0 of the cube
//   downsample  level m − 1 → level m (2×2 box), the mip chain the specular lobe samples
//   irradiance  Monte Carlo cosine-weighted filtering of the cube into the irradiance cube
// Each dispatch covers one level of all six faces (global id z = face).
#include "lib/envmap.wgsl"

// Mirrored in core/src/gpu/uniforms.rs (EnvUniforms).
struct EnvBuild {
    zenith: vec4<f32>,     // sky colour straight up (rgb)
    horizon: vec4<f32>,    // sky colour at the horizon
    ground: vec4<f32>,     // below the horizon
    sun: vec4<f32>,        // xyz: unit direction toward the sun; w: cos(angular radius)
    sun_color: vec4<f32>,  // rgb: radiance of the disk; w: halo strength
    scale: vec4<f32>,      // x: radiance scale; y: solid angle of a level-0 texel of the
                           // source cube (irradiance); z: last mip level of the source cube
    params: vec4<u32>,     // x: source (ENV_SKY, ENV_EQUIRECT); y: face size of the level
                           // written; z: samples per irradiance texel
}

// The source (params.x) is ENV_SKY or ENV_EQUIRECT (declared from Rust, gpu::uniforms).
// Largest finite rgba16float value: brighter texels (a sun in an HDR photograph) are
// clamped rather than becoming infinite.
const HALF_MAX: f32 = 65504.0;

@group(0) @binding(0) var<uniform> env: EnvBuild;
@group(0) @binding(1) var equirect: texture_2d<f32>;
@group(0) @binding(2) var equirect_sampler: sampler;
@group(0) @binding(3) var dst: texture_storage_2d_array<rgba16float, write>;
@group(0) @binding(4) var src_level: texture_2d_array<f32>;
@group(0) @binding(5) var src_cube: texture_cube<f32>;
@group(0) @binding(6) var cube_sampler: sampler;

// The procedural sky: zenith to horizon above (a hard horizon), ground below, a sun disk
// with a soft halo.
fn sky(d: vec3<f32>) -> vec3<f32> {
    var c = env.ground.rgb;
    if (d.y >= 0.0) {
        c = mix(env.horizon.rgb, env.zenith.rgb, sqrt(d.y));
    }
    let cs = dot(d, env.sun.xyz);
    if (cs >= env.sun.w) {
        c = c + env.sun_color.rgb;
    }
    c = c + env.sun_color.rgb * env.sun_color.w * pow(max(cs, 0.0), 256.0);
    return c;
}

// Equirectangular lookup: longitude from −Z (image centre) turning toward +X, latitude
// from +Y (top row) to −Y (bottom row).
fn equirect_radiance(d: vec3<f32>) -> vec3<f32> {
    let u = 0.5 + atan2(d.x, -d.z) / (2.0 * PI);
    let v = acos(clamp(d.y, -1.0, 1.0)) / PI;
    return textureSampleLevel(equirect, equirect_sampler, vec2<f32>(u, v), 0.0).rgb;
}

fn texel_direction(gid: vec3<u32>) -> vec3<f32> {
    let st = (vec2<f32>(gid.xy) + 0.5) / f32(env.params.y);
    return normalize(cube_direction(gid.z, st));
}

fn store(gid: vec3<u32>, c: vec3<f32>) {
    let v = clamp(c, vec3<f32>(0.0), vec3<f32>(HALF_MAX));
    textureStore(dst, vec2<i32>(gid.xy), i32(gid.z), vec4<f32>(v, 1.0));
}

@compute @workgroup_size(8, 8, 1)
fn build(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= env.params.y || gid.y >= env.params.y) {
        return;
    }
    let d = texel_direction(gid);
    var c: vec3<f32>;
    if (env.params.x == ENV_EQUIRECT) {
        c = equirect_radiance(d);
    } else {
        c = sky(d);
    }
    store(gid, c * env.scale.x);
}

// Relative solid angle of the texel centred at st ∈ [0, 1]² on a cube face (dA / r³).
fn texel_weight(st: vec2<f32>) -> f32 {
    let c = 2.0 * st - 1.0;
    let r2 = 1.0 + dot(c, c);
    return 1.0 / (r2 * sqrt(r2));
}

// Each texel of level m is the solid-angle-weighted mean of its four children in level
// m − 1, so every level integrates to the same ∫ L dω (a plain box average over-weights the
// children near face corners, which cover up to 3× less solid angle: a sun near a corner
// came out 7% too bright in the irradiance).
@compute @workgroup_size(8, 8, 1)
fn downsample(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= env.params.y || gid.y >= env.params.y) {
        return;
    }
    let p = vec2<i32>(gid.xy) * 2;
    let f = i32(gid.z);
    let child = 1.0 / f32(2u * env.params.y);
    var sum = vec3<f32>(0.0);
    var wsum = 0.0;
    for (var k = 0; k < 4; k = k + 1) {
        let q = p + vec2<i32>(k & 1, k >> 1u);
        let w = texel_weight((vec2<f32>(q) + 0.5) * child);
        sum = sum + w * textureLoad(src_level, q, f, 0).rgb;
        wsum = wsum + w;
    }
    store(gid, sum / wsum);
}

// π-normalised irradiance E(n) / π = (1/π) ∫ L(ω) max(n·ω, 0) dω, estimated with
// cosine-weighted Hammersley directions (estimator: the mean of L), each read from the mip
// level its pdf calls for so that few samples see the whole map. A constant environment
// L = c gives c.
@compute @workgroup_size(8, 8, 1)
fn irradiance(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= env.params.y || gid.y >= env.params.y) {
        return;
    }
    let n = texel_direction(gid);
    let b = basis_around(n);
    let count = env.params.z;
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < count; i = i + 1u) {
        let l = cosine_hemisphere(hammersley(i, count));
        let lod = filtered_lod(l.z / PI, count, env.scale.y, env.scale.z);
        sum = sum + textureSampleLevel(src_cube, cube_sampler, b * l, lod).rgb;
    }
    store(gid, sum / f32(count));
}
