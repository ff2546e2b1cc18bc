// Progressive Monte Carlo path tracing of an unstructured mesh as a participating medium:
// one path per pixel per dispatch, added to the sums of the paths before, as pathtrace.wgsl
// does for an image (lib/pathtrace.wgsl holds what they share).
//
// The medium: extinction σ = α(s) / unit distance, α the transfer function's opacity at the
// scalar s (VTK's unstructured convention, the ray caster's attenuation τ), linear in each
// tetrahedron; single-scattering albedo the transfer function's colour; Henyey–Greenstein
// scattering with anisotropy g. Paths fly by regular tracking: a free flight draws its
// optical depth τ* = −ln(1 − ξ) and walks the tetrahedra (lib/mesh.wgsl) adding each
// piece's exact optical depth (σ is linear along a piece between the table's knots, so its
// integral is a quadratic in the distance, inverted in closed form where τ* is reached);
// transparent tetrahedra are stepped over without integrating. Transmittance toward the
// environment and the lights is exp(−τ) of the same walk (no tracking noise), with Russian
// roulette once it is below 0.1 (as the image's ratio tracking plays it). Paths
// leave a non-convex mesh and enter it again through the boundary hierarchy. Otherwise as
// pathtrace.wgsl: next-event estimates toward the environment (multiple importance
// sampling with the phase function) and the view's lights, Russian roulette after 3
// bounces, at most pt.counts.z scattering events; alpha is the fraction of paths that met
// the medium.
#include "lib/mesh.wgsl"
#include "lib/march.wgsl"
#include "lib/pathtrace.wgsl"

// Optical depth past which a shadow ray's transmittance is taken as 0 (e^−30 ≈ 1e−13).
const OPAQUE_DEPTH: f32 = 30.0;
// Shadow rays play Russian roulette past this optical depth (a transmittance of 0.1): half
// of them stop (transmittance 0), the others go on with twice the weight (the depth less
// ln 2), an unbiased estimate that stops walking where little light gets through.
const ROULETTE_DEPTH: f32 = 2.302585;
const LN_2: f32 = 0.693147;

// Where a flight ended: at a collision (tet the tetrahedron, s the scalar there) or, with
// tet NO_HIT, at the end of its segment; and the optical depth it crossed.
struct Flight {
    t: f32,
    tet: u32,
    s: f32,
    depth: f32,
}

// Flies along r, walking w, over [seg.x, seg.y) until the optical depth reaches `goal`;
// with `roulette` (shadow rays) it plays Russian roulette past ROULETTE_DEPTH after each
// tetrahedron, a stopped ray ending as if it had reached the goal.
fn fly(r: Ray, seg: vec2<f32>, start: Walk, goal: f32, roulette: bool, rng: ptr<function, Rng>) -> Flight {
    var w = start;
    var out: Flight;
    out.t = seg.y;
    out.tet = NO_HIT;
    out.depth = 0.0;
    let o = r.index_origin;
    let d = r.index_dir;
    loop {
        let ex = walk_exit(&w, o, d, seg.y);
        if (ex.tf == NO_HIT) {
            break;
        }
        let tet = ex.tf >> 2u;
        let lo = max(w.hit.t, seg.x);
        let hi = min(ex.t, seg.y);
        if (hi > lo && !transparent_tet(w.k, tet)) {
            // the part of the tetrahedron's segment within seg, then its pieces between
            // the knots (or table entries), along each of which σ is linear
            let sv = scalars_at(w.hit, ex, lo, hi);
            let s0 = sv.x;
            let s1 = sv.y;
            let len = hi - lo;
            let x0 = entry_of(s0);
            let x1 = entry_of(s1);
            let up = x1 > x0;
            var xa = x0;
            var ua = 0.0;
            var sa = tau_at(xa);
            // (a tetrahedron the flight crosses whole adds its depth in a few reads: pieces
            // are walked only where the goal is reached, so that flights stay within
            // lavapipe's loop budget when pieces end at every table entry)
            let whole = segment_depth(s0, s1, len);
            var pieces = TABLE_N + 2u;
            if (out.depth + whole < goal) {
                out.depth = out.depth + whole;
                pieces = 0u;
            }
            for (var i = 0u; i < pieces; i = i + 1u) {
                let xb = next_cut(xa, x1, up);
                let ub = select((xb - x0) / (x1 - x0), 1.0, xb == x1);
                let sb = tau_at(xb);
                // optical depth a·v + b·v² at the fraction v of the piece
                let plen = (ub - ua) * len;
                let a = sa * plen;
                let b = 0.5 * (sb - sa) * plen;
                let rest = goal - out.depth;
                if (a + b >= rest) {
                    let v = clamp(2.0 * rest / max(a + sqrt(max(a * a + 4.0 * b * rest, 0.0)), 1e-30), 0.0, 1.0);
                    let u = ua + v * (ub - ua);
                    out.t = lo + u * len;
                    out.s = mix(s0, s1, u);
                    out.tet = tet;
                    out.depth = goal;
                    return out;
                }
                out.depth = out.depth + a + b;
                if (xb == x1) {
                    break;
                }
                xa = xb;
                ua = ub;
                sa = sb;
            }
            if (roulette && out.depth > ROULETTE_DEPTH) {
                if (rand(rng) < 0.5) {
                    out.tet = tet;
                    out.depth = goal;
                    return out;
                }
                out.depth = out.depth - LN_2;
            }
        }
        if (ex.t >= seg.y) {
            break;
        }
        walk_across(&w, o, d, ex, seg.y);
    }
    return out;
}

// An unbiased estimate of the transmittance along r from its origin, inside tetrahedron
// `tet` where the scalar is s, to `reach` (or out of the mesh), on the kept side of the
// clipping planes: exp(−τ) of the walk, with Russian roulette where it is small.
fn transmittance_from(r: Ray, tet: u32, s: f32, reach: f32, rng: ptr<function, Rng>) -> f32 {
    var seg = clip_interval(r, vec2<f32>(0.0, 3.0e38));
    seg.y = min(seg.y, reach);
    if (!(seg.x < seg.y)) {
        return 1.0;
    }
    let f = fly(r, seg, walk_inside(r.index_origin, r.index_dir, tet, 0.0, s), OPAQUE_DEPTH, true, rng);
    return select(exp(-f.depth), 0.0, f.tet != NO_HIT);
}

// A free flight's optical depth.
fn flight_depth(rng: ptr<function, Rng>) -> f32 {
    return -log(1.0 - rand(rng));
}

// The mesh's box (index space) along r: the boundary hierarchy's root.
fn mesh_box(r: Ray) -> vec2<f32> {
    return box_interval(r, nodes[0].lo, nodes[0].hi);
}

// One path through the pixel: (radiance, met the medium ? 1 : 0). `secondary` is the
// stream the path continues with after its first collision.
fn trace(camera_ray: Ray, px: vec2<u32>, rng: ptr<function, Rng>, secondary: Rng) -> vec4<f32> {
    let background = (pt.options.x & PT_FLAG_BACKGROUND) != 0u;
    let g = pt.medium.y;
    var r = camera_ray;
    // near and far planes, the host's opaque geometry, the clipping planes; the walk from
    // the line's first boundary crossing (a near plane inside the mesh starts the path there)
    var seg = segment_within(r, px, vec2<f32>(0.0, r.far));
    var w = walk_in(r.index_origin, r.index_dir, -3.0e38, seg.y);
    var beta = vec3<f32>(1.0);
    var radiance = vec3<f32>(0.0);
    var hit = 0.0;
    // the density of the sampled direction the path now travels in
    var dir_pdf = 0.0;
    for (var bounce = 0u; bounce <= pt.counts.z; bounce = bounce + 1u) {
        var f: Flight;
        f.tet = NO_HIT;
        if (seg.x < seg.y) {
            f = fly(r, seg, w, flight_depth(rng), false, rng);
        }
        if (f.tet == NO_HIT) {
            radiance = radiance + escaped(r.dir, bounce, beta, dir_pdf);
            break;
        }
        let x = r.origin + f.t * r.dir;
        if (bounce == 0u) {
            hit = 1.0;
            *rng = secondary;
            if (GUIDE && (pt.options.x & PT_FLAG_GUIDE) != 0u) {
                let gi = gradient_in(load_tet(f.tet), r.index_origin + f.t * r.index_dir);
                let g0 = (frame.gradient_to_world * vec4<f32>(gi, 0.0)).xyz;
                set_guide(g0, r.dir, f.t);
            }
        }
        if (bounce == pt.counts.z) {
            break;   // the path has scattered as often as it may
        }
        let albedo = colour_tau(entry_of(f.s)).rgb;
        // Next-event estimation: the environment, from its own distribution ...
        let wl = env_sample(vec3<f32>(rand(rng), rand2(rng)));
        let pl = env_pdf(wl);
        let hl = hg_pdf(dot(r.dir, wl), g);
        if (pl > 0.0 && any(albedo > vec3<f32>(0.0))) {
            let tl = transmittance_from(ray_from(x, wl), f.tet, f.s, 3.0e38, rng);
            radiance = radiance + beta * albedo * hl * (tl * power_heuristic(pl, hl) / pl) * env_radiance(wl);
        }
        // ... and the lights: directional (the headlight along the camera ray) and
        // positional, with VTK's attenuation and spot cone.
        for (var i = 0u; i < frame.light_count; i = i + 1u) {
            let ld = light_dir(i, x, camera_ray.dir);
            if (ld.k > 0.0 && any(albedo > vec3<f32>(0.0))) {
                let td = transmittance_from(ray_from(x, ld.l), f.tet, f.s, ld.reach, rng);
                let hd = hg_pdf(dot(r.dir, ld.l), g);
                radiance = radiance + beta * albedo * hd * (td * ld.k) * frame.lights[i].diffuse.rgb;
            }
        }
        // Continue along a direction drawn from the phase function: weight the albedo.
        if (all(albedo <= vec3<f32>(0.0))) {
            break;
        }
        let wn = hg_sample(r.dir, g, rand2(rng));
        beta = beta * albedo;
        dir_pdf = hg_pdf(dot(r.dir, wn), g);
        r = ray_from(x, wn);
        seg = clip_interval(r, vec2<f32>(0.0, 3.0e38));
        w = walk_inside(r.index_origin, r.index_dir, f.tet, 0.0, f.s);
        if (!survives(&beta, bounce, rng)) {
            break;
        }
    }
    return vec4<f32>(radiance, select(hit, 1.0, background));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    frame = frame_ubo;
    mesh = mesh_ubo;
    pt = pt_ubo;
    let px = traced_pixel(gid);
    if (px.x == 0xffffffffu) {
        return;
    }
    let idx = px.y * frame.width + px.x;
    var rng = primary_stream(idx);
    let ray = ray_through(image_ndc(vec2<f32>(px) + rand2(&rng)));
    let path = trace(ray, px, &rng, secondary_stream(idx));
    // depth: where the pixel's centre ray enters the mesh's box
    let centre = make_ray(px);
    let seg = segment_within(centre, px, mesh_box(centre));
    accumulate(idx, path, select(1.0, distance_to_depth(centre, seg.x), seg.x < seg.y));
}
