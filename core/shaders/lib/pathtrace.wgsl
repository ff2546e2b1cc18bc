// What the path tracers share (pathtrace.wgsl through an image, pathtrace_mesh.wgsl through
// an unstructured mesh): their uniforms, the accumulation a path adds to, the environment
// as a light (its radiance, and directions drawn from its luminance), the view's lights
// as next-event targets, and the pixel and random streams of an invocation.
#include "lib/common.wgsl"
#include "lib/ray.wgsl"
#include "lib/envmap.wgsl"
#include "lib/phase.wgsl"

struct PathTrace {
    env_rotation: mat4x4<f32>,  // world → environment directions
    medium: vec4<f32>,          // x largest block majorant (per world unit), y anisotropy g, z 1 / unit distance, w environment weight
    surface: vec4<f32>,         // x gradient threshold ψ (world units; 3e38: none), y stochastic blend rate k (0: the hard switch), z GGX roughness, w Fresnel reflectance at normal incidence
    lobe: vec4<f32>,            // x transmitted share of the BSDF's non-specular part, y its Phong exponent, z the intermixed volumes' summed majorant (per world unit), w unused
    counts: vec4<u32>,          // x paths per primary ray, y paths accumulated before this one, z most scattering events, w seed
    options: vec4<u32>,         // x flags (PT_FLAG_*), y texels per edge of env_cdf's cube faces, z scattering regions (PT_SCATTER_*), w pixels traced: stride | x offset << 8 | y offset << 16 within rect
    rect: vec4<u32>,            // the frame's pixels: x0, y0, x1, y1 (exclusive)
}

// The denoiser's guide (GUIDE) is compiled only into the pipelines that sum it.
override GUIDE: bool = true;

// Per pixel: the sums of radiance (rgb) and of coverage (a) over all paths so far.
@group(0) @binding(SLOT_PT_ACCUM) var<storage, read_write> accum: array<vec4<f32>>;
// Per pixel: x the paths so far, y the sum of their squared luminances, z the window depth
// where the centre ray enters the medium's segment (1 until a path met the medium).
@group(0) @binding(SLOT_PT_MOMENTS) var<storage, read_write> moments: array<vec4<f32>>;
@group(0) @binding(SLOT_PT_UNIFORMS) var<uniform> pt_ubo: PathTrace;
// A private copy filled by the entry point, as lib/common.wgsl's `frame`.
var<private> pt: PathTrace;
@group(0) @binding(SLOT_PT_ENV_CUBE) var env_cube: texture_cube<f32>;
@group(0) @binding(SLOT_PT_ENV_SAMPLER) var env_sampler: sampler;
// The environment's sampling distribution over the texels of a small cube (options.y² per
// face, faces +X … −Z, rows top to bottom): the cumulative probabilities, last = 1
// (core/src/passes/medium.rs: luminance × solid angle, with a tenth spread uniformly).
@group(0) @binding(SLOT_PT_ENV_CDF) var<storage, read> env_cdf: array<f32>;
// Per pixel (PT_FLAG_GUIDE), summed over the paths: the unit normal at the camera path's
// first collision (facing the camera; the gradient's direction) and its distance along
// the ray (denoise.wgsl reads them).
@group(0) @binding(SLOT_PT_GUIDE) var<storage, read_write> guide: array<vec4<f32>>;

// This path's contribution to `guide` (zero when it met nothing).
var<private> path_guide: vec4<f32> = vec4<f32>(0.0);

fn env_radiance(d: vec3<f32>) -> vec3<f32> {
    let e = (pt.env_rotation * vec4<f32>(d, 0.0)).xyz;
    return pt.medium.w * textureSampleLevel(env_cube, env_sampler, e, 0.0).rgb;
}

// Face (x) and face coordinates sc, tc ∈ [−1, 1] (yz) of a direction, the inverse of
// cube_direction (environment.rs: cube_face_coords).
fn cube_face_coords(d: vec3<f32>) -> vec3<f32> {
    let a = abs(d);
    if (a.x >= a.y && a.x >= a.z) {
        if (d.x > 0.0) {
            return vec3<f32>(0.0, -d.z / a.x, -d.y / a.x);
        }
        return vec3<f32>(1.0, d.z / a.x, -d.y / a.x);
    }
    if (a.y >= a.z) {
        if (d.y > 0.0) {
            return vec3<f32>(2.0, d.x / a.y, d.z / a.y);
        }
        return vec3<f32>(3.0, d.x / a.y, -d.z / a.y);
    }
    if (d.z > 0.0) {
        return vec3<f32>(4.0, d.x / a.z, -d.y / a.z);
    }
    return vec3<f32>(5.0, -d.x / a.z, -d.y / a.z);
}

// Density over directions (per steradian) of env_sample for the world direction d: the
// texel's probability spread uniformly over its face coordinates, whose solid angle per
// unit area is (1 + sc² + tc²)^(−3/2).
fn env_pdf(d: vec3<f32>) -> f32 {
    let n = pt.options.y;
    let f = cube_face_coords((pt.env_rotation * vec4<f32>(d, 0.0)).xyz);
    let ij = min(vec2<u32>((f.yz + 1.0) * 0.5 * f32(n)), vec2<u32>(n - 1u));
    let i = (u32(f.x) * n + ij.y) * n + ij.x;
    let p = env_cdf[i] - select(0.0, env_cdf[max(i, 1u) - 1u], i > 0u);
    let q = 1.0 + f.y * f.y + f.z * f.z;
    return p * f32(n * n) * q * sqrt(q) * 0.25;
}

// A world direction drawn from the environment's distribution (pdf: env_pdf).
fn env_sample(u: vec3<f32>) -> vec3<f32> {
    let n = pt.options.y;
    let count = 6u * n * n;
    // the first texel whose cumulative probability exceeds u.x
    var lo = 0u;
    var hi = count - 1u;
    while (lo < hi) {
        let mid = (lo + hi) / 2u;
        if (env_cdf[mid] > u.x) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    let face = lo / (n * n);
    let rest = lo % (n * n);
    let st = (vec2<f32>(f32(rest % n), f32(rest / n)) + u.yz) / f32(n);
    let e = normalize(cube_direction(face, st));
    // environment → world: the rotation's transpose
    let m = mat3x3<f32>(pt.env_rotation[0].xyz, pt.env_rotation[1].xyz, pt.env_rotation[2].xyz);
    return transpose(m) * e;
}

fn power_heuristic(a: f32, b: f32) -> f32 {
    return a * a / max(a * a + b * b, 1e-30);
}


// Light i as seen from world point x: the direction toward it (xyz; the headlight shines
// along the camera ray `view_dir`), how far the light is (w; 3e38 for a directional one)
// and its factor: VTK's attenuation and spot cone for a positional light, 1 otherwise.
struct LightDir {
    l: vec3<f32>,
    reach: f32,
    k: f32,
}

fn light_dir(i: u32, x: vec3<f32>, view_dir: vec3<f32>) -> LightDir {
    let light = frame.lights[i];
    var out: LightDir;
    out.l = select(light.position.xyz, -view_dir, light.position.w > 1.5);
    out.reach = 3.0e38;
    out.k = 1.0;
    if (light.position.w > 0.5 && light.position.w < 1.5) {
        let to_light = light.position.xyz - x;
        out.reach = length(to_light);
        out.l = to_light / max(out.reach, 1e-30);
        let a3 = light.attenuation;
        out.k = 1.0 / max(a3.x + a3.y * out.reach + a3.z * out.reach * out.reach, 1e-20);
        if (light.spot.w > -1.5) {
            let cos_a = dot(-out.l, light.spot.xyz);
            out.k = select(0.0, out.k * pow(max(cos_a, 0.0), light.diffuse.w), cos_a > light.spot.w);
        }
    }
    return out;
}

// The pixel invocation gid traces in this dispatch (pt.options.w: every stride-th pixel of
// the rectangle from an offset), x = 0xffffffff where it traces none.
fn traced_pixel(gid: vec3<u32>) -> vec2<u32> {
    let lattice = pt.options.w;
    let offset = vec2<u32>((lattice >> 8u) & 0xffu, (lattice >> 16u) & 0xffu);
    let px = pt.rect.xy + offset + gid.xy * (lattice & 0xffu);
    if (px.x >= pt.rect.z || px.y >= pt.rect.w) {
        return vec2<u32>(0xffffffffu, 0u);
    }
    return px;
}

// The primary ray's random stream of pixel idx, shared by the counts.x paths of one primary
// ray (the camera ray's jitter and its first free flight)...
fn primary_stream(idx: u32) -> Rng {
    return rng_seed(idx, pcg_hash(pt.counts.w) ^ (pt.counts.y / pt.counts.x));
}

// ... and the stream a path continues with after its first collision.
fn secondary_stream(idx: u32) -> Rng {
    return rng_seed(idx, pcg_hash(pt.counts.w ^ 0x68e31da4u) ^ pt.counts.y);
}

// Adds a path (radiance, met the medium ? 1 : 0) to pixel idx's sums, with its guide, and
// the window depth where the pixel's centre ray enters the medium (`entry`, 1 for none),
// once any path met it.
fn accumulate(idx: u32, path: vec4<f32>, entry: f32) {
    let lum = dot(path.rgb, vec3<f32>(0.2126, 0.7152, 0.0722));
    var sum = path;
    var m = vec4<f32>(1.0, lum * lum, 1.0, 0.0);
    if (pt.counts.y > 0u) {
        sum = sum + accum[idx];
        m = vec4<f32>(m.xy + moments[idx].xy, 1.0, 0.0);
    }
    accum[idx] = sum;
    if (GUIDE && (pt.options.x & PT_FLAG_GUIDE) != 0u) {
        var gs = path_guide;
        if (pt.counts.y > 0u) {
            gs = gs + guide[idx];
        }
        guide[idx] = gs;
    }
    if (sum.a > 0.0) {
        m.z = entry;
    }
    moments[idx] = m;
}

// The light a path brings back when it leaves the medium along d after `bounce` scattering
// events, its throughput beta and the density dir_pdf its direction was drawn with: the
// environment, where the camera ray leaves it only as the background, else weighted
// against its next-event estimate by multiple importance sampling.
fn escaped(d: vec3<f32>, bounce: u32, beta: vec3<f32>, dir_pdf: f32) -> vec3<f32> {
    if (bounce == 0u) {
        return select(vec3<f32>(0.0), env_radiance(d), (pt.options.x & PT_FLAG_BACKGROUND) != 0u);
    }
    return beta * power_heuristic(dir_pdf, env_pdf(d)) * env_radiance(d);
}

// The denoiser's guide for a camera path's first collision at distance t along d, where
// the world gradient is g: its direction facing the camera (−d where there is none).
fn set_guide(g: vec3<f32>, d: vec3<f32>, t: f32) {
    var n = -d;
    if (dot(g, g) > 1e-20) {
        n = normalize(g);
        n = select(n, -n, dot(n, d) > 0.0);
    }
    path_guide = vec4<f32>(n, t);
}

// Whether a path goes on after scattering event `bounce`: from the fourth on, Russian
// roulette with its largest throughput (0.05 to 1) as the probability, the survivors'
// throughput divided by it.
fn survives(beta: ptr<function, vec3<f32>>, bounce: u32, rng: ptr<function, Rng>) -> bool {
    if (bounce >= 3u) {
        let q = clamp(max(max((*beta).x, (*beta).y), (*beta).z), 0.05, 1.0);
        if (rand(rng) >= q) {
            return false;
        }
        *beta = *beta / q;
    }
    return true;
}
