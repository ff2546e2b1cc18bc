// Ray casting an unstructured volume (core/src/passes/unstructured.rs): one thread per
// pixel. A ray enters the mesh where it first meets a boundary triangle facing it (a
// bounding volume hierarchy over the boundary triangles), walks from tetrahedron to
// tetrahedron across shared faces, each tetrahedron's exit face and point from the ray's
// Plücker products with its edges, and where it leaves the mesh looks for the next boundary
// triangle facing it beyond (non-convex meshes). Along a tetrahedron the scalar is linear
// (barycentric on the entry and exit faces; cell scalars constant), and each segment is
// integrated exactly for the transfer tables (linear between entries): split at the
// entries it crosses, each piece with linear colour and linear attenuation
// τ = opacity / unit distance, emission colour · τ (VTK's unstructured integrators).
// "Index space" is the mesh's own coordinates relative to its centre; t is world distance.
// Only the part of each ray within the near and far planes, the host's depth and the
// clipping planes is integrated; composite skips the integral of a tetrahedron whose
// scalars the transfer function makes fully transparent (empty-space skipping).
// SHADE: each segment is lit as at its middle, by the gradient interpolated there from the
// points' (gradient_in): the lighting is then a constant affine map of the emitted colour
// along the segment, so its integral stays in closed form (the clamp to [0, 1] applied to
// a piece's mean colour rather than to each point's).
// GRAD_OPACITY: each segment's attenuation is scaled by the gradient opacity of the
// gradient's magnitude (world units) at its middle, the gradient SHADE lights it by: a
// constant factor along the segment, so the closed forms hold.
// VOLUMETRIC (shaded composite): volumetric shadows, as the image ray caster draws them
// (lib/shadow.wgsl, VTK's VolumetricScatteringBlending) with the mesh's own light
// transport: at each segment's middle, the transmittance toward each light is exp(−τ) of a
// walk through the mesh (exact: τ linear along each piece; a headlight's from the ray's own
// optical depth, trail_to), as far as the reach (VTK's,
// measured in the mesh's box mapped to the unit cube) or the light; the volumetric term
// Σ T·p(μ)·kd·I_diffuse (+ ka·I_ambient but the headlight's), p Henyey–Greenstein over the
// world cosine, mixed with the gradient lighting by VTK's weight, from the gradient's
// magnitude (of the scalar normalised by the data range, over two units) and the opacity
// the attenuation at the middle gives over a typical cell (mesh.shadow.w). Still an affine
// map of the emitted colour per segment.
#include "lib/output.wgsl"
#include "lib/march.wgsl"
#include "lib/shading.wgsl"
#include "lib/volumetric.wgsl"
#include "lib/mesh.wgsl"

override BLEND: u32 = BLEND_COMPOSITE;
override SHADE: bool = false;
override GRAD_OPACITY: bool = false;
override VOLUMETRIC: bool = false;

// ---- integration ----

// e^(x²) erfc(x) for x ≥ 0 (the Chebyshev fit of Numerical Recipes, relative error
// below 1.2e-7).
fn erfcx(x: f32) -> f32 {
    let t = 1.0 / (1.0 + 0.5 * x);
    let p = -1.26551223 + t * (1.00002368 + t * (0.37409196 + t * (0.09678418 +
        t * (-0.18628806 + t * (0.27886807 + t * (-1.13520398 + t * (1.48851587 +
        t * (-0.82215223 + t * 0.17087277))))))));
    return t * exp(p);
}

// Dawson's integral F(x) = e^(−x²) ∫₀ˣ e^(y²) dy for x ≥ 0: its series near 0, Rybicki's
// sum (h = 0.4, twelve terms) up to 10, the asymptotic series beyond.
fn dawson(x: f32) -> f32 {
    let x2 = x * x;
    if (x < 0.2) {
        return x * (1.0 - 2.0 / 3.0 * x2 * (1.0 - 2.0 / 5.0 * x2 * (1.0 - 2.0 / 7.0 * x2)));
    }
    if (x > 10.0) {
        let r = 1.0 / x2;
        return 0.5 / x * (1.0 + r * (0.5 + r * (0.75 + r * 1.875)));
    }
    let h = 0.4;
    let n0 = 2.0 * round(0.5 * x / h);
    let xp = x - n0 * h;
    var sum = 0.0;
    for (var k = -11; k <= 11; k = k + 2) {
        let kh = f32(k) * h;
        sum = sum + exp(-(xp - kh) * (xp - kh)) / (n0 + f32(k));
    }
    return sum * 0.5641895835; // 1 / √π
}

// The mean over u in [0, 1] of exp(−a·u − b·u²), a ≥ 0, a + 2b ≥ 0: the mean
// transmittance over a piece of optical depth a·u + b·u² at u.
fn psi(a: f32, b: f32) -> f32 {
    if (a + abs(b) < 1.0) {
        // Gauss–Legendre, four points: the exponent is small, the error far below f32's
        let x = vec4<f32>(0.0694318442, 0.3300094782, 0.6699905218, 0.9305681558);
        let w = vec4<f32>(0.1739274226, 0.3260725774, 0.3260725774, 0.1739274226);
        return dot(w, exp(-a * x - b * x * x));
    }
    if (abs(b) < 1e-6 * a) {
        return (1.0 - exp(-a)) / a;
    }
    if (b > 0.0) {
        let s = sqrt(b);
        let x0 = 0.5 * a / s;
        return 0.8862269255 / s * (erfcx(x0) - exp(-(a + b)) * erfcx(x0 + s));
    }
    let s = sqrt(-b);
    let zeta = exp(-(a + b));
    return (dawson(0.5 * a / s) - zeta * dawson(0.5 * (a + 2.0 * b) / s)) / s;
}

// The ray's state: premultiplied colour, the projections' value and length, the depth.
var<private> st: PixelState;
// SHADE: the lighting of the tetrahedron being integrated.
var<private> lit: Lighting;
// GRAD_OPACITY: the factor of its attenuation.
var<private> opacity_scale: f32 = 1.0;

// Composites a piece of length len whose colour and attenuation run linearly from cf to cb
// (rgb colour, a attenuation), starting at distance t0.
fn composite_piece(r: Ray, cf: vec4<f32>, cb: vec4<f32>, len: f32, t0: f32) {
    let a = cf.a * opacity_scale * len;
    let b = 0.5 * (cb.a - cf.a) * opacity_scale * len;
    if (a + b <= 0.0 && a <= 0.0) {
        return;
    }
    let zeta = exp(-(a + b));
    let p = psi(a, b);
    var emitted = cb.rgb * (1.0 - zeta) + (cf.rgb - cb.rgb) * (1.0 - p);
    if (SHADE) {
        emitted = clamp(emitted * lit.scale + lit.add * (1.0 - zeta), vec3<f32>(0.0),
                        vec3<f32>(1.0 - zeta));
    }
    let before = st.color.a;
    let keep = 1.0 - before;
    st.color = st.color + keep * vec4<f32>(emitted, 1.0 - zeta);
    if (st.misc.z == 0.0 && st.color.a > frame.depth_threshold) {
        let f = clamp((frame.depth_threshold - before) / max(st.color.a - before, 1e-30), 0.0, 1.0);
        st.misc.y = distance_to_depth(r, t0 + f * len);
        st.misc.z = 1.0;
    }
}

// Opacity × normalised scalar at table coordinate x (average and additive).
fn projection_at(x: f32) -> f32 {
    let u = clamp(x / f32(TABLE_N - 1u), 0.0, 1.0);
    return row_lookup(tables, 1, u, false).x * u;
}

// One segment [t0, t0 + len] along which the scalar runs linearly from s0 to s1.
fn integrate(r: Ray, s0: f32, s1: f32, t0: f32, len: f32) {
    if (BLEND == BLEND_MAXIMUM) {
        let m = max(s0, s1);
        st.value.x = select(max(st.value.x, m), m, st.misc.x == 0.0);
        st.misc.x = st.misc.x + 1.0;
        return;
    }
    if (BLEND == BLEND_MINIMUM) {
        let m = min(s0, s1);
        st.value.x = select(min(st.value.x, m), m, st.misc.x == 0.0);
        st.misc.x = st.misc.x + 1.0;
        return;
    }
    if (len <= 0.0) {
        return;
    }
    // the pieces between the knots (or table entries) the segment crosses: within each,
    // colour, attenuation and the normalised scalar are linear in t
    let x0 = entry_of(s0);
    let x1 = entry_of(s1);
    let up = x1 > x0;
    var xa = x0;
    var ua = 0.0;
    var ca = colour_tau(xa);
    for (var i = 0u; i <= TABLE_N + 1u; i = i + 1u) {
        let xb = next_cut(xa, x1, up);
        let ub = select((xb - x0) / (x1 - x0), 1.0, xb == x1);
        let plen = (ub - ua) * len;
        let cb = colour_tau(xb);
        if (BLEND == BLEND_COMPOSITE) {
            composite_piece(r, ca, cb, plen, t0 + ua * len);
            if (st.color.a >= frame.termination) {
                return;
            }
        } else {
            // the product of two linear functions: Simpson's rule is exact
            let mid = projection_at(0.5 * (xa + xb));
            let term = plen / 6.0 * (projection_at(xa) + 4.0 * mid + projection_at(xb));
            st.value.x = st.value.x + term * select(1.0, mesh.unit.x, BLEND == BLEND_ADDITIVE);
        }
        if (xb == x1) {
            break;
        }
        xa = xb;
        ua = ub;
        ca = cb;
    }
    if (BLEND == BLEND_AVERAGE) {
        st.misc.x = st.misc.x + len;
    } else if (BLEND == BLEND_ADDITIVE) {
        st.misc.x = st.misc.x + 1.0;
    }
}

// The part of segment [ta, tb] (scalars sa, sb) within [seg.x, seg.y], integrated.
fn integrate_within(r: Ray, seg: vec2<f32>, ta: f32, tb: f32, sa: f32, sb: f32) {
    let lo = max(ta, seg.x);
    let hi = min(tb, seg.y);
    if (hi < lo || (hi == lo && BLEND != BLEND_MAXIMUM && BLEND != BLEND_MINIMUM)) {
        return;
    }
    let span = tb - ta;
    var s0 = sa;
    var s1 = sb;
    if (span > 0.0) {
        s0 = mix(sa, sb, (lo - ta) / span);
        s1 = mix(sa, sb, (hi - ta) / span);
    }
    integrate(r, s0, s1, lo, hi - lo);
}

// The optical depth over [a, b] of the segment through tetrahedron k from `entry` to `ex`
// (of a walk from o along d): the attenuation scaled by its gradient opacity at the middle
// of [a, b] (GRAD_OPACITY); 0 through a transparent tetrahedron.
fn piece_depth(k: Tet, entry: Hit, ex: Hit, a: f32, b: f32, o: vec3<f32>, d: vec3<f32>) -> f32 {
    if (b <= a || transparent_tet(k, ex.tf >> 2u)) {
        return 0.0;
    }
    let sv = scalars_at(entry, ex, a, b);
    var scale = 1.0;
    if (GRAD_OPACITY) {
        let g = gradient_in(k, o + 0.5 * (a + b) * d);
        scale = gradient_opacity(0u, length((frame.gradient_to_world * vec4<f32>(g, 0.0)).xyz));
    }
    return scale * segment_depth(sv.x, sv.y, b - a);
}

// The transmittance from index-space point x, in tetrahedron `tet` where the scalar is s,
// along d (t world distance) to `limit`: exp(−τ) of the walk; light passes through the gaps
// of a non-convex mesh.
fn transmittance(x: vec3<f32>, d: vec3<f32>, tet: u32, s: f32, limit: f32) -> f32 {
    var w = walk_inside(x, d, tet, 0.0, s);
    var depth = 0.0;
    loop {
        let ex = walk_exit(&w, x, d, limit);
        if (ex.tf == NO_HIT) {
            break;
        }
        depth = depth + piece_depth(w.k, w.hit, ex, w.hit.t, min(ex.t, limit), x, d);
        if (ex.t >= limit || depth > 30.0) {
            break;
        }
        walk_across(&w, x, d, ex, limit);
    }
    return exp(-depth);
}

// VOLUMETRIC: a headlight's shadow rays run back along the pixel's own ray, so their optical
// depth is the ray's: ray_depth from the ray's first entry into the mesh to the current
// tetrahedron's entry, and a second walk of the same ray (trail, leaving its tetrahedron at
// trail_ex) that trails by the reach, trail_depth to its tetrahedron's entry. Each
// tetrahedron is walked twice in all, where a shadow walk per segment would walk the reach.
var<private> ray_depth: f32 = 0.0;
var<private> trail: Walk;
var<private> trail_ex: Hit;
var<private> trail_depth: f32 = 0.0;

// The ray's optical depth from its first entry to distance t (never less than the last
// call's t): the trailing walk moves on to t.
fn trail_to(o: vec3<f32>, d: vec3<f32>, t: f32, t_max: f32) -> f32 {
    // (walks take function-space pointers: the walk moves on in a copy)
    var w = trail;
    loop {
        if (trail_ex.tf == NO_HIT || trail_ex.t > t) {
            break;
        }
        trail_depth = trail_depth + piece_depth(w.k, w.hit, trail_ex, w.hit.t, trail_ex.t, o, d);
        walk_across(&w, o, d, trail_ex, t_max);
        trail_ex = walk_exit(&w, o, d, t_max);
    }
    trail = w;
    if (trail_ex.tf == NO_HIT) {
        return trail_depth;
    }
    return trail_depth + piece_depth(w.k, w.hit, trail_ex, w.hit.t, t, o, d);
}

// VOLUMETRIC: `surface` (the gradient lighting of a segment) mixed with the volumetric term
// at the segment's middle, distance mid along the ray from o along d (index space) inside
// tetrahedron k, entered at `entry` and left at `ex`; scalar s, world point pos, world
// gradient gw; τ the attenuation there (gradient opacity applied).
fn volumetric_lighting(surface: Lighting, o: vec3<f32>, d: vec3<f32>, mid: f32, k: Tet,
                       entry: Hit, ex: Hit, s: f32, pos: vec3<f32>, view_dir: vec3<f32>,
                       gw: vec3<f32>, tau: f32, t_max: f32) -> Lighting {
    let v = -view_dir;
    let x = o + mid * d;
    var vol: Lighting;
    vol.scale = vec3<f32>(0.0);
    vol.add = vec3<f32>(0.0);
    for (var i = 0u; i < NUM_LIGHTS; i = i + 1u) {
        let light = frame.lights[i];
        let li = light_incidence(light, pos, v);
        var limit = 3.0e38;
        if (light.position.w > 0.5 && light.position.w < 1.5) {
            limit = distance(light.position.xyz, pos);
        }
        let dl = (frame.world_to_index * vec4<f32>(li.xyz, 0.0)).xyz;
        limit = min(limit, frame.scatter.z / max(length(dl * mesh.shadow.xyz), 1e-30));
        var tr = 1.0;
        if (light.position.w > 1.5) {
            let here = ray_depth + piece_depth(k, entry, ex, entry.t, mid, o, d);
            tr = exp(-max(here - trail_to(o, d, mid - limit, t_max), 0.0));
        } else {
            tr = transmittance(x, dl, ex.tf >> 2u, s, limit);
        }
        vol.scale = vol.scale + tr * shadow_phase(dot(-li.xyz, v)) * li.w * frame.material.y *
            light.diffuse.rgb;
        if (light.position.w < 1.5) {
            vol.add = vol.add + frame.material.x * light.ambient.rgb;
        }
    }
    let a = 1.0 - exp(-tau * mesh.shadow.w);
    let wv = volumetric_weight(length(gw) * frame.scatter.w, a);
    var out: Lighting;
    out.scale = mix(surface.scale, vol.scale, wv);
    out.add = mix(surface.add, vol.add, wv);
    return out;
}

// Whether composite may skip tetrahedron k (index t): it adds nothing where it is
// transparent.
fn empty_tet(k: Tet, t: u32) -> bool {
    return BLEND == BLEND_COMPOSITE && transparent_tet(k, t);
}

fn done() -> bool {
    return BLEND == BLEND_COMPOSITE && st.color.a >= frame.termination;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    frame = frame_ubo;
    mesh = mesh_ubo;
    let px = gid.xy + frame.rect.xy;
    if (px.x >= frame.rect.z || px.y >= frame.rect.w) {
        return;
    }
    let ray = make_ray(px);
    // near and far planes, the host's opaque geometry, the clipping planes
    let seg = segment_within(ray, px, vec2<f32>(0.0, ray.far));
    let o = ray.index_origin;
    let d = ray.index_dir;
    if (seg.x < seg.y || (seg.x == seg.y && BLEND != BLEND_COMPOSITE)) {
        // (from the line's first boundary crossing, behind the camera too: a near plane
        // inside the mesh starts its rays inside, where they are integrated from seg.x)
        var w = walk_in(o, d, -3.0e38, seg.y);
        if (VOLUMETRIC) {
            var first = w;
            trail_ex = walk_exit(&first, o, d, seg.y);
            trail = first;
        }
        loop {
            let ex = walk_exit(&w, o, d, seg.y);
            if (ex.tf == NO_HIT) {
                break;
            }
            if (!empty_tet(w.k, ex.tf >> 2u)) {
                if (SHADE || GRAD_OPACITY) {
                    let mid = 0.5 * (max(w.hit.t, seg.x) + min(ex.t, seg.y));
                    let g = gradient_in(w.k, o + mid * d);
                    let gw = (frame.gradient_to_world * vec4<f32>(g, 0.0)).xyz;
                    if (GRAD_OPACITY) {
                        opacity_scale = gradient_opacity(0u, length(gw));
                    }
                    if (SHADE) {
                        let pos = ray.origin + mid * ray.dir;
                        lit = lighting(gw, pos, ray.dir, frame.material);
                        if (VOLUMETRIC) {
                            let sm = scalars_at(w.hit, ex, mid, mid).x;
                            let tau = tau_at(entry_of(sm)) * opacity_scale;
                            lit = volumetric_lighting(lit, o, d, mid, w.k, w.hit, ex, sm, pos,
                                                      ray.dir, gw, tau, seg.y);
                        }
                    }
                }
                integrate_within(ray, seg, w.hit.t, ex.t, w.hit.s, ex.s);
            }
            if (VOLUMETRIC) {
                ray_depth = ray_depth + piece_depth(w.k, w.hit, ex, w.hit.t, ex.t, o, d);
            }
            if (done() || ex.t >= seg.y) {
                break;
            }
            walk_across(&w, o, d, ex, seg.y);
        }
    }
    write_pixel(px, st);
}
