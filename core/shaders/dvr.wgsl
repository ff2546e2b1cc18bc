// Direct volume rendering: marches each pixel's ray through the volume, brick after brick
// (lib/volume.wgsl), and writes the pixel. Samples sit on one lattice per ray, whatever the
// bricking, so a bricked volume gives the same samples as an unbricked one. The lattice is
// VTK 9.2's (tests/regression/SAMPLING.md): t_k = t_entry + (k + 1)·Δ (k + jitter with
// jittering), the first sample taken even past the exit, a sample on the exit face kept,
// and up to one step past opaque depth and clipping planes.
#include "lib/common.wgsl"
#include "lib/ray.wgsl"
#include "lib/volume.wgsl"
#include "lib/march.wgsl"
#include "lib/intermix.wgsl"
#include "lib/blanking.wgsl"
#include "lib/rectilinear.wgsl"
#include "lib/table2d.wgsl"
#include "lib/shading.wgsl"
#include "lib/shadow.wgsl"
#include "lib/classify.wgsl"
#include "lib/output.wgsl"

// Pipeline constants: each combination is its own pipeline, so the ray loop carries only
// the code of the mode it runs (core/src/passes/dvr.rs, DvrVariant).
override BLEND: u32 = 0u;
override SKIP: bool = false;
// MIP and MinIP (one component): skip blocks whose scalar range cannot move the ray's
// extremum, i.e. the block's max ≤ the running max (MIP), its min ≥ the running min (MinIP).
// Such a block's samples leave the value unchanged, so the image is the same as without
// (exactly so in real arithmetic; a filtered f32 sample may round an ulp past its corners).
override RANGE_SKIP: bool = false;
override CROP: bool = false;
// A streamed frame (its bricks exceed the memory budget): several passes, each with a group
// of bricks resident, front to back. A ray marches until its next sample's brick waits for
// a later pass (PAGE_MISSING), keeps its state in `state` and resumes there; misc.w holds
// the next sample's index, or −1 once the pixel is written.
override STREAMING: bool = false;
// Quadrature::Midpoint: samples in the middle of their steps, the ray ending exactly where
// it leaves the volume, opaque depth or a clipping plane (its last part, shorter than a
// step, sampled after the loop at its middle).
override MIDPOINT: bool = false;
// Quadrature::Adaptive, unshaded composite (with MIDPOINT): a step per block (its occupancy
// value).
override ADAPTIVE: bool = false;

@group(0) @binding(SLOT_RAY_STATE) var<storage, read_write> state: array<PixelState>;
// FLAG_DEPTH_RANGE: the window depth where each pixel's ray starts (depth_in: where it ends).
@group(0) @binding(SLOT_DEPTH_NEAR) var depth_near: texture_2d<f32>;

// The intermixed volumes (lib/intermix.wgsl): the rays march the world box holding every
// volume; each sample composites the main volume where its grid holds the sample, then each
// intermixed volume in turn where its grid does, as VTK's multi-volume shader does. A grid
// of `dims` points holds index-space point p (in_grid) as that shader decides: it tests
// the sample's texture coordinate against [0, 1], and a point-data texture spans half a
// point beyond the outer points, so p may lie up to half a point outside the grid (where
// the texture's clamping reads the outer points).
fn in_grid(p: vec3<f32>, dims: vec3<f32>) -> bool {
    return all(p >= vec3<f32>(-0.5)) && all(p <= dims - 0.5);
}

// Colour (not premultiplied) and step-corrected opacity of intermixed volume j at world
// point pos: zero outside its grid; shaded by its own gradient (central differences, one
// point apart) when SHADE is on.
fn intermixed_sample(j: u32, pos: vec3<f32>, view_dir: vec3<f32>) -> vec4<f32> {
    let v = intermix.volumes[j];
    let p = intermixed_point(j, pos);
    if (!in_grid(p, v.dims.xyz)) {
        return vec4<f32>(0.0);
    }
    var e = intermixed_entry(j, 0u, intermixed_value(j, p));
    if (SHADE && e.a > 0.0) {
        let ex = vec3<f32>(1.0, 0.0, 0.0);
        let ey = vec3<f32>(0.0, 1.0, 0.0);
        let ez = vec3<f32>(0.0, 0.0, 1.0);
        let g = 0.5 * vec3<f32>(
            intermixed_value(j, p + ex) - intermixed_value(j, p - ex),
            intermixed_value(j, p + ey) - intermixed_value(j, p - ey),
            intermixed_value(j, p + ez) - intermixed_value(j, p - ez));
        let n = (v.gradient_to_world * vec4<f32>(g, 0.0)).xyz;
        e = vec4<f32>(shade(e.rgb, n, pos, view_dir), e.a);
    }
    return e;
}

// `color` with the sample c (colour not premultiplied) composited behind it.
fn over(color: vec4<f32>, c: vec4<f32>) -> vec4<f32> {
    let w = (1.0 - color.a) * c.a;
    return vec4<f32>(color.rgb + w * c.rgb, color.a + w);
}


// Per min–max block, the first component's (min, max) over every point a sample in the
// block interpolates from (nearest or trilinear), widened where the storage rounds the data
// (MinMaxGrid::sample_bounds). Built once per volume upload; read by RANGE_SKIP only.
@group(0) @binding(SLOT_BLOCK_RANGE) var block_range: texture_3d<f32>;

// Whether the samples of the block holding p cannot change the extremum v (MIP: none can
// exceed it; MinIP: none can fall below it); a tie leaves max/min unchanged too.
fn block_keeps_extremum(p: vec3<f32>, v: f32) -> bool {
    let r = textureLoad(block_range, block_coord(p), 0).xy;
    if (BLEND == BLEND_MAXIMUM) {
        return r.y <= v;
    }
    return r.x >= v;
}

// The ray's extremum after sample s (MIP: maximum, MinIP: minimum): per component for one
// or independent components; for dependent components the whole sample whose opacity
// component (the last) is the extremum, as vtkGPUVolumeRayCastMapper keeps it, so colour and
// opacity come from one sample. The first sample (`first`) is taken as it is.
fn extremum(value: vec4<f32>, s: vec4<f32>, first: bool) -> vec4<f32> {
    if (first) {
        return s;
    }
    if (!INDEPENDENT) {
        let oc = NCOMP - 1u;
        let better = select(s[oc] < value[oc], s[oc] > value[oc], BLEND == BLEND_MAXIMUM);
        return select(value, s, better);
    }
    if (BLEND == BLEND_MAXIMUM) {
        return max(value, s);
    }
    return min(value, s);
}

// The projections (MIP, MinIP, average, additive): the march's running value and misc.x,
// the samples counted, after a sample of scalars `s` standing for `w` steps (1, or less for
// a midpoint ray's last, shorter step). VTK: the average takes the opacity-weighted
// normalised scalars of the samples inside its range; additive sums the same terms, the
// opacity scaled linearly by step / unit distance.
fn project(s: vec4<f32>, w: f32) {
    if (BLEND == BLEND_MAXIMUM || BLEND == BLEND_MINIMUM) {
        m.value = extremum(m.value, s, m.misc.x == 0.0);
        m.misc.x = m.misc.x + 1.0;
    } else if (BLEND == BLEND_AVERAGE) {
        let r = frame.average_range;
        if (!has_flag(FLAG_AVERAGE_RANGE) || (s.x >= r.x && s.x <= r.y)) {
            m.value = m.value + w * projection_term(s, vec4<f32>(1.0));
            m.misc.x = m.misc.x + w;
        }
    } else {
        m.value = m.value + w * projection_term(s, frame.additive_scale);
        m.misc.x = m.misc.x + 1.0;
    }
}

// Opacity × normalised scalar per component (average and additive blend modes), the
// opacity scaled by `scale` per component.
fn projection_term(s: vec4<f32>, scale: vec4<f32>) -> vec4<f32> {
    var out = vec4<f32>(0.0);
    for (var c = 0u; c < NCOMP; c = c + 1u) {
        let u = clamp(scalar_coord(c, s[c]), 0.0, 1.0);
        out[c] = raw_alpha(c, s[c]) * u * scale[c];
    }
    return out;
}

// The slice blend mode (VTK 9.2's SLICE_BLEND with a vtkPlane): the pixel's state from the
// point at distance t where its ray meets the plane frame.slice, box being the ray's
// interval in the volume's box and term where the opaque depth ends it. Nothing where the
// ray runs parallel to the plane, or the point lies outside the box, behind the camera,
// at or past the opaque depth, on the cut side of a clipping plane, in a cropped region or
// blanked. The colour is the transfer function's as given, premultiplied by the scalar
// opacity; the alpha is that opacity times gradient opacity (VTK's computeColor, then
// rgb × opacity); shading as composite's. Independent components mix as the maximum
// intensity projection does (classify_value), unshaded. The depth is the point's once
// the alpha exceeds the depth threshold.
fn slice_state(ray: Ray, box: vec2<f32>, term: f32) -> PixelState {
    var st: PixelState;
    let pl = frame.slice;
    let rate = dot(pl.xyz, ray.index_dir);
    let t = -(dot(pl.xyz, ray.index_origin) + pl.w) / rate;
    // (written so that a NaN t, from a ray parallel to the plane, also leaves)
    if (!(t >= max(box.x, 0.0) && t <= box.y && t < term)) {
        return st;
    }
    let cl = clip_interval(ray, vec2<f32>(t, t));
    let lp = ray.index_origin + t * ray.index_dir;
    let p = grid_point(lp);
    if (cl.x > cl.y || (CROP && !in_crop(lp)) || left_out(p)) {
        return st;
    }
    let s = sample_scalars(p);
    var color: vec4<f32>;
    if (INDEPENDENT && NCOMP > 1u) {
        color = classify_value(s);
    } else {
        let oc = select(NCOMP - 1u, 0u, INDEPENDENT);
        let a = raw_alpha(0u, s[oc]);
        var rgb = classify(0u, s.x).rgb;
        if (!INDEPENDENT && NCOMP == 4u) {
            rgb = clamp(sample_texel(p).rgb, vec3<f32>(0.0), vec3<f32>(1.0));
        }
        var alpha = a;
        if (SHADE || GRAD_OPACITY) {
            let g = world_gradient(gradient_at(p, s), oc);
            if (GRAD_OPACITY) {
                alpha = a * gradient_opacity(0u, length(g));
            }
            if (SHADE) {
                rgb = shade(rgb, g, ray.origin + t * ray.dir, ray.dir);
            }
        }
        color = vec4<f32>(rgb * a, alpha);
    }
    st.color = color;
    if (color.a > frame.depth_threshold) {
        st.misc.y = distance_to_depth(ray, t);
        st.misc.z = 1.0;
    }
    return st;
}

// A ray's samples on VTK 9.2's lattice: sample k (0 ≤ k < k_end) at seg.x + (k + jit)·dt;
// the ray ends at seg.y. No sample where seg is empty (x ≥ y, or NaN).
struct Lattice {
    seg: vec2<f32>,
    jit: f32,
    dt: f32,
    k_end: f32,
}

// The lattice of pixel px's ray (pix: its index), box being the ray's interval in the
// volume's box (or the intermixed volumes' box) and term where the host's opaque depth
// ends it. Also sets the shadow rays' jitter and, for a piece, what lib/output.wgsl needs.
fn ray_lattice(ray: Ray, px: vec2<u32>, pix: u32, box: vec2<f32>, term: f32) -> Lattice {
    let dt = frame.sample_distance;
    var seg = vec2<f32>(max(box.x, 0.0), min(box.y, ray.far));
    let cl = clip_interval(ray, vec2<f32>(seg.x, term));
    var first_forced = false;
    var jit = 1.0; // VTK: g_rayOrigin += g_dirStep (no jitter): the first sample one step in
    if (has_flag(FLAG_JITTER)) {
        jit = hash01(pix ^ frame.jitter_seed);
        shadow_jitter = jit;
    }
    // (pre-integrated, the samples stay on the steps' ends, each classifying its step)
    if (MIDPOINT && !PREINT) {
        jit = 0.5;
    }
    if (!(max(seg.x, cl.x) < min(seg.y, cl.y))) {
        seg = vec2<f32>(1.0, 0.0);
    } else {
        seg.x = cl.x;
        seg.y = min(seg.y, cl.y + select(dt, 0.0, MIDPOINT));
        if (frame.clip_planes > 0u) {
            // VTK discards a clipped ray whose first sample lies outside the box
            if (seg.x + jit * dt > box.y) {
                seg = vec2<f32>(1.0, 0.0);
            }
        } else if (seg.x + jit * dt >= seg.y && !has_flag(FLAG_PIECE) && !MIDPOINT) {
            // VTK always takes its first sample (clamped to the edge) even past the exit
            first_forced = true;
        }
    }
    // A piece of a whole volume (FLAG_PIECE): samples on the whole's lattice, and a face two
    // pieces share sampled once, by the nearer piece: the ray's part here is half-open
    // unless the ray leaves the whole volume here.
    var half_open = false;
    if (has_flag(FLAG_PIECE)) {
        let whole = whole_interval(ray);
        let tg = whole.x;
        let tge = whole.y;
        // (the whole ray's first sample forced past its exit, as above, falls to the piece
        // where the ray enters the whole)
        let forced = frame.clip_planes == 0u && tg < tge && tg + jit * dt >= tge;
        piece_samples = select(max(floor((tge - tg) / dt - jit) + 1.0, 0.0), 1.0, forced);
        piece_last = box.y >= tge - 1.0e-3 * dt;
        half_open = !piece_last;
        if (seg.x < seg.y) {
            first_forced = forced && seg.x <= tg + 1.0e-3 * dt;
            seg.x = whole_lattice_from(tg, seg.x, dt, jit);
        }
    }
    // A depth range (Renderer::render_between): the lattice's samples in [near, far) only,
    // counted alike at both ends so that ranges which meet share no sample.
    // With midpoints the range is the path itself: its steps end exactly at both ends.
    var range_samples = 1.0e7;
    if (has_flag(FLAG_DEPTH_RANGE) && seg.x < seg.y && MIDPOINT) {
        let near = depth_to_distance(ray, px, textureLoad(depth_near, vec2<i32>(px), 0).x);
        let far = depth_to_distance(ray, px, textureLoad(depth_in, vec2<i32>(px), 0).x);
        seg = vec2<f32>(max(seg.x, near), min(seg.y, far));
    } else if (has_flag(FLAG_DEPTH_RANGE) && seg.x < seg.y) {
        let near = depth_to_distance(ray, px, textureLoad(depth_near, vec2<i32>(px), 0).x);
        let far = depth_to_distance(ray, px, textureLoad(depth_in, vec2<i32>(px), 0).x);
        let first = max(ceil((near - seg.x) / dt - jit), 0.0);
        range_samples = ceil((far - seg.x) / dt - jit) - first;
        seg.x = seg.x + first * dt;
        first_forced = false;
        if (range_samples <= 0.0) {
            seg = vec2<f32>(1.0, 0.0);
        }
    }
    // Bounded below 2^24 so that k + 1 is always exact and the loop always ends. Samples
    // up to the segment's end, one exactly on it too (VTK keeps a sample on the exit face).
    let k_last = (seg.y - seg.x) / dt - jit;
    var k_end = min(select(floor(k_last) + 1.0, ceil(k_last), half_open), 1.0e7);
    if (first_forced) {
        k_end = max(k_end, 1.0);
    }
    if (MIDPOINT) {
        // whole steps only: the rest of the ray is one shorter step (adaptive: k counts
        // the sample distances walked, and the last step ends at the path's end)
        k_end = min(select(floor((seg.y - seg.x) / dt), (seg.y - seg.x) / dt, ADAPTIVE), 1.0e7);
    }
    return Lattice(seg, jit, dt, min(k_end, range_samples));
}

// One ray's march, shared by the march functions below (one per quadrature): its lattice,
// where it stands on it (k: the next sample) and what it has gathered (the PixelState
// fields).
struct March {
    lat: Lattice,
    k: f32,
    // a streamed ray whose next sample's brick waits for a later pass
    suspended: bool,
    color: vec4<f32>,
    value: vec4<f32>,
    misc: vec4<f32>,
    // Where the opacity first passes the depth threshold, turned into a depth after the
    // march: lavapipe runs a branch's code for all lanes whenever any lane takes it, and
    // the conversion reads the camera at a dynamic index (lib/ray.wgsl) with a gather per
    // matrix element.
    depth_t: f32,
    // PREINT: the scalars of sample front_k, the last taken (composite keeps them in the
    // ray state's `value`, and front_k + 2 in misc.x: 0 there means none), and whether its
    // block was occupied.
    front: vec4<f32>,
    front_k: f32,
    front_occupied: bool,
}
var<private> m: March;

// The march of lattice `lat` from the ray state st (a streamed ray resumes at its next
// sample).
fn begin_march(lat: Lattice, st: PixelState) {
    m.lat = lat;
    m.k = 0.0;
    if (STREAMING) {
        m.k = st.misc.w;
    }
    m.suspended = false;
    m.color = st.color;
    m.value = st.value;
    m.misc = st.misc;
    m.depth_t = -1.0;
    m.front = st.value;
    m.front_k = st.misc.x - 2.0;
    m.front_occupied = true;
}

// The distance along the ray of lattice sample k.
fn lattice_t(k: f32) -> f32 {
    return m.lat.seg.x + (k + m.lat.jit) * m.lat.dt;
}

// Composites c (not premultiplied) over the ray's colour, and notes the distance t where
// its opacity first passes the depth threshold (misc.z: passed; turned into a depth after
// the march).
fn composite_over(c: vec4<f32>, t: f32) {
    m.color = over(m.color, c);
    if (m.misc.z == 0.0 && m.color.a > frame.depth_threshold) {
        m.depth_t = t;
        m.misc.z = 1.0;
    }
}

// RANGE_SKIP: MIP / MinIP block by block. An outer loop decides per block, as the ray
// enters it, whether to skip the block whole or to march all its samples in the inner loop.
// Not a test inside the sample loop: lavapipe runs a branch's code for all lanes whenever
// any lane takes it, so a per-sample test costs the lookup every sample. Skipping waits for
// the ray to hold a value (misc.x counts the samples taken). Samples stay on the lattice:
// each block's run ends at the first k past its exit, as SKIP's jump does. Leaves k at
// k_end, so march_lattice takes no sample after it.
fn march_extremum_blocks(ray: Ray) {
    let seg = m.lat.seg;
    let jit = m.lat.jit;
    let dt = m.lat.dt;
    loop {
        if (m.k >= m.lat.k_end) {
            break;
        }
        let p0 = ray.index_origin + lattice_t(m.k) * ray.index_dir;
        let next = max(m.k + 1.0, ceil((block_exit(ray, p0) - seg.x) / dt - jit));
        if (m.misc.x > 0.0 && block_keeps_extremum(p0, m.value.x)) {
            m.k = next;
            continue;
        }
        let stop = min(next, m.lat.k_end);
        loop {
            if (m.k >= stop) {
                break;
            }
            let p = ray.index_origin + lattice_t(m.k) * ray.index_dir;
            if ((!CROP || in_crop(p)) && !left_out(p)) {
                m.value = extremum(m.value, sample_scalars(p), m.misc.x == 0.0);
                m.misc.x = m.misc.x + 1.0;
            }
            m.k = m.k + 1.0;
        }
    }
}

// Quadrature::Adaptive: steps of as many sample distances as the block holding the middle
// of the step's first sample distance allows, a coarse one ending at the block's exit
// (never shorter than one), each sampled at its middle, its opacity corrected for its
// length. One loop, one sample an iteration, the block's exit computed only for coarse
// steps and skips (nested loops, or work some lanes do and others not, leave lanes idle on
// lavapipe). It ends the ray: the midpoint tail takes no sample after it.
fn march_adaptive(ray: Ray) {
    let seg = m.lat.seg;
    let dt = m.lat.dt;
    let k_end = m.lat.k_end;
    loop {
        if (m.k >= k_end) {
            break;
        }
        let k = m.k;
        let probe = ray.index_origin + (seg.x + (k + 0.5) * dt) * ray.index_dir;
        let occ = block_texel(probe);
        let mult = occ & 0xffu;
        if (SKIP && mult == 0u) {
            m.k = max((leap_exit(ray, probe, occ >> 8u) - seg.x) / dt, k + 0.5);
            continue;
        }
        var k1 = min(k + 1.0, k_end);
        var whole = k1 == k + 1.0;
        var w = 1.0;
        if (mult > 1u) {
            let h = f32(mult);
            let exit = (block_exit(ray, probe) - seg.x) / dt;
            k1 = min(min(k + h, max(exit, k + 1.0)), k_end);
            whole = k1 == k + h;
            w = h;
        }
        // (a whole step's length exact: its opacity needs no pow)
        w = select(k1 - k, w, whole);
        let t = seg.x + 0.5 * (k + k1) * dt;
        let p = grid_point(ray.index_origin + t * ray.index_dir);
        if (STREAMING && waits(p, ray.index_dir)) {
            m.suspended = true;
            break;
        }
        let s = sample_scalars(p);
        var c = classify_sample(s, s, p, ray.origin + t * ray.dir, ray.dir);
        if (!whole) {
            c.a = 1.0 - pow(max(1.0 - c.a, 0.0), w);
        } else if (mult >= 2u) {
            let q = (1.0 - c.a) * (1.0 - c.a);
            c.a = 1.0 - select(q, q * q, mult >= 4u);
        }
        m.k = k1;
        if (c.a > 0.0) {
            composite_over(c, t);
            if (m.color.a >= frame.termination) {
                break;
            }
        }
    }
}

// PREINT: the front scalars of the segment ending at sample s (index-space point lp, the
// segment starting at `start`), and s becomes the next segment's front.
fn segment_front(k: f32, start: vec3<f32>, lp: vec3<f32>, s: vec4<f32>) -> vec4<f32> {
    var sf = m.front;
    if (m.front_k != k - 1.0) {
        sf = front_scalars(grid_point(start), s);
        _ = grid_point(lp);
    }
    return sf;
}

// The lattice's samples (VTK's quadrature, and the whole steps of the midpoint rule), from
// k to k_end: empty-space skipping, cropping, blanking and masks, streaming, then each
// sample composited (with the intermixed volumes) or projected. Composite stops at early
// ray termination.
fn march_lattice(ray: Ray) {
    let seg = m.lat.seg;
    let jit = m.lat.jit;
    let dt = m.lat.dt;
    let k_end = m.lat.k_end;
    loop {
        if (m.k >= k_end) {
            break;
        }
        let k = m.k;
        let t = lattice_t(k);
        let lp = ray.index_origin + t * ray.index_dir;
        let p = grid_point(lp);
        var occupied = true;
        var occ = 0u;
        if (SKIP) {
            occ = block_texel(p);
            occupied = (occ & 0xffu) != 0u;
        }
        // PREINT takes the sample after one taken in an occupied block even in an empty
        // block: its segment begins in the occupied one.
        if (SKIP && !occupied && !(PREINT && m.front_occupied && m.front_k == k - 1.0)) {
            let next = max(k + 1.0, ceil((leap_exit(ray, lp, occ >> 8u) - seg.x) / dt - jit));
            if (BLEND == BLEND_AVERAGE || BLEND == BLEND_ADDITIVE) {
                // their terms there are 0, but the samples count
                m.misc.x = m.misc.x + min(next, k_end) - k;
            }
            m.k = next;
            continue;
        }
        if ((CROP && !in_crop(lp)) || left_out(p)) {
            m.k = k + 1.0;
            continue;
        }
        if (STREAMING && waits(p, ray.index_dir)) {
            m.suspended = true;
            break;
        }
        // (intermixed, the main volume's sample is read only inside its grid)
        let s = sample_scalars(select(p, clamp(p, vec3<f32>(0.0), frame.dims.xyz - 1.0), INTERMIX > 0u));
        if (BLEND == BLEND_COMPOSITE) {
            var sf = s;
            if (PREINT) {
                sf = segment_front(k, lp - dt * ray.index_dir, lp, s);
                m.front = s;
                m.front_k = k;
                m.front_occupied = occupied;
            }
            let pos = ray.origin + t * ray.dir;
            var c = vec4<f32>(0.0);
            if (INTERMIX == 0u || in_grid(p, frame.dims.xyz)) {
                c = classify_sample(sf, s, p, pos, ray.dir);
            }
            for (var j = 0u; j < INTERMIX; j = j + 1u) {
                m.color = over(m.color, c);
                c = intermixed_sample(j, pos, ray.dir);
            }
            if (c.a > 0.0 || INTERMIX > 0u) {
                composite_over(c, t);
                if (m.color.a >= frame.termination) {
                    break;
                }
            }
        } else {
            project(s, 1.0);
        }
        m.k = k + 1.0;
    }
}

// Quadrature::Midpoint: the part of the ray past the last whole step, sampled at its
// middle, weighted by its length in steps: composite corrects the opacity for it, average
// and additive weigh their terms (and average its count), MIP and MinIP take the sample as
// it is.
fn march_midpoint_tail(ray: Ray) {
    let seg = m.lat.seg;
    let dt = m.lat.dt;
    let k_end = m.lat.k_end;
    if (m.suspended || m.k < k_end || (BLEND == BLEND_COMPOSITE && m.color.a >= frame.termination)) {
        return;
    }
    let w = (seg.y - seg.x) / dt - k_end;
    // (pre-integrated: the last step's end, classifying the step from its start)
    let t = select(seg.x + (k_end + 0.5 * w) * dt, seg.y, PREINT);
    let lp = ray.index_origin + t * ray.index_dir;
    let p = grid_point(lp);
    let inside = w > 0.0 && !((CROP && !in_crop(lp)) || left_out(p));
    var occupied = inside;
    if (SKIP && inside) {
        occupied = block_occupied(p);
    }
    if (occupied && STREAMING && waits(p, ray.index_dir)) {
        m.suspended = true; // (resumes here: k stays k_end)
    } else if (occupied) {
        let s = sample_scalars(p);
        if (BLEND == BLEND_COMPOSITE) {
            var sf = s;
            if (PREINT) {
                let start = ray.index_origin + (seg.x + k_end * dt) * ray.index_dir;
                sf = segment_front(k_end, start, lp, s);
            }
            var c = classify_sample(sf, s, p, ray.origin + t * ray.dir, ray.dir);
            c.a = 1.0 - pow(max(1.0 - c.a, 0.0), w);
            if (c.a > 0.0) {
                composite_over(c, t);
            }
        } else {
            project(s, w);
        }
    } else if (inside && BLEND == BLEND_AVERAGE) {
        m.misc.x = m.misc.x + w; // (an empty block's samples count, their terms are 0)
    }
}

// The ray state after the march: the depth sample's window depth, the pre-integration
// front kept for a streamed ray's next pass, and a streamed ray's next sample (−1: done).
fn end_march(ray: Ray) -> PixelState {
    var st: PixelState;
    st.color = m.color;
    st.value = m.value;
    st.misc = m.misc;
    if (m.depth_t >= 0.0) {
        st.misc.y = distance_to_depth(ray, m.depth_t);
    }
    if (PREINT) {
        st.value = m.front;
        st.misc.x = m.front_k + 2.0;
    }
    if (STREAMING) {
        st.misc.w = select(-1.0, m.k, m.suspended);
    }
    return st;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    frame = frame_ubo;
    enter_volume();
    // The dispatch covers only frame.rect, the pixels the volume's box can project to.
    let px = gid.xy + frame.rect.xy;
    if (px.x >= frame.rect.z || px.y >= frame.rect.w) {
        return;
    }
    let pix = px.y * frame.width + px.x;
    var st: PixelState;
    if (STREAMING) {
        st = state[pix];
        if (st.misc.w < 0.0) {
            return;
        }
        locate_slack = 0.5;
    }
    let ray = make_ray(px);
    var box = box_interval(ray, vec3<f32>(0.0), frame.dims.xyz - 1.0);
    if (INTERMIX > 0u) {
        box = slab_interval(ray.origin, ray.dir, intermix.box_lo.xyz, intermix.box_hi.xyz);
    }
    // VTK 9.2: the ray ends at the opaque depth or a clipping plane, but its loop tests that
    // end only after stepping, so it samples up to one step past it (never past the box).
    var term = ray.far;
    if (has_flag(FLAG_DEPTH_INPUT)) {
        let d = textureLoad(depth_in, vec2<i32>(px), 0).x;
        term = min(term, depth_to_distance(ray, px, d));
    }
    if (BLEND == BLEND_SLICE) {
        write_pixel(px, slice_state(ray, box, term));
        return;
    }
    let lat = ray_lattice(ray, px, pix, box, term);
    // (written so that NaN from a degenerate ray also leaves)
    if (!(lat.seg.x < lat.seg.y)) {
        if (STREAMING) {
            st.misc.w = -1.0;
            state[pix] = st;
        }
        write_pixel(px, st);
        return;
    }
    begin_march(lat, st);
    if (RANGE_SKIP) {
        march_extremum_blocks(ray);
    }
    if (ADAPTIVE) {
        march_adaptive(ray);
    } else {
        march_lattice(ray);
    }
    if (MIDPOINT && !ADAPTIVE) {
        march_midpoint_tail(ray);
    }
    st = end_march(ray);
    if (STREAMING) {
        state[pix] = st;
        if (m.suspended) {
            return;
        }
    }
    write_pixel(px, st);
}
