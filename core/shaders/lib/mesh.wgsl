// An unstructured volume on the GPU (core/src/resources/mesh): its bindings, the walk of a
// ray from tetrahedron to tetrahedron (entry through the boundary, exit faces from Plücker
// products, re-entry where a non-convex mesh lets the ray out and in again) and its
// transfer function read per table entry. "Index space" is the mesh's own coordinates
// relative to its centre; t is world distance. Shared by the ray caster (unstructured.wgsl)
// and the path tracer (pathtrace_mesh.wgsl).
#include "lib/common.wgsl"
#include "lib/ray.wgsl"

override CELL_SCALARS: bool = false;

struct Mesh {
    counts: vec4<u32>,  // tetrahedra, boundary triangles, hierarchy nodes, most steps
    unit: vec4<f32>,    // x: 1 / unit distance
    split: vec4<u32>,   // x: knots, or MESH_EVERY_ENTRY (pieces end at every table entry)
    knots: array<vec4<f32>, MESH_KNOTS / 4>, // table coordinates where pieces end, ascending
    opaque: array<vec4<u32>, MESH_OPAQUE_WORDS / 4>, // a bit per table entry of opacity > 0
    halves: vec4<u32>,  // x: the tetrahedra in the first binding of tets and neighbours
    // xyz: 1 / the box's extent per axis (index space → the unit cube, where VTK measures
    // the shadows' reach); w: a typical cell's size (the box's diagonal over the cube root of
    // the tetrahedra), the step volumetric shadows take the opacity of
    shadow: vec4<f32>,
}

struct BvhNode {
    lo: vec3<f32>,
    a: u32,             // leaf: first triangle; inner: second child
    hi: vec3<f32>,
    count: u32,         // triangles of a leaf, 0 for an inner node
}

@group(0) @binding(SLOT_MESH) var<uniform> mesh_ubo: Mesh;
// (read once into private memory, as `frame`: lavapipe gathers uniforms read in loops)
var<private> mesh: Mesh;
@group(0) @binding(SLOT_MESH_POINTS) var<storage, read> points: array<vec4<f32>>;
// (tetrahedra from mesh.halves.x on in the second binding: tet_ids)
@group(0) @binding(SLOT_MESH_TETS) var<storage, read> tets: array<vec4<u32>>;
@group(0) @binding(SLOT_MESH_TETS_HI) var<storage, read> tets_hi: array<vec4<u32>>;
// across face f of tetrahedron t (opposite its point f): 4 · neighbour + its face, or
// NO_NEIGHBOUR on the boundary (neighbours_of)
@group(0) @binding(SLOT_MESH_NEIGHBOURS) var<storage, read> neighbours: array<vec4<u32>>;
@group(0) @binding(SLOT_MESH_NEIGHBOURS_HI) var<storage, read> neighbours_hi: array<vec4<u32>>;
@group(0) @binding(SLOT_MESH_CELL_SCALARS) var<storage, read> cell_scalars: array<f32>;
// the scalar's gradient at each point (xyz; SHADE)
@group(0) @binding(SLOT_MESH_GRADIENTS) var<storage, read> gradients: array<vec4<f32>>;
// the opacity row's running integral at each table entry, in entry units:
// depth_prefix[i] = ∫₀ⁱ α (α linear between entries; MeshTransfer writes it with the tables)
@group(0) @binding(SLOT_MESH_DEPTH) var<storage, read> depth_prefix: array<f32>;
@group(0) @binding(SLOT_MESH_NODES) var<storage, read> nodes: array<BvhNode>;
// boundary triangles as 4 · tetrahedron + face, in the hierarchy's leaf order
@group(0) @binding(SLOT_MESH_BOUNDARY) var<storage, read> boundary: array<u32>;

const NO_NEIGHBOUR: u32 = 0xffffffffu;
const NO_HIT: u32 = 0xffffffffu;

// Tetrahedron t's point indices.
fn tet_ids(t: u32) -> vec4<u32> {
    if (t < mesh.halves.x) {
        return tets[t];
    }
    return tets_hi[t - mesh.halves.x];
}

// Across each face of tetrahedron t: 4 · neighbour + its face, or NO_NEIGHBOUR.
fn neighbours_of(t: u32) -> vec4<u32> {
    if (t < mesh.halves.x) {
        return neighbours[t];
    }
    return neighbours_hi[t - mesh.halves.x];
}

// Where a ray crosses a face: distance, the face as 4 · tet + face, the scalar there.
struct Hit {
    t: f32,
    tf: u32,
    s: f32,
}

// A triangle (a, b, c) with its point scalars and a normal n (face_of: the outward one).
struct Face {
    a: vec3<f32>,
    b: vec3<f32>,
    c: vec3<f32>,
    n: vec3<f32>,
    sa: f32,
    sb: f32,
    sc: f32,
}

fn face_of(t: u32, f: u32) -> Face {
    let ids = tet_ids(t);
    let pa = points[ids[(f + 1u) % 4u]];
    let pb = points[ids[(f + 2u) % 4u]];
    let pc = points[ids[(f + 3u) % 4u]];
    let q = points[ids[f]].xyz;
    var out = make_face(pa, pb, pc);
    out.n = select(out.n, -out.n, dot(out.n, q - out.a) > 0.0);
    return out;
}

// The triangle of points (xyz, w the scalar) a, b, c, its normal cross(b − a, c − a).
fn make_face(pa: vec4<f32>, pb: vec4<f32>, pc: vec4<f32>) -> Face {
    var out: Face;
    out.a = pa.xyz;
    out.b = pb.xyz;
    out.c = pc.xyz;
    out.sa = pa.w;
    out.sb = pb.w;
    out.sc = pc.w;
    out.n = cross(out.b - out.a, out.c - out.a);
    return out;
}

// The ray's entry into the mesh: the nearest boundary triangle facing the ray at a
// distance ≥ t_min, not of tetrahedron `skip` (the one the ray just left).
fn next_entry(o: vec3<f32>, d: vec3<f32>, t_min: f32, t_max: f32, skip: u32) -> Hit {
    var best: Hit;
    best.t = t_max;
    best.tf = NO_HIT;
    var stack: array<u32, MESH_BVH_STACK>;
    var sp = 0u;
    var node = 0u;
    let inv = 1.0 / d;
    loop {
        let nd = nodes[node];
        let t0 = (nd.lo - o) * inv;
        let t1 = (nd.hi - o) * inv;
        let near = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), t_min));
        let far = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), min(max(t0.z, t1.z), best.t));
        // (widened for rounding: flat boxes hold the faces of flat boundaries; written so
        // that a NaN, from a ray in a slab's plane, culls nothing)
        let visit = !(near - far > 1e-6 * (abs(near) + abs(far)) + 1e-6);
        if (visit && nd.count > 0u) {
            for (var i = nd.a; i < nd.a + nd.count; i = i + 1u) {
                let tf = boundary[i];
                if ((tf >> 2u) == skip) {
                    continue;
                }
                let fc = face_of(tf >> 2u, tf & 3u);
                if (dot(fc.n, d) >= 0.0) {
                    continue; // faces away: the ray would leave through it
                }
                // Möller–Trumbore, edges widened a little so that rays through an edge
                // enter by one of the triangles that share it
                let e1 = fc.b - fc.a;
                let e2 = fc.c - fc.a;
                let pv = cross(d, e2);
                let det = dot(e1, pv);
                if (abs(det) < 1e-30) {
                    continue;
                }
                let inv_det = 1.0 / det;
                let tv = o - fc.a;
                let u = dot(tv, pv) * inv_det;
                let qv = cross(tv, e1);
                let v = dot(d, qv) * inv_det;
                let th = dot(e2, qv) * inv_det;
                let eps = 1e-5;
                if (u >= -eps && v >= -eps && u + v <= 1.0 + eps && th >= t_min && th < best.t) {
                    best.t = th;
                    best.tf = tf;
                    if (CELL_SCALARS) {
                        best.s = cell_scalars[tf >> 2u];
                    } else {
                        let w = clamp(vec3<f32>(1.0 - u - v, u, v), vec3<f32>(0.0), vec3<f32>(1.0));
                        best.s = dot(w, vec3<f32>(fc.sa, fc.sb, fc.sc)) / max(w.x + w.y + w.z, 1e-30);
                    }
                }
            }
        }
        if (visit && nd.count == 0u && sp < MESH_BVH_STACK) {
            // the nearer child first (the first holds the lower half along the split axis,
            // taken as the box's longest), so that the nearest hit culls the farther boxes
            let ext = nd.hi - nd.lo;
            let along = select(select(d.z, d.y, ext.y >= ext.z), d.x, ext.x >= max(ext.y, ext.z));
            stack[sp] = select(nd.a, node + 1u, along < 0.0);
            sp = sp + 1u;
            node = select(node + 1u, nd.a, along < 0.0);
            continue;
        }
        if (sp == 0u) {
            break;
        }
        sp = sp - 1u;
        node = stack[sp];
    }
    return best;
}

// A tetrahedron in registers: its point indices and its points (xyz, w the point scalar).
struct Tet {
    ids: vec4<u32>,
    p0: vec4<f32>,
    p1: vec4<f32>,
    p2: vec4<f32>,
    p3: vec4<f32>,
}

fn load_tet(t: u32) -> Tet {
    var out: Tet;
    out.ids = tet_ids(t);
    out.p0 = points[out.ids.x];
    out.p1 = points[out.ids.y];
    out.p2 = points[out.ids.z];
    out.p3 = points[out.ids.w];
    return out;
}

// The point of `old` whose index is id (one of them).
fn shared_point(old: Tet, id: u32) -> vec4<f32> {
    var p = old.p3;
    p = select(p, old.p2, old.ids.z == id);
    p = select(p, old.p1, old.ids.y == id);
    return select(p, old.p0, old.ids.x == id);
}

// Tetrahedron t entered through its face f from `old` (whose exit face it shares): three
// of its points are old's, one load brings the fourth.
fn next_tet(old: Tet, t: u32, f: u32) -> Tet {
    var out: Tet;
    out.ids = tet_ids(t);
    let fresh = points[out.ids[f]];
    out.p0 = select(shared_point(old, out.ids.x), fresh, f == 0u);
    out.p1 = select(shared_point(old, out.ids.y), fresh, f == 1u);
    out.p2 = select(shared_point(old, out.ids.z), fresh, f == 2u);
    out.p3 = select(shared_point(old, out.ids.w), fresh, f == 3u);
    return out;
}

// The scalar's gradient at index-space point x of tetrahedron k, in index space: its
// points' gradients (resources/mesh/gradients.rs) weighted by x's barycentric coordinates
// (their mean in a tetrahedron too flat to invert).
fn gradient_in(k: Tet, x: vec3<f32>) -> vec3<f32> {
    let e1 = k.p1.xyz - k.p0.xyz;
    let e2 = k.p2.xyz - k.p0.xyz;
    let e3 = k.p3.xyz - k.p0.xyz;
    let det = dot(e1, cross(e2, e3));
    var l = vec4<f32>(0.25);
    if (abs(det) > 1e-30) {
        let r = x - k.p0.xyz;
        let l1 = dot(r, cross(e2, e3)) / det;
        let l2 = dot(r, cross(e3, e1)) / det;
        let l3 = dot(r, cross(e1, e2)) / det;
        l = clamp(vec4<f32>(1.0 - l1 - l2 - l3, l1, l2, l3), vec4<f32>(0.0), vec4<f32>(1.0));
    }
    return l.x * gradients[k.ids.x].xyz + l.y * gradients[k.ids.y].xyz +
        l.z * gradients[k.ids.z].xyz + l.w * gradients[k.ids.w].xyz;
}

// The ray's exit from tetrahedron k (index t), entered through face f_in at t_in, from the
// signs of the ray's products with the tetrahedron's edges (Plücker coordinates, as Platis
// and Theoharis 2003), taken from the entry point e: w(i, j) = d · ((p_i − e) × (p_j − e)).
// The faces (1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1) are outward (resources/mesh orients
// every tetrahedron positively), and the ray leaves through the one whose three edges'
// products are ≥ 0, which are then its exit point's barycentric weights. Of the faces but
// f_in and those whose products do not sum above 0, the one whose least product is largest
// (ties at an edge or rounding: the nearest miss); tf NO_HIT where the ray does not leave
// through it (a ray along a face).
fn exit_of(o: vec3<f32>, d: vec3<f32>, k: Tet, t: u32, f_in: u32, t_in: f32) -> Hit {
    let e = o + t_in * d;
    let r0 = k.p0.xyz - e;
    let r1 = k.p1.xyz - e;
    let r2 = k.p2.xyz - e;
    let r3 = k.p3.xyz - e;
    let c0 = cross(d, r0);
    let c1 = cross(d, r1);
    let c2 = cross(d, r2);
    let e01 = dot(c0, r1);
    let e02 = dot(c0, r2);
    let e03 = dot(c0, r3);
    let e12 = dot(c1, r2);
    let e13 = dot(c1, r3);
    let e23 = dot(c2, r3);
    // per face, its points' weights (0 for the point opposite) and the least of them
    let w0 = vec4<f32>(0.0, e23, -e13, e12);
    let w1 = vec4<f32>(-e23, 0.0, e03, -e02);
    let w2 = vec4<f32>(e13, -e03, 0.0, e01);
    let w3 = vec4<f32>(-e12, e02, -e01, 0.0);
    var m = vec4<f32>(
        min(min(e23, -e13), e12),
        min(min(-e23, e03), -e02),
        min(min(e13, -e03), e01),
        min(min(-e12, e02), -e01),
    );
    // A face whose weights do not sum above 0 is not crossed (a ray in its plane, as along
    // the faces of a grid's tetrahedra, touches it everywhere with weights 0): never the exit.
    let sums = vec4<f32>(w0.y + w0.z + w0.w, w1.x + w1.z + w1.w, w2.x + w2.y + w2.w,
                         w3.x + w3.y + w3.z);
    let out_of_play = (vec4<u32>(0u, 1u, 2u, 3u) == vec4<u32>(f_in)) | !(sums > vec4<f32>(0.0));
    m = select(m, vec4<f32>(-3.0e38), out_of_play);
    let best = max(max(m.x, m.y), max(m.z, m.w));
    let f = select(select(select(3u, 2u, m.z == best), 1u, m.y == best), 0u, m.x == best);
    let w = select(select(select(w3, w2, f == 2u), w1, f == 1u), w0, f == 0u);
    var out: Hit;
    out.tf = NO_HIT;
    if (!(w.x + w.y + w.z + w.w > 0.0)) {
        return out;
    }
    let l = max(w, vec4<f32>(0.0));
    let bary = l / (l.x + l.y + l.z + l.w);
    let depth = vec4<f32>(dot(r0, d), dot(r1, d), dot(r2, d), dot(r3, d));
    out.t = max(t_in + dot(bary, depth) / dot(d, d), t_in);
    out.tf = 4u * t + f;
    if (CELL_SCALARS) {
        out.s = cell_scalars[t];
    } else {
        out.s = dot(bary, vec4<f32>(k.p0.w, k.p1.w, k.p2.w, k.p3.w));
    }
    return out;
}

// The scalars at distances lo and hi of the segment from `entry` to `ex` (linear along it).
fn scalars_at(entry: Hit, ex: Hit, lo: f32, hi: f32) -> vec2<f32> {
    let span = ex.t - entry.t;
    if (span > 0.0) {
        return mix(vec2<f32>(entry.s), vec2<f32>(ex.s), (vec2<f32>(lo, hi) - entry.t) / span);
    }
    return vec2<f32>(entry.s, ex.s);
}

// A ray's walk through the mesh: the tetrahedron it is in (hit.tf >> 2, its points in k),
// where it entered it (hit.t, scalar hit.s, through face f_in; 4 when the walk started
// inside), where the ray leaves the boundary hierarchy's box, and the steps taken. hit.tf
// is NO_HIT once the ray is out of the mesh for good.
struct Walk {
    hit: Hit,
    k: Tet,
    f_in: u32,
    root_far: f32,
    steps: u32,
}

// A walk with the ray's distance out of the hierarchy's box and no tetrahedron yet.
fn walk_start(o: vec3<f32>, d: vec3<f32>) -> Walk {
    var w: Walk;
    let root = nodes[0];
    let r0 = (root.lo - o) / d;
    let r1 = (root.hi - o) / d;
    w.root_far = min(min(max(r0.x, r1.x), max(r0.y, r1.y)), max(r0.z, r1.z));
    w.hit.tf = NO_HIT;
    w.steps = 0u;
    return w;
}

// The walk of a ray entering the mesh through its boundary at t_min or beyond (before
// t_max).
fn walk_in(o: vec3<f32>, d: vec3<f32>, t_min: f32, t_max: f32) -> Walk {
    var w = walk_start(o, d);
    walk_enter(&w, o, d, t_min, t_max, NO_HIT);
    return w;
}

// The walk of a ray that starts at distance t inside tetrahedron `tet`, where the scalar is s.
fn walk_inside(o: vec3<f32>, d: vec3<f32>, tet: u32, t: f32, s: f32) -> Walk {
    var w = walk_start(o, d);
    w.hit.t = t;
    w.hit.tf = 4u * tet;
    w.hit.s = s;
    w.k = load_tet(tet);
    w.f_in = 4u;
    return w;
}

// Into the mesh through the nearest boundary triangle facing the ray at t_min or beyond
// (before t_max), not of tetrahedron `skip`.
fn walk_enter(w: ptr<function, Walk>, o: vec3<f32>, d: vec3<f32>, t_min: f32, t_max: f32, skip: u32) {
    (*w).hit = next_entry(o, d, t_min, t_max, skip);
    if ((*w).hit.tf != NO_HIT) {
        (*w).k = load_tet((*w).hit.tf >> 2u);
        (*w).f_in = (*w).hit.tf & 3u;
    }
}

// Where the ray leaves the walk's tetrahedron (tf NO_HIT when the walk is over: out of the
// mesh, or out of steps). A ray along a face leaves the tetrahedron where it entered and
// enters the mesh again beyond.
fn walk_exit(w: ptr<function, Walk>, o: vec3<f32>, d: vec3<f32>, t_max: f32) -> Hit {
    loop {
        if ((*w).hit.tf == NO_HIT || (*w).steps >= mesh.counts.w) {
            break;
        }
        let t = (*w).hit.tf >> 2u;
        let ex = exit_of(o, d, (*w).k, t, (*w).f_in, (*w).hit.t);
        (*w).steps = (*w).steps + 1u;
        if (ex.tf != NO_HIT) {
            return ex;
        }
        walk_enter(w, o, d, (*w).hit.t, t_max, t);
    }
    var none: Hit;
    none.tf = NO_HIT;
    return none;
}

// Past the walk's exit ex: into the neighbour across that face, or, on the boundary, into
// the next boundary triangle facing the ray: further on in a non-convex mesh, or right
// there where a face does not conform (the triangles on both sides differ), looked for a
// rounding error back. Where the ray leaves the hierarchy's box no triangle faces it beyond.
fn walk_across(w: ptr<function, Walk>, o: vec3<f32>, d: vec3<f32>, ex: Hit, t_max: f32) {
    let t = (*w).hit.tf >> 2u;
    let nb = neighbours_of(t)[ex.tf & 3u];
    let slack = 1e-5 * (abs(ex.t) + length(o));
    if (nb == NO_NEIGHBOUR) {
        if (ex.t >= (*w).root_far - slack) {
            (*w).hit.tf = NO_HIT;
        } else {
            walk_enter(w, o, d, ex.t - slack, t_max, t);
        }
        return;
    }
    (*w).hit.t = ex.t;
    (*w).hit.tf = nb;
    (*w).hit.s = select(ex.s, cell_scalars[nb >> 2u], CELL_SCALARS);
    (*w).k = next_tet((*w).k, nb >> 2u, nb & 3u);
    (*w).f_in = nb & 3u;
}

// The table coordinate (entries, 0 … TABLE_N − 1, unclamped) of scalar s.
fn entry_of(s: f32) -> f32 {
    return scalar_coord(0u, s) * f32(TABLE_N - 1u);
}

// Colour (rgb) and attenuation τ (a) at table coordinate x, linear between entries.
fn colour_tau(x: f32) -> vec4<f32> {
    let c = row_lookup(tables, 0, x / f32(TABLE_N - 1u), false);
    return vec4<f32>(c.rgb, tau_at(x));
}

// The attenuation τ (per world unit) at table coordinate x, linear between entries.
fn tau_at(x: f32) -> f32 {
    return row_lookup(tables, 1, x / f32(TABLE_N - 1u), false).x * mesh.unit.x;
}

// The opacity row's value at table entry i (the row tau_at reads, before 1 / unit distance).
fn alpha_entry(i: u32) -> f32 {
    return textureLoad(tables, vec2<i32>(i32(min(i, TABLE_N - 1u)), 1), 0).x;
}

// ∫ α from table entry i to i + f (0 ≤ f ≤ 1; α linear between entries).
fn alpha_within(i: u32, f: f32) -> f32 {
    let a0 = alpha_entry(i);
    return f * a0 + 0.5 * f * f * (alpha_entry(i + 1u) - a0);
}

// ∫ α over table coordinates [x0, x1] (x0 ≤ x1; α constant past the table's ends, as the
// lookups clamp): the entries' trapezoids where few lie between, else the difference of
// the running integral (depth_prefix), whose rounding is then small beside it.
fn alpha_integral(x0: f32, x1: f32) -> f32 {
    let last = f32(TABLE_N - 1u);
    var sum = 0.0;
    // the parts past the ends
    if (x0 < 0.0) {
        sum = sum + (min(x1, 0.0) - x0) * alpha_entry(0u);
    }
    if (x1 > last) {
        sum = sum + (x1 - max(x0, last)) * alpha_entry(TABLE_N - 1u);
    }
    let a = clamp(x0, 0.0, last);
    let b = clamp(x1, 0.0, last);
    if (b <= a) {
        return sum;
    }
    let ia = min(u32(a), TABLE_N - 2u);
    let ib = min(u32(b), TABLE_N - 2u);
    let fa = a - f32(ia);
    let fb = b - f32(ib);
    if (ib - ia > 8u) {
        return sum + depth_prefix[ib] - depth_prefix[ia] + alpha_within(ib, fb) - alpha_within(ia, fa);
    }
    var whole = 0.0;
    for (var i = ia; i < ib; i = i + 1u) {
        whole = whole + 0.5 * (alpha_entry(i) + alpha_entry(i + 1u));
    }
    return sum + whole + alpha_within(ib, fb) - alpha_within(ia, fa);
}

// The optical depth ∫ τ of a segment of length len along which the scalar runs linearly from
// s0 to s1: exact, τ being linear between the table entries; a few table reads whatever the
// span (shadow walks take one per tetrahedron).
fn segment_depth(s0: f32, s1: f32, len: f32) -> f32 {
    let x0 = entry_of(s0);
    let x1 = entry_of(s1);
    let span = abs(x1 - x0);
    if (!(span > 1e-4)) {
        return len * tau_at(0.5 * (x0 + x1));
    }
    return len * mesh.unit.x * alpha_integral(min(x0, x1), max(x0, x1)) / span;
}

// Where the piece from table coordinate xa toward x1 (up: increasing) ends: the next knot
// strictly beyond xa, or x1.
fn next_cut(xa: f32, x1: f32, up: bool) -> f32 {
    let n = mesh.split.x;
    if (n == MESH_EVERY_ENTRY) {
        let last = f32(TABLE_N - 1u);
        if (up && xa < last) {
            return min(select(floor(xa) + 1.0, 0.0, xa < 0.0), x1);
        } else if (!up && xa > 0.0) {
            return max(select(ceil(xa) - 1.0, last, xa > last), x1);
        }
        return x1;
    }
    if (up) {
        for (var i = 0u; i < n; i = i + 1u) {
            let k = mesh.knots[i / 4u][i % 4u];
            if (k > xa) {
                return min(k, x1);
            }
        }
    } else {
        for (var i = n; i > 0u; i = i - 1u) {
            let k = mesh.knots[(i - 1u) / 4u][(i - 1u) % 4u];
            if (k < xa) {
                return max(k, x1);
            }
        }
    }
    return x1;
}

// Whether a table entry from x0 to x1 (table coordinates, one entry wider each way for the
// lookups' rounding) has an opacity above 0.
fn any_opaque(x0: f32, x1: f32) -> bool {
    if (!(x0 <= x1)) {
        return true; // (NaN scalars: integrated as they are)
    }
    let last = f32(TABLE_N - 1u);
    let i0 = u32(clamp(floor(x0) - 1.0, 0.0, last));
    let i1 = u32(clamp(ceil(x1) + 1.0, 0.0, last));
    for (var w = i0 / 32u; w <= i1 / 32u; w = w + 1u) {
        var bits = mesh.opaque[w / 4u][w % 4u];
        if (w == i0 / 32u) {
            bits = bits & (0xffffffffu << (i0 % 32u));
        }
        if (w == i1 / 32u) {
            bits = bits & (0xffffffffu >> (31u - i1 % 32u));
        }
        if (bits != 0u) {
            return true;
        }
    }
    return false;
}

// Whether tetrahedron k (index t) is transparent: the transfer function's opacity is 0 over
// its scalars (the range of its points', or its cell scalar).
fn transparent_tet(k: Tet, t: u32) -> bool {
    var lo: f32;
    var hi: f32;
    if (CELL_SCALARS) {
        lo = cell_scalars[t];
        hi = lo;
    } else {
        lo = min(min(k.p0.w, k.p1.w), min(k.p2.w, k.p3.w));
        hi = max(max(k.p0.w, k.p1.w), max(k.p2.w, k.p3.w));
    }
    return !any_opaque(entry_of(lo), entry_of(hi));
}
