// First hit of the isosurfaces of an unstructured volume (core/src/passes/iso/mesh.rs): each
// pixel's ray walks the tetrahedra as unstructured.wgsl's does (lib/mesh.wgsl), within the
// part of it the near and far planes, the host's depth and the clipping planes keep, and
// writes each crossing of an iso-value as one layer of the G-buffer firsthit.wgsl writes (the
// same layout), which deferred.wgsl shades and composites.
//
// Crossings are exact. With point scalars the scalar is linear along a tetrahedron's segment,
// so a value is crossed where the line between the segment's end scalars meets it. With cell
// scalars, constant in each tetrahedron, a surface lies on the faces between tetrahedra whose
// scalars lie on either side of its value. A ray that leaves a non-convex mesh and enters it
// again starts afresh: outside the mesh there is no field to cross (as an image ray starts at
// its volume's face). The normal is the points' gradients interpolated at the hit
// (lib/mesh.wgsl gradient_in), facing the side the ray came from. Ambient accessibility walks
// the mesh from the hit along iso.counts.w directions of the hemisphere around the normal,
// each for iso.ao.x world units: a direction is occluded where its walk meets the far side of
// the iso-value at least one of iso.options.x steps from the hit (as firsthit.wgsl's first
// sample), open where it leaves the mesh first.
#include "lib/march.wgsl"
#include "lib/envmap.wgsl"
#include "lib/iso.wgsl"
#include "lib/mesh.wgsl"

// Per pixel: color.x = layers written, color.y = their accumulated opacity (deferred.wgsl
// reads the layer count).
@group(0) @binding(2) var<storage, read_write> state: array<PixelState>;
// G-buffer, one array layer per surface layer (as firsthit.wgsl's):
//   position  xyz world position of the hit, w iso index
//   normal    xyz unit world normal facing the viewer, w gradient magnitude (scalar / world unit)
//   extra     x window depth, y ambient accessibility (1: open), z distance along the ray
@group(0) @binding(8) var g_position: texture_storage_2d_array<rgba32float, write>;
@group(0) @binding(9) var g_normal: texture_storage_2d_array<rgba32float, write>;
@group(0) @binding(10) var g_extra: texture_storage_2d_array<rgba32float, write>;

// The pixel's layers so far, their accumulated opacity, and whether it has all it keeps.
var<private> layers: u32 = 0u;
var<private> alpha: f32 = 0.0;
var<private> full: bool = false;

// Whether the walk from index-space point p (in tetrahedron `tet`) along d reaches a scalar
// on the far side of v (the side where (s < v) differs from front_below) between
// iso.ao.x / iso.options.x and iso.ao.x world units; leaving the mesh first is open.
// Linear within each tetrahedron, the scalar is checked where the walk leaves each one and
// where it ends.
fn occluded(p: vec3<f32>, d: vec3<f32>, tet: u32, v: f32, front_below: bool) -> bool {
    let reach = iso.ao.x;
    let near = reach / f32(max(iso.options.x, 1u));
    var w = walk_inside(p, d, tet, 0.0, v);
    loop {
        let ex = walk_exit(&w, p, d, reach);
        if (ex.tf == NO_HIT) {
            return false;
        }
        var s = ex.s;
        let span = ex.t - w.hit.t;
        if (ex.t > reach && span > 0.0) {
            s = mix(w.hit.s, ex.s, (reach - w.hit.t) / span);
        }
        if (min(ex.t, reach) >= near && (s < v) != front_below) {
            return true;
        }
        let t = ex.tf >> 2u;
        if (ex.t >= reach || neighbours_of(t)[ex.tf & 3u] == NO_NEIGHBOUR) {
            return false;
        }
        walk_across(&w, p, d, ex, reach);
    }
    return false;
}

// Ambient accessibility at index-space point p of tetrahedron `tet` (on the side the ray
// came from) with world normal n: the fraction of the hemisphere's directions (Hammersley,
// uniform) not occluded.
fn ambient_access(p: vec3<f32>, tet: u32, n: vec3<f32>, v: f32, front_below: bool) -> f32 {
    let count = iso.counts.w;
    if (count == 0u) {
        return 1.0;
    }
    let frame_n = basis_around(n);
    var open = 0u;
    for (var i = 0u; i < count; i = i + 1u) {
        let dw = frame_n * uniform_hemisphere(hammersley(i, count));
        let d = (frame.world_to_index * vec4<f32>(dw, 0.0)).xyz;
        if (!occluded(p, d, tet, v, front_below)) {
            open = open + 1u;
        }
    }
    return f32(open) / f32(count);
}

// Writes the next layer for the crossing of iso-value `which` at distance t, in tetrahedron
// k (its points' gradients give the normal); `front` is the tetrahedron on the side the ray
// came from, `below` whether the scalar is below the value there.
fn write_hit(px: vec2<u32>, ray: Ray, t: f32, which: u32, below: bool, k: Tet, front: u32) {
    let x = ray.index_origin + t * ray.index_dir;
    let gw = (frame.gradient_to_world * vec4<f32>(gradient_in(k, x), 0.0)).xyz;
    let glen = length(gw);
    var n = -ray.dir;
    if (glen > 0.0) {
        n = select(gw, -gw, below) / glen;
    }
    let ao = ambient_access(x, front, n, iso_value(which), below);
    let c = vec2<i32>(px);
    let l = i32(layers);
    textureStore(g_position, c, l, vec4<f32>(ray.origin + t * ray.dir, f32(which)));
    textureStore(g_normal, c, l, vec4<f32>(n, glen));
    textureStore(g_extra, c, l, vec4<f32>(distance_to_depth(ray, t), ao, t, 0.0));
    layers = layers + 1u;
    alpha = alpha + (1.0 - alpha) * iso.colors[which].a;
    full = layers >= iso.counts.z || alpha >= frame.termination;
}

// The crossings of the piece from (ta, sa) to (tb, sb), the scalar linear between (ta = tb:
// a face between cells), nearest first.
fn cross_piece(px: vec2<u32>, ray: Ray, ta: f32, sa: f32, tb: f32, sb: f32, k: Tet, front: u32) {
    let n_iso = min(iso.counts.x, MAX_ISO);
    var crossed = 0u;
    var th: array<f32, MAX_ISO>;
    for (var i = 0u; i < n_iso; i = i + 1u) {
        let v = iso_value(i);
        if ((sa < v) != (sb < v)) {
            crossed = crossed | (1u << i);
            th[i] = clamp(ta + (v - sa) / (sb - sa) * (tb - ta), ta, tb);
        }
    }
    loop {
        if (crossed == 0u || full) {
            break;
        }
        let which = nearest_crossing(crossed, th);
        crossed = crossed & ~(1u << which);
        write_hit(px, ray, th[which], which, sa < iso_value(which), k, front);
    }
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    frame = frame_ubo;
    mesh = mesh_ubo;
    iso = iso_ubo;
    let px = gid.xy + frame.rect.xy;
    if (px.x >= frame.rect.z || px.y >= frame.rect.w) {
        return;
    }
    let ray = make_ray(px);
    let seg = segment_within(ray, px, vec2<f32>(0.0, ray.far));
    let o = ray.index_origin;
    let d = ray.index_dir;
    full = iso.counts.z == 0u || frame.termination <= 0.0;
    if (seg.x < seg.y && !full) {
        // (from the line's first boundary crossing, behind the camera too, as
        // unstructured.wgsl's walk)
        var w = walk_in(o, d, -3.0e38, seg.y);
        // where the ray left the previous tetrahedron into this one across a shared face,
        // within the segment: its scalar there and its index
        var have_prev = false;
        var s_prev = 0.0;
        var prev = 0u;
        loop {
            let ex = walk_exit(&w, o, d, seg.y);
            if (ex.tf == NO_HIT) {
                break;
            }
            let tet = w.hit.tf >> 2u;
            let lo = max(w.hit.t, seg.x);
            let hi = min(ex.t, seg.y);
            let inside = lo <= hi;
            if (inside) {
                if (have_prev) {
                    cross_piece(px, ray, w.hit.t, s_prev, w.hit.t, w.hit.s, w.k, prev);
                }
                let sv = scalars_at(w.hit, ex, lo, hi);
                if (!full) {
                    cross_piece(px, ray, lo, sv.x, hi, sv.y, w.k, tet);
                }
                s_prev = sv.y;
            }
            if (full || ex.t >= seg.y) {
                break;
            }
            have_prev = inside && neighbours_of(tet)[ex.tf & 3u] != NO_NEIGHBOUR;
            prev = tet;
            walk_across(&w, o, d, ex, seg.y);
        }
    }
    var st: PixelState;
    st.color = vec4<f32>(f32(layers), alpha, 0.0, 0.0);
    state[px.y * frame.width + px.x] = st;
}
