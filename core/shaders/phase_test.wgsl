// Checks of the path tracer's scattering code (lib/phase.wgsl, lib/bsdf.wgsl), one sample
// per invocation (core/tests/pathtrace.rs):
//   mode 0: a Henyey–Greenstein direction; x = its cosine to the propagation direction
//           (the chi-square test of the sampler);
//   mode 1: the BSDF (colour 1) at a surface with normal `normal` for a path arriving
//           along `params.yzw`: x = value / density of a direction drawn by bsdf_sample
//           (its mean is the albedo), y = 4π·value and z = 4π·density of a uniformly
//           drawn direction (their means are the albedo and 1).
#include "lib/envmap.wgsl"
#include "lib/phase.wgsl"
#include "lib/bsdf.wgsl"

struct PhaseTest {
    // x: anisotropy g; yzw: the unit propagation direction
    params: vec4<f32>,
    // x GGX roughness, y Fresnel reflectance at normal incidence, z transmitted share,
    // w Phong exponent of the transmitted lobe
    bsdf: vec4<f32>,
    // xyz: the surface's normal (mode 1)
    normal: vec4<f32>,
    // x: samples, y: seed, z: mode
    counts: vec4<u32>,
}

@group(0) @binding(0) var<uniform> test: PhaseTest;
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= test.counts.x) {
        return;
    }
    var rng = rng_seed(gid.x, test.counts.y);
    let d = test.params.yzw;
    if (test.counts.z == 0u) {
        let w = hg_sample(d, test.params.x, rand2(&rng));
        results[gid.x] = vec4<f32>(dot(w, d) / max(length(w), 1e-20), 0.0, 0.0, 0.0);
        return;
    }
    let q = test.bsdf;
    let b = bsdf_at(test.normal.xyz, d, vec3<f32>(1.0), q.x, q.y, q.z, q.w);
    let a = rand(&rng);
    let w = bsdf_sample(b, d, vec3<f32>(a, rand2(&rng)));
    let e = bsdf_eval(b, d, w);
    let weight = select(0.0, e.r / e.a, e.a > 0.0);
    // a uniform direction on the sphere
    let u = rand2(&rng);
    let z = 1.0 - 2.0 * u.x;
    let r = sqrt(max(0.0, 1.0 - z * z));
    let wu = vec3<f32>(r * cos(2.0 * PI * u.y), r * sin(2.0 * PI * u.y), z);
    let eu = bsdf_eval(b, d, wu);
    results[gid.x] = vec4<f32>(weight, 4.0 * PI * eu.r, 4.0 * PI * eu.a, 0.0);
}
