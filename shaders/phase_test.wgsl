// Draws Henyey–Greenstein scattering directions with the path tracer's own sampling code
// (lib/phase.wgsl) and returns the cosine of each to the propagation direction, for the
// chi-square test of the sampler (core/tests/pathtrace.rs).
#include "lib/envmap.wgsl"
#include "lib/phase.wgsl"

struct PhaseTest {
    // x: anisotropy g; yzw: the unit propagation direction
    params: vec4<f32>,
    // x: samples, y: seed
    counts: vec4<u32>,
}

@group(0) @binding(0) var<uniform> test: PhaseTest;
@group(0) @binding(1) var<storage, read_write> cosines: array<f32>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= test.counts.x) {
        return;
    }
    var rng = rng_seed(gid.x, test.counts.y);
    let d = test.params.yzw;
    let w = hg_sample(d, test.params.x, rand2(&rng));
    cosines[gid.x] = dot(w, d) / max(length(w), 1e-20);
}
