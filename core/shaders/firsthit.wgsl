// First hit of the isosurfaces: marches each pixel's ray through the volume with the rays,
// segment (near/far planes, the host's depth, clipping planes), cropping, empty-space
// skipping and sample lattice of the dvr pass; wherever the field crosses one of the
// iso-values between two consecutive samples, the crossing is refined by interval
// bisection on the exactly interpolated field and written as one layer of the G-buffer:
// position, normal and gradient magnitude at the refined hit, iso index, window depth and
// ambient occlusion. Marching goes on behind translucent surfaces until the accumulated
// opacity reaches the termination threshold or the G-buffer's layers are full; deferred.wgsl
// shades the layers and composites them front to back.
#include "lib/common.wgsl"
#include "lib/ray.wgsl"
#include "lib/volume.wgsl"
#include "lib/march.wgsl"
#include "lib/envmap.wgsl"
#include "lib/iso.wgsl"
#include "lib/blanking.wgsl"
#include "lib/rectilinear.wgsl"

// Pipeline constants (core/src/passes/iso.rs, FirstHitVariant).
override SKIP: bool = false;
override CROP: bool = false;
// A streamed frame (its bricks exceed the memory budget): several passes, each with a group
// of bricks resident, front to back, as in dvr.wgsl. A ray stops before a sample whose brick
// waits for a later pass and resumes there. Samples stay within one voxel of the brick
// serving them (the host streams only with a sample distance of at most one voxel and no
// ambient occlusion), so its apron holds every point a crossing's refinement reads.
override STREAMING: bool = false;
// The component whose isosurfaces are drawn (core/src/passes/iso.rs, iso_component).
override ISO_COMP: u32 = 0u;

// Per pixel: color.x = layers written, color.y = their accumulated opacity; deferred.wgsl
// reads the layer count from it. Streaming also keeps: color.z the next sample, color.w 1
// while the ray waits (−1 once done), value = (whether a previous sample is held, its
// distance, its scalar, whether the segment's end is still to sample).
@group(0) @binding(2) var<storage, read_write> state: array<PixelState>;
// G-buffer, one array layer per surface layer:
//   position  xyz world position of the hit, w iso index
//   normal    xyz unit world normal facing the viewer, w gradient magnitude (scalar / world unit)
//   extra     x window depth, y ambient accessibility (1: open), z distance along the ray
@group(0) @binding(8) var g_position: texture_storage_2d_array<rgba32float, write>;
@group(0) @binding(9) var g_normal: texture_storage_2d_array<rgba32float, write>;
@group(0) @binding(10) var g_extra: texture_storage_2d_array<rgba32float, write>;
// A nearest-neighbour sampler (the renderer's): texels are fetched through it at their
// centres, exactly, which is faster than textureLoad on lavapipe.
@group(0) @binding(11) var texel_sampler: sampler;
// A binary mask (Renderer::set_mask): samples whose nearest point holds 0 are left out, as
// cropped ones are (MASK_BINARY; label maps do not change isosurfaces, as in VTK).
@group(0) @binding(12) var mask_tex: texture_3d<u32>;
override MASK: u32 = MASK_NONE;

fn point_at(ray: Ray, t: f32) -> vec3<f32> {
    return ray.index_origin + t * ray.index_dir;
}

fn texel_scalar(c: vec3<i32>) -> f32 {
    let tc = (vec3<f32>(c) + 0.5) * pool.inv_size.xyz;
    return textureSampleLevel(volume_tex, texel_sampler, tc, 0.0)[ISO_COMP];
}

// Where p falls in its brick's slot of the pool: the cell's first texel (clamped so the
// cell lies inside) and the fraction within it; outside the slot the nearest edge (as a
// clamping sampler reads it).
struct Cell {
    i0: vec3<i32>,
    f: vec3<f32>,
    lo: vec3<i32>,
    hi: vec3<i32>,
}

fn cell_at(p: vec3<f32>) -> Cell {
    var c: Cell;
    let q = locate(p);
    c.lo = vec3<i32>(brick.slot_lo);
    c.hi = vec3<i32>(brick.slot_hi);
    let t = clamp(q * brick.inv_scale - brick.tex_lo, brick.slot_lo, brick.slot_hi);
    c.i0 = clamp(vec3<i32>(floor(t)), c.lo, max(c.hi - 1, c.lo));
    c.f = t - vec3<f32>(c.i0);
    return c;
}

// Texel (clamped to the slot) at offset o from the cell's first texel.
fn cell_texel(c: Cell, o: vec3<i32>) -> f32 {
    return texel_scalar(clamp(c.i0 + o, c.lo, c.hi));
}

// Component ISO_COMP at index-space point p, interpolated trilinearly in f32 from the texels
// themselves: a sampler's filter weights carry only a few bits of sub-texel precision
// (8 on lavapipe, 1/256 of a voxel), far coarser than the hits are placed.
fn exact_scalar(p: vec3<f32>) -> f32 {
    let c = cell_at(p);
    let f = c.f;
    let x00 = mix(cell_texel(c, vec3<i32>(0, 0, 0)), cell_texel(c, vec3<i32>(1, 0, 0)), f.x);
    let x10 = mix(cell_texel(c, vec3<i32>(0, 1, 0)), cell_texel(c, vec3<i32>(1, 1, 0)), f.x);
    let x01 = mix(cell_texel(c, vec3<i32>(0, 0, 1)), cell_texel(c, vec3<i32>(1, 0, 1)), f.x);
    let x11 = mix(cell_texel(c, vec3<i32>(0, 1, 1)), cell_texel(c, vec3<i32>(1, 1, 1)), f.x);
    var v = mix(mix(x00, x10, f.y), mix(x01, x11, f.y), f.z);
    if (!SINGLE_BRICK && brick.empty) {
        v = brick.constant[ISO_COMP];
    }
    return v * frame.scalar_scale[ISO_COMP] + frame.scalar_shift[ISO_COMP];
}

// Index-space gradient at p: central differences, one voxel each way along each axis, of
// the field interpolated exactly as exact_scalar does. The six points share the cell of
// p, so the differences need 32 texels, not 48: per axis, the cell's two texel planes
// across that axis and one more plane on each side.
fn exact_gradient(p: vec3<f32>) -> vec3<f32> {
    let c = cell_at(p);
    let f = c.f;
    var g = vec3<f32>(0.0);
    for (var v = 0; v < 4; v = v + 1) {
        // the four lines of the cell along each axis: offsets (a, b) across it
        let a = v & 1;
        let b = v >> 1u;
        // weights of the line among the four (bilinear across the axis)
        let wx = select(1.0 - f.y, f.y, a == 1) * select(1.0 - f.z, f.z, b == 1);
        let wy = select(1.0 - f.x, f.x, a == 1) * select(1.0 - f.z, f.z, b == 1);
        let wz = select(1.0 - f.x, f.x, a == 1) * select(1.0 - f.y, f.y, b == 1);
        let x0 = cell_texel(c, vec3<i32>(0, a, b));
        let x1 = cell_texel(c, vec3<i32>(1, a, b));
        let y0 = cell_texel(c, vec3<i32>(a, 0, b));
        let y1 = cell_texel(c, vec3<i32>(a, 1, b));
        let z0 = cell_texel(c, vec3<i32>(a, b, 0));
        let z1 = cell_texel(c, vec3<i32>(a, b, 1));
        // f(p + e) − f(p − e) along a line: mix(t[1], t[2], f) − mix(t[−1], t[0], f)
        g.x = g.x + wx * (mix(x1, cell_texel(c, vec3<i32>(2, a, b)), f.x) - mix(cell_texel(c, vec3<i32>(-1, a, b)), x0, f.x));
        g.y = g.y + wy * (mix(y1, cell_texel(c, vec3<i32>(a, 2, b)), f.y) - mix(cell_texel(c, vec3<i32>(a, -1, b)), y0, f.y));
        g.z = g.z + wz * (mix(z1, cell_texel(c, vec3<i32>(a, b, 2)), f.z) - mix(cell_texel(c, vec3<i32>(a, b, -1)), z0, f.z));
    }
    if (!SINGLE_BRICK && brick.empty) {
        g = vec3<f32>(0.0);
    }
    // (per pool texel: a coarser level's stand-in spans 1 / inv_scale index units)
    return 0.5 * frame.scalar_scale[ISO_COMP] * brick.inv_scale * g;
}

// The field the surfaces are of at p, and its index-space gradient: the exact trilinear
// ones, or with CUBIC the cubic B-spline's value and its central differences one voxel each
// way (each sample making its own brick current).
fn surface_scalar(p: vec3<f32>) -> f32 {
    if (CUBIC) {
        return sample_scalars(p)[ISO_COMP];
    }
    return exact_scalar(grid_point(p));
}

fn surface_gradient(p: vec3<f32>) -> vec3<f32> {
    if (!CUBIC) {
        // (on a rectilinear grid: the grid's gradient by the rate its index space changes
        // along the lattice's)
        let q = grid_point(p);
        return exact_gradient(q) * index_slope;
    }
    var g = vec3<f32>(0.0);
    for (var a = 0; a < 3; a = a + 1) {
        var e = vec3<f32>(0.0);
        e[a] = 1.0;
        g[a] = 0.5 * (sample_scalars(p + e)[ISO_COMP] - sample_scalars(p - e)[ISO_COMP]);
    }
    return g;
}

// The distance in [t0, t1] where the field crosses v, `below` telling whether it is below v
// at t0: interval bisection through the sampler (iso.counts.y halvings, one fetch each),
// then the crossing of the line through the exactly interpolated values at the final
// bracket's ends. The sampler's coarse filter weights can put that bracket a fraction of
// its width off the exact crossing; the line then extends a little beyond it, which for
// a bracket of 1/256 voxel costs nothing measurable.
fn refine(ray: Ray, t0: f32, t1: f32, v: f32, below: bool) -> f32 {
    var a = t0;
    var b = t1;
    for (var i = 0u; i < iso.counts.y; i = i + 1u) {
        let m = 0.5 * (a + b);
        if ((sample_scalars(grid_point(point_at(ray, m)))[ISO_COMP] < v) == below) {
            a = m;
        } else {
            b = m;
        }
    }
    let fa = surface_scalar(point_at(ray, a)) - v;
    let fb = surface_scalar(point_at(ray, b)) - v;
    if (fa != fb) {
        return clamp(a + fa / (fa - fb) * (b - a), t0, t1);
    }
    return 0.5 * (a + b);
}

// Ambient accessibility at index-space point p with world normal n: the fraction of
// iso.counts.w directions (Hammersley, uniform over the hemisphere around n) whose short
// ray (iso.options.x steps over iso.ao.x world units) never reaches the other side of
// iso-value v. A ray that leaves the volume counts as open; masked samples (MASK_BINARY)
// are left out, as the surfaces leave them out, so a masked region occludes nothing.
fn ambient_access(p: vec3<f32>, n: vec3<f32>, v: f32, front_below: bool) -> f32 {
    let count = iso.counts.w;
    if (count == 0u) {
        return 1.0;
    }
    let steps = max(iso.options.x, 1u);
    let frame_n = basis_around(n);
    let lo = vec3<f32>(0.0);
    let hi = frame.dims.xyz - 1.0;
    let step_len = iso.ao.x / f32(steps);
    var open = 0u;
    for (var i = 0u; i < count; i = i + 1u) {
        let d = frame_n * uniform_hemisphere(hammersley(i, count));
        let step = (frame.world_to_index * vec4<f32>(d, 0.0)).xyz * step_len;
        var hit = false;
        for (var j = 1u; j <= steps; j = j + 1u) {
            let q = p + f32(j) * step;
            if (any(q < lo) || any(q > hi)) {
                break;
            }
            let g = grid_point(q);
            if ((MASK == MASK_BINARY && mask_value(mask_tex, g) == 0u) || blanked(g)) {
                continue;
            }
            if ((sample_scalars(g)[ISO_COMP] < v) != front_below) {
                hit = true;
                break;
            }
        }
        if (!hit) {
            open = open + 1u;
        }
    }
    return f32(open) / f32(count);
}

// Writes G-buffer layer `layer` for the hit of iso-value `which` at distance t.
fn write_hit(px: vec2<u32>, layer: u32, ray: Ray, t: f32, which: u32, below: bool) {
    let p = point_at(ray, t);
    let gw = (frame.gradient_to_world * vec4<f32>(surface_gradient(p), 0.0)).xyz;
    let glen = length(gw);
    // The normal faces the side the ray came from: against the gradient when the field
    // rises along the ray.
    var n = -ray.dir;
    if (glen > 0.0) {
        n = select(gw, -gw, below) / glen;
    }
    let ao = ambient_access(p, n, iso_value(which), below);
    let c = vec2<i32>(px);
    let l = i32(layer);
    textureStore(g_position, c, l, vec4<f32>(ray.origin + t * ray.dir, f32(which)));
    textureStore(g_normal, c, l, vec4<f32>(n, glen));
    textureStore(g_extra, c, l, vec4<f32>(distance_to_depth(ray, t), ao, t, 0.0));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    frame = frame_ubo;
    enter_volume();
    iso = iso_ubo;
    let px = gid.xy + frame.rect.xy;
    if (px.x >= frame.rect.z || px.y >= frame.rect.w) {
        return;
    }
    let pix = px.y * frame.width + px.x;
    var st: PixelState;
    if (STREAMING) {
        st = state[pix];
        if (st.color.w < 0.0) {
            return;
        }
        locate_slack = 1.0;
    }
    var layers = u32(st.color.x);
    var alpha = st.color.y;
    let max_layers = iso.counts.z;
    let ert = frame.termination;
    if (max_layers == 0u || ert <= 0.0) {
        state[pix] = st;
        return;
    }
    let ray = make_ray(px);
    let seg = ray_segment(ray, px);
    // (written so that NaN from a degenerate ray also leaves)
    if (!(seg.x < seg.y)) {
        st.color.w = -1.0;
        state[pix] = st;
        return;
    }
    let dt = frame.sample_distance;
    var jit = 0.0;
    if (has_flag(FLAG_JITTER)) {
        jit = hash01(pix ^ frame.jitter_seed);
    }
    // Lattice sample k lies at lattice + (k + jit) dt: from the segment's start, or for a
    // piece of a whole volume (FLAG_PIECE) on the whole's lattice, so that a piece samples
    // where the whole ray would (the segment's ends, the faces pieces share, are sampled
    // besides).
    var lattice = seg.x;
    if (has_flag(FLAG_PIECE)) {
        lattice = whole_lattice_from(whole_interval(ray).x, seg.x, dt, jit);
    }
    var k = 0.0;
    // Bounded below 2^24 so that k + 1 is always exact and the loop always ends.
    let k_end = min(ceil((seg.y - lattice) / dt - jit), 1.0e7);
    // The segment's end is sampled too, so a crossing between the last lattice sample and
    // the end is found.
    var tail = true;
    let n_iso = min(iso.counts.x, MAX_ISO);
    // The previous sample: a crossing lies between it and the current one. Taken afresh
    // one lattice step back (or at the segment's start) at the ray's start and after every
    // skip.
    var have_prev = false;
    var t_prev = 0.0;
    var s_prev = 0.0;
    // Masked (MASK_BINARY) or blanked samples lie between the previous sample and the
    // current one (a crossing then lies at the current sample, where they end).
    var gap = false;
    if (STREAMING && st.color.w > 0.0) {
        k = st.color.z;
        have_prev = st.value.x > 0.0;
        t_prev = st.value.y;
        s_prev = st.value.z;
        tail = (u32(st.value.w) & 1u) != 0u;
        gap = (u32(st.value.w) & 2u) != 0u;
    }
    var suspended = false;
    var done = false;
    // The last sample taken (t, s at p), and whether the march still has to step past it
    // (it has once the sample was compared, or its crossing handled).
    var t = 0.0;
    var s = 0.0;
    var p = vec3<f32>(0.0);
    var skip_after = false;
    // SKIP: the occupancy texel of the block holding p
    var occ = 0u;
    var advance = false;
    // Lavapipe runs the body of every branch for all lanes whenever it runs the code around
    // it, so the surface work (bisection, exact gradient, occlusion, G-buffer writes) stays
    // out of the sample loop: the inner loop only marches, one volume fetch per pass, until
    // the lane's next crossing or the end of its segment; the outer loop handles that
    // crossing once and marches on.
    loop {
        if (done) {
            break;
        }
        var found = false;
        var crossed = 0u;
        loop {
            if (advance) {
                advance = false;
                gap = false;
                have_prev = true;
                t_prev = t;
                s_prev = s;
                if (skip_after) {
                    have_prev = false;
                    k = max(k + 1.0, ceil((leap_exit(ray, p, occ >> 8u) - lattice) / dt - jit));
                } else {
                    k = k + 1.0;
                }
            }
            var k_here = k;
            var at_tail = false;
            if (k < k_end) {
                t = lattice + (k + jit) * dt;
            } else if (tail) {
                tail = false;
                at_tail = true;
                t = seg.y;
                k_here = k_end;
                if (have_prev && t <= t_prev) {
                    break;
                }
            } else {
                break;
            }
            p = point_at(ray, t);
            skip_after = false;
            if (SKIP && k_here < k_end) {
                occ = block_texel(p);
            }
            if (SKIP && k_here < k_end && (occ & 0xffu) == 0u) {
                if (!have_prev) {
                    k = max(k + 1.0, ceil((leap_exit(ray, p, occ >> 8u) - lattice) / dt - jit));
                    continue;
                }
                // The interval from the last sample into this empty block is still checked.
                skip_after = true;
            }
            if (CROP && !in_crop(p)) {
                have_prev = false;
                k = k + 1.0;
                continue;
            }
            let gp = grid_point(p);
            if ((MASK == MASK_BINARY && mask_value(mask_tex, gp) == 0u) || blanked(gp)) {
                // As VTK 9.2: a masked or blanked sample is skipped and the ray's state
                // carries over it; a ray whose samples start masked starts below every
                // iso-value.
                if (!have_prev) {
                    have_prev = true;
                    t_prev = t;
                    s_prev = -3.4e38;
                }
                gap = true;
                k = k + 1.0;
                continue;
            }
            // One fetch per pass: without a previous sample, this pass takes it (one
            // lattice step back) and the next pass comes back to t.
            let t_back = max(seg.x, lattice + (k_here - 1.0 + jit) * dt);
            let take_prev = !have_prev;
            let t_q = select(t, t_back, take_prev);
            if (STREAMING && waits(point_at(ray, t_q), ray.index_dir)) {
                suspended = true;
                tail = tail || at_tail;
                break;
            }
            let s_q = sample_scalars(grid_point(point_at(ray, t_q)))[ISO_COMP];
            if (take_prev) {
                t_prev = t_q;
                s_prev = s_q;
                have_prev = true;
                tail = tail || at_tail;
                continue;
            }
            s = s_q;
            crossed = 0u;
            for (var i = 0u; i < n_iso; i = i + 1u) {
                let v = iso_value(i);
                if ((s_prev < v) != (s < v)) {
                    crossed = crossed | (1u << i);
                }
            }
            advance = true;
            if (crossed != 0u && t > t_prev) {
                found = true;
                break;
            }
        }
        if (!found) {
            break;
        }
        var th: array<f32, MAX_ISO>;
        for (var i = 0u; i < n_iso; i = i + 1u) {
            if ((crossed & (1u << i)) != 0u) {
                th[i] = select(refine(ray, t_prev, t, iso_value(i), s_prev < iso_value(i)), t, gap);
            }
        }
        // Several iso-values crossed between two samples: emit them nearest first.
        loop {
            if (crossed == 0u || done) {
                break;
            }
            let which = nearest_crossing(crossed, th);
            crossed = crossed & ~(1u << which);
            write_hit(px, layers, ray, th[which], which, s_prev < iso_value(which));
            layers = layers + 1u;
            alpha = alpha + (1.0 - alpha) * iso.colors[which].a;
            done = layers >= max_layers || alpha >= ert;
        }
    }
    st.color.x = f32(layers);
    st.color.y = alpha;
    if (STREAMING) {
        st.color.z = k;
        st.color.w = select(-1.0, 1.0, suspended);
        st.value = vec4<f32>(select(0.0, 1.0, have_prev), t_prev, s_prev,
                             select(0.0, 1.0, tail) + select(0.0, 2.0, gap));
    }
    state[pix] = st;
}
