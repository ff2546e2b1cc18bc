// Progressive Monte Carlo path tracing of the volume as a participating medium: one path
// per pixel per dispatch, added to the sums of the paths before (accum, moments), over the
// whole rectangle or over one of its 16 interleaved subsets (options.w: every 4th pixel
// from an offset; pathtrace_show.wgsl shows the result). A frame is several dispatches: on lavapipe every loop iteration of an invocation draws on one budget of
// 65535 (llvmpipe's loop limiter), after which all its loops stop, so an invocation traces
// one path and no more (several per invocation lost paths, measured).
//
// The medium: extinction σ(x) = −ln(1 − α(s(x))) / unit distance, α the transfer
// function's opacity as given (so a slab one unit distance thick lets 1 − α through, VTK's
// meaning of ScalarOpacityUnitDistance), single-scattering albedo the transfer function's
// colour. Scattering follows the hybrid model: where the gradient magnitude |∇s| exceeds ψ
// (or, with the stochastic blend, with probability 1 − exp(−k|∇s|)) by the surface-like
// BSDF oriented by the gradient (lib/bsdf.wgsl), elsewhere by Henyey–Greenstein with
// anisotropy g. The scattering regions restrict where collisions scatter (nowhere, at
// surfaces only, between surfaces only, everywhere); the other collisions absorb the path
// (attenuation on) or do not happen (attenuation off: the medium is transparent there).
// Ray budgets: counts.x paths share one primary ray (the jittered camera ray and its first
// free flight are drawn from a stream keyed by the primary ray, the rest of the path from
// one keyed by the path). A path starts at the camera
// (jittered in its pixel), flies freely by delta (Woodcock) tracking against the majorant
// of each min–max block it crosses (σ̄ = the largest σ the block's scalar range can take;
// empty blocks are crossed in one step), scatters at real collisions; at each one it takes next-event estimates toward
// the environment (a direction importance-sampled from the environment's luminance,
// combined with the phase-sampled continuation by multiple importance sampling, power
// heuristic) and toward each light (directional, or positional with attenuation and cone)
// (transmittance by ratio tracking); Russian roulette after 3 bounces, at most
// pt.counts.z scattering events. Camera paths that miss the medium see the environment
// when it is the background; alpha is the fraction of paths that met the medium.
// Intermixed volumes (lib/intermix.wgsl) add their media: the extinctions add up (their
// summed majorants on top of each block's), a real collision takes the colour of the
// medium it met, drawn in proportion to the extinctions, and intermixed media, read without
// gradients, scatter as the main volume's where its gradient is zero.
#include "lib/common.wgsl"
#include "lib/ray.wgsl"
#include "lib/volume.wgsl"
#include "lib/march.wgsl"
#include "lib/intermix.wgsl"
#include "lib/blanking.wgsl"
#include "lib/rectilinear.wgsl"
#include "lib/table2d.wgsl"
#include "lib/envmap.wgsl"
#include "lib/phase.wgsl"
#include "lib/bsdf.wgsl"
#include "lib/pathtrace.wgsl"

// Pipeline constants: the code of the BSDF and of the scattering regions (HYBRID) is
// compiled only into the pipelines that use it (on lavapipe a path tracer carrying unused
// code runs markedly slower).
override HYBRID: bool = true;
// VTK's cropping regions: the medium is empty in the regions cropped away.
override CROP: bool = false;

// Declared from Rust (gpu::uniforms): PT_FLAG_BACKGROUND; PT_FLAG_ATTENUATION, collisions
// that do not scatter absorb (otherwise they do not happen); PT_FLAG_GUIDE, sum the
// denoiser's guide (the first collision's normal and distance) into `guide`; the
// PT_SCATTER_* regions; PT_MAX_OPACITY, the clamp that keeps extinction finite.
// Bound on the tentative collisions of one free flight or transmittance estimate (a
// majorant of 9.2 per unit over thousands of units: never reached in practice).
const PT_MAX_STEPS: u32 = 1000000u;

// Per min–max block (march.wgsl: block_coord): the largest extinction (per world unit) its
// scalar range can take under the transfer function, or where that is 0, minus the block's
// Chebyshev distance to the nearest block with extinction (core/src/resources/tables.rs,
// empty_distances): a ray leaps the cube of blocks without it (leap_exit).
@group(0) @binding(15) var majorants: texture_3d<f32>;
// The part of ray r inside the medium's box: the volume's, or with intermixed volumes the
// world box holding them all.
fn medium_box(r: Ray) -> vec2<f32> {
    if (INTERMIX > 0u) {
        return slab_interval(r.origin, r.dir, intermix.box_lo.xyz, intermix.box_hi.xyz);
    }
    return box_interval(r, vec3<f32>(0.0), frame.dims.xyz - 1.0);
}

// The part of a camera ray in the medium, before the near plane, the far plane and the
// host's opaque depth, on the kept side of the clipping planes.
fn camera_segment(r: Ray, px: vec2<u32>) -> vec2<f32> {
    return segment_within(r, px, medium_box(r));
}

// The part of a secondary ray inside the medium and on the kept side of the clipping planes.
fn inner_segment(r: Ray) -> vec2<f32> {
    var seg = medium_box(r);
    seg.x = max(seg.x, 0.0);
    return clip_interval(r, seg);
}

// Whether index-space point p lies in the main volume's grid (intermixed, the rays also
// cross space outside it, where its medium is empty).
fn in_main(p: vec3<f32>) -> bool {
    return INTERMIX == 0u || (all(p >= vec3<f32>(0.0)) && all(p <= frame.dims.xyz - 1.0));
}

// Intermixed volume j's extinction (per world unit) at world point x: empty outside its
// grid; σ from its opacity as given and its own unit distance.
fn intermixed_extinction(j: u32, x: vec3<f32>) -> f32 {
    let v = intermix.volumes[j];
    let p = intermixed_point(j, x);
    if (any(p < vec3<f32>(0.0)) || any(p > v.dims.xyz - 1.0)) {
        return 0.0;
    }
    let a = min(intermixed_entry(j, 1u, intermixed_value(j, p)).x, PT_MAX_OPACITY);
    return -log(1.0 - a) * v.range.w;
}

fn extinction(s: f32) -> f32 {
    return alpha_extinction(raw_alpha(0u, s));
}

fn alpha_extinction(alpha: f32) -> f32 {
    let a = min(alpha, PT_MAX_OPACITY);
    return -log(1.0 - a) * pt.medium.z;
}

// A mask (Renderer::set_mask), one value per point of the grid: MASK_BINARY empties the
// medium where the nearest point holds 0; MASK_LABELS gives a labelled point's medium its
// label's colour and opacity, mixed with the transfer function's by frame.mask.x (one
// component: the labels' rows follow the component's).
@group(0) @binding(17) var mask_tex: texture_3d<u32>;
override MASK: u32 = MASK_NONE;

// The medium's colour (rgb) and opacity (a, not step-corrected) at index-space point p,
// whose scalars are s: the transfer function's, or its 2D table's at s and the gradient
// magnitude there (TF2D).
fn medium(p: vec3<f32>, s: vec4<f32>) -> vec4<f32> {
    var own: vec4<f32>;
    if (has_2d(0u)) {
        own = table_2d(0u, s.x, length(world_gradient(gradient_at(p, s), 0u)));
    } else {
        own = vec4<f32>(classify(0u, s.x).rgb, raw_alpha(0u, s.x));
    }
    if (MASK == MASK_LABELS) {
        let l = mask_value(mask_tex, p);
        if (labelled(l)) {
            let row = label_row(1u, l);
            let u = label_coord(s.x);
            let e = vec4<f32>(table_lookup(row, 0u, u).rgb, table_lookup(row, 1u, u).x);
            return mix(own, e, frame.mask.x);
        }
    }
    return own;
}

// The probability that a collision where the gradient magnitude is m scatters by the BSDF
// (the rest scatter by Henyey–Greenstein).
fn bsdf_share(m: f32) -> f32 {
    if (pt.surface.y > 0.0) {
        return 1.0 - exp(-pt.surface.y * m);
    }
    return select(0.0, 1.0, m > pt.surface.x);
}

// Whether the hybrid model looks at the gradient at all.
fn uses_gradient() -> bool {
    return HYBRID && (pt.surface.y > 0.0 || pt.surface.x < 3.0e38);
}

// The share of the collisions at a point that scatter, for its BSDF share b.
fn scatter_share(b: f32) -> f32 {
    switch pt.options.z {
        case PT_SCATTER_NONE: {
            return 0.0;
        }
        case PT_SCATTER_SURFACES: {
            return b;
        }
        case PT_SCATTER_BETWEEN: {
            return 1.0 - b;
        }
        default: {
            return 1.0;
        }
    }
}

fn attenuates() -> bool {
    return (pt.options.x & PT_FLAG_ATTENUATION) != 0u;
}

// The extinction the paths meet at t: the media's, less the collisions that neither
// scatter nor absorb when attenuation is off (the host sets no majorant at all when
// nothing scatters and nothing attenuates). Intermixed volumes are read without their
// gradients: their collisions scatter as the main volume's where its gradient is zero.
fn extinction_at(r: Ray, t: f32) -> f32 {
    var sigma = main_extinction(r, t);
    if (INTERMIX > 0u) {
        let x = r.origin + t * r.dir;
        var others = 0.0;
        for (var j = 0u; j < INTERMIX; j = j + 1u) {
            others = others + intermixed_extinction(j, x);
        }
        sigma = sigma + others * intermixed_share();
    }
    return sigma;
}

// The medium a real collision at t met: the main volume's (MAX_INTERMIXED) or intermixed
// volume j's, drawn in proportion to their shares of extinction_at.
fn collided_medium(r: Ray, t: f32, rng: ptr<function, Rng>) -> u32 {
    let x = r.origin + t * r.dir;
    let share = intermixed_share();
    var u = rand(rng) * extinction_at(r, t) - main_extinction(r, t);
    for (var j = 0u; j < INTERMIX; j = j + 1u) {
        if (u < 0.0) {
            break;
        }
        let e = intermixed_extinction(j, x) * share;
        if (u < e) {
            return j;
        }
        u = u - e;
    }
    return MAX_INTERMIXED;
}

// The share of the intermixed volumes' collisions that the paths meet: all of them with
// attenuation, else those that scatter where the gradient is zero (the BSDF's share is
// then 0: ψ ≥ 0).
fn intermixed_share() -> f32 {
    let partial = pt.options.z == PT_SCATTER_SURFACES || pt.options.z == PT_SCATTER_BETWEEN;
    if (HYBRID && !attenuates() && partial) {
        return scatter_share(0.0);
    }
    return 1.0;
}

// The main volume's part of extinction_at.
fn main_extinction(r: Ray, t: f32) -> f32 {
    let lp = r.index_origin + t * r.index_dir;
    if (!in_main(lp) || (CROP && !in_crop(lp))) {
        return 0.0;
    }
    let p = grid_point(lp);
    if (blanked(p) || (MASK == MASK_BINARY && mask_value(mask_tex, p) == 0u)) {
        return 0.0;
    }
    let s = sample_scalars(p);
    var sigma: f32;
    if (MASK == MASK_LABELS || TF2D != 0u) {
        sigma = alpha_extinction(medium(p, s).a);
    } else {
        sigma = extinction(s.x);
    }
    let partial = pt.options.z == PT_SCATTER_SURFACES || pt.options.z == PT_SCATTER_BETWEEN;
    if (HYBRID && !attenuates() && partial && sigma > 0.0) {
        let m = length(world_gradient(gradient_at(p, s), 0u));
        sigma = sigma * scatter_share(bsdf_share(m));
    }
    return sigma;
}

// How a collision scatters: by the BSDF (surface) or by Henyey–Greenstein with the
// colour in b.color.
struct Scatterer {
    surface: bool,
    b: Bsdf,
}

// The scattering's value (rgb) toward w for a path that arrived along d, and the density
// (a) with which scatter_sample draws w.
fn scatter_eval(sc: Scatterer, d: vec3<f32>, w: vec3<f32>) -> vec4<f32> {
    if (sc.surface) {
        return bsdf_eval(sc.b, d, w);
    }
    let p = hg_pdf(dot(d, w), pt.medium.y);
    return vec4<f32>(sc.b.color * p, p);
}

fn scatter_sample(sc: Scatterer, d: vec3<f32>, rng: ptr<function, Rng>) -> vec3<f32> {
    if (sc.surface) {
        let a = rand(rng);
        return bsdf_sample(sc.b, d, vec3<f32>(a, rand2(rng)));
    }
    return hg_sample(d, pt.medium.y, rand2(rng));
}

// The majorant over the block the ray is in at t (just past t, so that a ray on a block
// boundary sees the block ahead) and the distance where it leaves that block (at least a
// little past t, so that every step advances). Intermixed volumes add their summed
// majorant everywhere; outside the main volume's grid the span ends where the ray enters it.
// On a rectilinear grid (RECTILINEAR: the rays march the box's uniform lattice and each
// sample is mapped to the grid's index space) the span is the whole ray.
fn block_span(r: Ray, t: f32) -> vec2<f32> {
    if (RECTILINEAR) {
        // (the blocks are the grid's, whose index space the rays do not march: the largest
        // majorant everywhere)
        return vec2<f32>(pt.medium.x, 3.0e38);
    }
    let p = r.index_origin + (t + 1e-4) * r.index_dir;
    if (!in_main(p)) {
        let b = box_interval(r, vec3<f32>(0.0), frame.dims.xyz - 1.0);
        let end = select(3.0e38, b.x, b.x > t + 1e-4 && b.x < b.y);
        return vec2<f32>(pt.lobe.z, end);
    }
    let m = textureLoad(majorants, block_coord(p), 0).x;
    if (m <= 0.0) {
        return vec2<f32>(pt.lobe.z, max(leap_exit(r, p, u32(-m)), t + 1e-4));
    }
    return vec2<f32>(m + pt.lobe.z, max(block_exit(r, p), t + 1e-4));
}

// One step of tracking over [t, t1): the next tentative collision, drawn against the
// majorant of the block the ray is in at t (y = that majorant, > 0), or, when none falls
// before the block or the segment ends, that end (y = 0). Drawing afresh at every block
// boundary is exact: the exponential distribution is memoryless.
fn tracking_step(r: Ray, t: f32, t1: f32, rng: ptr<function, Rng>) -> vec2<f32> {
    let span = block_span(r, t);
    let end = min(span.y, t1);
    if (span.x > 0.0) {
        let step = -log(1.0 - rand(rng)) / span.x;
        if (t + step < end) {
            return vec2<f32>(t + step, span.x);
        }
    }
    return vec2<f32>(end, 0.0);
}

// Delta tracking: the distance of the first real collision in [t0, t1), or t1 when the
// ray gets through.
fn free_flight(r: Ray, t0: f32, t1: f32, rng: ptr<function, Rng>) -> f32 {
    var result = t1;
    if (pt.medium.x > 0.0) {
        var t = t0;
        for (var i = 0u; i < PT_MAX_STEPS && t < t1; i = i + 1u) {
            let c = tracking_step(r, t, t1, rng);
            t = c.x;
            if (c.y > 0.0 && rand(rng) * c.y < extinction_at(r, t)) {
                result = t;
                break;
            }
        }
    }
    return result;
}

// Ratio tracking: an unbiased estimate of the transmittance over [t0, t1) against each
// block's majorant, with Russian roulette once it is small.
fn transmittance(r: Ray, t0: f32, t1: f32, rng: ptr<function, Rng>) -> f32 {
    var tr = 1.0;
    if (pt.medium.x > 0.0) {
        var t = t0;
        for (var i = 0u; i < PT_MAX_STEPS && t < t1; i = i + 1u) {
            let c = tracking_step(r, t, t1, rng);
            t = c.x;
            if (c.y <= 0.0) {
                continue;
            }
            tr = tr * (1.0 - extinction_at(r, t) / c.y);
            if (tr < 0.1) {
                if (rand(rng) >= 0.5) {
                    tr = 0.0;
                    break;
                }
                tr = tr * 2.0;
            }
        }
    }
    return tr;
}

// One path through the pixel: (radiance, met the medium ? 1 : 0). `secondary` is the
// stream the path continues with after its first collision.
fn trace(camera_ray: Ray, px: vec2<u32>, rng: ptr<function, Rng>, secondary: Rng) -> vec4<f32> {
    let background = (pt.options.x & PT_FLAG_BACKGROUND) != 0u;
    var r = camera_ray;
    var seg = camera_segment(r, px);
    var beta = vec3<f32>(1.0);
    var radiance = vec3<f32>(0.0);
    var hit = 0.0;
    // the density of the sampled direction the path now travels in
    var dir_pdf = 0.0;
    for (var bounce = 0u; bounce <= pt.counts.z; bounce = bounce + 1u) {
        let t = free_flight(r, seg.x, seg.y, rng);
        if (t >= seg.y) {
            radiance = radiance + escaped(r.dir, bounce, beta, dir_pdf);
            break;
        }
        if (bounce == 0u) {
            hit = 1.0;
            *rng = secondary;
            if (GUIDE && (pt.options.x & PT_FLAG_GUIDE) != 0u) {
                let p0 = r.index_origin + t * r.index_dir;
                var g0 = vec3<f32>(0.0);
                if (in_main(p0)) {
                    let q0 = grid_point(p0);
                    g0 = world_gradient(gradient_at(q0, sample_scalars(q0)), 0u);
                }
                set_guide(g0, r.dir, t);
            }
        }
        if (bounce == pt.counts.z) {
            break;   // the path has scattered as often as it may
        }
        let x = r.origin + t * r.dir;
        let p = grid_point(r.index_origin + t * r.index_dir);
        var sc: Scatterer;
        var share = 0.0;
        var grad = vec3<f32>(0.0);
        var which = MAX_INTERMIXED;
        if (INTERMIX > 0u) {
            which = collided_medium(r, t, rng);
        }
        if (which < MAX_INTERMIXED) {
            // an intermixed volume's medium: its colour; no gradient, so no BSDF (share 0)
            sc.b.color = intermixed_entry(which, 0u, intermixed_value(which, intermixed_point(which, x))).rgb;
        } else {
            let s = sample_scalars(p);
            sc.b.color = medium(p, s).rgb;
            if (uses_gradient()) {
                grad = world_gradient(gradient_at(p, s), 0u);
                share = bsdf_share(length(grad));
            }
        }
        if (attenuates()) {
            // the absorbing share of the collisions (without attenuation, extinction_at
            // left them out)
            beta = beta * scatter_share(share);
            if (all(beta <= vec3<f32>(0.0))) {
                break;
            }
        }
        switch pt.options.z {
            case PT_SCATTER_SURFACES: {
                sc.surface = true;
            }
            case PT_SCATTER_BETWEEN: {
                sc.surface = false;
            }
            default: {
                sc.surface = share > 0.0 && rand(rng) < share;
            }
        }
        if (sc.surface) {
            sc.b = bsdf_at(grad, r.dir, sc.b.color, pt.surface.z, pt.surface.w, pt.lobe.x, pt.lobe.y);
        }
        // Next-event estimation: the environment, from its own distribution.
        let wl = env_sample(vec3<f32>(rand(rng), rand2(rng)));
        let pl = env_pdf(wl);
        let el = scatter_eval(sc, r.dir, wl);
        if (pl > 0.0 && any(el.rgb > vec3<f32>(0.0))) {
            let rl = ray_from(x, wl);
            let sl = inner_segment(rl);
            let tl = transmittance(rl, sl.x, sl.y, rng);
            radiance = radiance + beta * el.rgb * (tl * power_heuristic(pl, el.a) / pl) * env_radiance(wl);
        }
        // ... and the lights: directional (the headlight along the camera ray) and
        // positional, with VTK's attenuation and spot cone.
        for (var i = 0u; i < frame.light_count; i = i + 1u) {
            let ld = light_dir(i, x, camera_ray.dir);
            let ed = scatter_eval(sc, r.dir, ld.l);
            if (ld.k > 0.0 && any(ed.rgb > vec3<f32>(0.0))) {
                let rd = ray_from(x, ld.l);
                let sd = inner_segment(rd);
                let td = transmittance(rd, sd.x, min(sd.y, ld.reach), rng);
                radiance = radiance + beta * ed.rgb * (td * ld.k) * frame.lights[i].diffuse.rgb;
            }
        }
        // Continue along a sampled direction, weighted by value / density.
        let wn = scatter_sample(sc, r.dir, rng);
        let en = scatter_eval(sc, r.dir, wn);
        if (en.a <= 0.0 || all(en.rgb <= vec3<f32>(0.0))) {
            break;
        }
        beta = beta * en.rgb / en.a;
        dir_pdf = en.a;
        r = ray_from(x, wn);
        seg = inner_segment(r);
        if (!survives(&beta, bounce, rng)) {
            break;
        }
    }
    return vec4<f32>(radiance, select(hit, 1.0, background));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    frame = frame_ubo;
    enter_volume();
    pt = pt_ubo;
    let px = traced_pixel(gid);
    if (px.x == 0xffffffffu) {
        return;
    }
    let idx = px.y * frame.width + px.x;
    var rng = primary_stream(idx);
    let ray = ray_through(image_ndc(vec2<f32>(px) + rand2(&rng)));
    let path = trace(ray, px, &rng, secondary_stream(idx));
    // depth: where the pixel's centre ray enters the medium's segment
    let centre = make_ray(px);
    let seg = camera_segment(centre, px);
    accumulate(idx, path, select(1.0, distance_to_depth(centre, seg.x), seg.x < seg.y));
}
