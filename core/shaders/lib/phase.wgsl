// Random numbers and the Henyey–Greenstein phase function, shared by the path tracer
// (pathtrace.wgsl) and the phase-function sampling check (phase_test.wgsl). Needs PI and
// basis_around (lib/envmap.wgsl).
#include "lib/envmap.wgsl"

// PCG hash (O'Neill): a well-mixed u32 from a u32.
fn pcg_hash(v: u32) -> u32 {
    let s = v * 747796405u + 2891336453u;
    let w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}

// One random stream: a PCG state per path.
struct Rng {
    state: u32,
}

fn rng_seed(a: u32, b: u32) -> Rng {
    var r: Rng;
    r.state = pcg_hash(a ^ pcg_hash(b));
    return r;
}

// Uniform in [0, 1) (24 bits).
fn rand(r: ptr<function, Rng>) -> f32 {
    (*r).state = (*r).state * 747796405u + 2891336453u;
    let s = (*r).state;
    let w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return f32(((w >> 22u) ^ w) >> 8u) / 16777216.0;
}

fn rand2(r: ptr<function, Rng>) -> vec2<f32> {
    let a = rand(r);
    return vec2<f32>(a, rand(r));
}

// Henyey–Greenstein density over the sphere of directions for the cosine between the
// incoming and outgoing propagation directions; g in (−1, 1): > 0 forward, 0 isotropic.
fn hg_pdf(cos_theta: f32, g: f32) -> f32 {
    let d = max(1.0 + g * g - 2.0 * g * cos_theta, 1e-12);
    return (1.0 - g * g) / (4.0 * PI * d * sqrt(d));
}

// The cosine for u ∈ [0, 1) by the inverse of the Henyey–Greenstein CDF (exact).
fn hg_sample_cos(u: f32, g: f32) -> f32 {
    if (abs(g) < 1e-3) {
        return 1.0 - 2.0 * u;
    }
    let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    return clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}

// A direction scattered from the unit propagation direction d, distributed as
// Henyey–Greenstein with anisotropy g (pdf: hg_pdf(dot(d, result), g)).
fn hg_sample(d: vec3<f32>, g: f32, u: vec2<f32>) -> vec3<f32> {
    let c = hg_sample_cos(u.x, g);
    let s = sqrt(max(0.0, 1.0 - c * c));
    let phi = 2.0 * PI * u.y;
    return basis_around(d) * vec3<f32>(s * cos(phi), s * sin(phi), c);
}

