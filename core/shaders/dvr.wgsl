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
#include "lib/output.wgsl"

// Pipeline constants: each combination is its own pipeline, so the ray loop carries only
// the code of the mode it runs (core/src/passes/dvr.rs, DvrVariant).
override BLEND: u32 = 0u;
override INDEPENDENT: bool = true;
override SHADE: bool = false;
override GRAD_OPACITY: bool = false;
override SKIP: bool = false;
// MIP and MinIP (one component): skip blocks whose scalar range cannot move the ray's
// extremum, i.e. the block's max ≤ the running max (MIP), its min ≥ the running min (MinIP).
// Such a block's samples leave the value unchanged, so the image is the same as without
// (exactly so in real arithmetic; a filtered f32 sample may round an ulp past its corners).
override RANGE_SKIP: bool = false;
override CROP: bool = false;
// Volumetric shadows (lib/shadow.wgsl; one component, shading on).
override VOLUMETRIC: bool = false;
// VTK's ComputeNormalFromOpacity (independent components): shading normals from the gradient
// of each component's step-corrected opacity, gradient opacity included, instead of the
// scalar's. The scalar gradient still drives gradient opacity at the sample.
override OPACITY_NORMAL: bool = false;
// A streamed frame (its bricks exceed the memory budget): several passes, each with a group
// of bricks resident, front to back. A ray marches until its next sample's brick waits for
// a later pass (PAGE_MISSING), keeps its state in `state` and resumes there; misc.w holds
// the next sample's index, or −1 once the pixel is written.
override STREAMING: bool = false;
// Pre-integrated classification (RenderParams::preintegration; composite, one or independent
// components): each sample classifies the ray segment from the previous lattice point, the
// scalar taken to run linearly between them, from the pre-integration tables; shading and
// gradient opacity stay the sample's own (the back of the segment).
override PREINT: bool = false;
// Quadrature::Midpoint: samples in the middle of their steps, the ray ending exactly where
// it leaves the volume, opaque depth or a clipping plane (its last part, shorter than a
// step, sampled after the loop at its middle).
override MIDPOINT: bool = false;
// Quadrature::Adaptive, unshaded composite (with MIDPOINT): a step per block (its occupancy
// value).
override ADAPTIVE: bool = false;

@group(0) @binding(7) var<storage, read_write> state: array<PixelState>;
// FLAG_DEPTH_RANGE: the window depth where each pixel's ray starts (depth_in: where it ends).
@group(0) @binding(25) var depth_near: texture_2d<f32>;

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


// A mask (Renderer::set_mask), one value per point of the grid: MASK_BINARY leaves out the
// samples whose nearest point holds 0, MASK_LABELS classifies samples by their nearest
// point's label (classify_labelled); the blanking mask's placeholder otherwise.
@group(0) @binding(10) var mask_tex: texture_3d<u32>;
override MASK: u32 = MASK_NONE;

fn mask_at(p: vec3<f32>) -> u32 {
    return mask_value(mask_tex, p);
}

// Whether the sample at index-space point p is left out by blanking or a binary mask.
fn left_out(p: vec3<f32>) -> bool {
    return blanked(p) || (MASK == MASK_BINARY && mask_at(p) == 0u);
}



// Per component c, rows c·TABLE_N + f: for a segment whose front scalar is at table entry f
// and whose back scalar is at entry b (column), the premultiplied colour and opacity it adds
// at this step (core/src/params/transfer.rs, build_preintegration).
@group(0) @binding(9) var preint_tables: texture_2d<f32>;

// The pre-integration table of component c at front scalar sf and back scalar sb, clamped to
// the table's range as `classify` is, read with the volume's sampler: bilinear, or nearest
// with NEAREST (whose pipelines bind the nearest sampler).
fn preintegrated(c: u32, sf: f32, sb: f32) -> vec4<f32> {
    let n = f32(TABLE_N);
    let x = clamp(scalar_coord(c, sb), 0.0, 1.0) * (n - 1.0) + 0.5;
    let y = clamp(scalar_coord(c, sf), 0.0, 1.0) * (n - 1.0) + 0.5 + f32(c) * n;
    return textureSampleLevel(preint_tables, volume_sampler, vec2<f32>(x / n, y / (n * f32(NCOMP))), 0.0);
}

// Colour (not premultiplied) and step-corrected opacity of component c for the segment
// from the previous sample (scalar sf) to this one (scalar s): pre-integrated with PREINT,
// else the sample's own classification.
fn classify_segment(c: u32, sf: f32, s: f32) -> vec4<f32> {
    if (!PREINT) {
        return classify(c, s);
    }
    let e = preintegrated(c, sf, s);
    if (e.a <= 0.0) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(e.rgb / e.a, e.a);
}

// PREINT: the scalars at the previous lattice point q, for a sample whose previous one was
// not taken (the ray's first, or one after skipped, cropped or blanked samples); the
// sample's own scalars s where q's brick is not resident (its constant is not the data).
fn front_scalars(q: vec3<f32>, s: vec4<f32>) -> vec4<f32> {
    let v = sample_scalars(q);
    if (!SINGLE_BRICK && (brick.empty || brick.missing)) {
        return s;
    }
    return v;
}


// Per min–max block, the first component's (min, max) over every point a sample in the
// block interpolates from (nearest or trilinear), widened where the storage rounds the data
// (MinMaxGrid::sample_bounds). Built once per volume upload; read by RANGE_SKIP only.
@group(0) @binding(2) var block_range: texture_3d<f32>;

// Whether the samples of the block holding p cannot change the extremum v (MIP: none can
// exceed it; MinIP: none can fall below it); a tie leaves max/min unchanged too.
fn block_keeps_extremum(p: vec3<f32>, v: f32) -> bool {
    let r = textureLoad(block_range, block_coord(p), 0).xy;
    if (BLEND == BLEND_MAXIMUM) {
        return r.y <= v;
    }
    return r.x >= v;
}

// Step-corrected opacity of every component at pool texture coordinate tc (index-space
// point q), times gradient opacity when it is on (VTK's opacity of a neighbour in
// ComputeNormalFromOpacity).
fn opacities_at(tc: vec3<f32>, q: vec3<f32>) -> vec4<f32> {
    let s = scalars_at(tc);
    var g: Gradient;
    if (GRAD_OPACITY) {
        g = gradient_tc(tc, q, s);
    }
    var a = vec4<f32>(0.0);
    for (var c = 0u; c < NCOMP; c = c + 1u) {
        a[c] = classify(c, s[c]).a;
        if (GRAD_OPACITY) {
            a[c] = a[c] * gradient_opacity(c, length(world_gradient(g, c)));
        }
    }
    return a;
}

// Index-space gradient of every component's opacity at p: central differences over the six
// neighbours one voxel away, as VTK's computeDensityGradient (zero in a non-resident
// brick). With gradient opacity the neighbours' own gradients reach two voxels from p,
// beyond a brick's apron: the pass takes this only for a volume of one brick.
fn opacity_gradient_at(p: vec3<f32>) -> Gradient {
    let tc = pool_coord(p);
    var g: Gradient;
    if (!SINGLE_BRICK && brick.empty) {
        return g;
    }
    let dx = vec3<f32>(pool.inv_size.x, 0.0, 0.0);
    let dy = vec3<f32>(0.0, pool.inv_size.y, 0.0);
    let dz = vec3<f32>(0.0, 0.0, pool.inv_size.z);
    let ex = vec3<f32>(1.0, 0.0, 0.0);
    let ey = vec3<f32>(0.0, 1.0, 0.0);
    let ez = vec3<f32>(0.0, 0.0, 1.0);
    g.x = 0.5 * (opacities_at(tc + dx, p + ex) - opacities_at(tc - dx, p - ex));
    g.y = 0.5 * (opacities_at(tc + dy, p + ey) - opacities_at(tc - dy, p - ey));
    g.z = 0.5 * (opacities_at(tc + dz, p + ez) - opacities_at(tc - dz, p - ez));
    return g;
}

// The gradient whose direction shades a sample at p: the opacity's (OPACITY_NORMAL) or the
// scalar's, g.
fn shading_gradient(p: vec3<f32>, g: Gradient) -> Gradient {
    if (OPACITY_NORMAL) {
        return opacity_gradient_at(p);
    }
    return g;
}

// classify_sample of a one-component volume by its transfer function.
fn classify_one(sf: vec4<f32>, s: vec4<f32>, p: vec3<f32>, pos: vec3<f32>, view_dir: vec3<f32>) -> vec4<f32> {
    var e: vec4<f32>;
    var gs: Gradient;
    if (has_2d(0u)) {
        gs = gradient_at(p, s);
        e = table_2d(0u, s.x, length(world_gradient(gs, 0u)));
    } else {
        e = classify_segment(0u, sf.x, s.x);
    }
    if (e.a <= 0.0 || frame.weights.x <= 0.0) {
        return vec4<f32>(0.0);
    }
    if (SHADE || GRAD_OPACITY) {
        if (!has_2d(0u)) {
            gs = gradient_at(p, s);
        }
        let g = world_gradient(gs, 0u);
        let a = e.a;
        // (a 2D table replaces gradient opacity, as VTK 9.2 draws TF_2D)
        if (GRAD_OPACITY && !has_2d(0u)) {
            e.a = e.a * gradient_opacity(0u, length(g));
        }
        if (SHADE) {
            let n = world_gradient(shading_gradient(p, gs), 0u);
            var rgb = shade(e.rgb, n, pos, view_dir);
            if (VOLUMETRIC) {
                let gm = vtk_gradient_magnitude(n, OPACITY_NORMAL);
                rgb = volumetric_shade(e.rgb, a, gm, rgb, p, pos, view_dir, GRAD_OPACITY);
            }
            e = vec4<f32>(rgb, e.a);
        }
    }
    return e;
}

// MASK_LABELS: a one-component sample labelled l (1 to frame.mask.y) classified as VTK's
// label maps do: its label's colour and step-corrected opacity at the scalar, lit and
// times its label's gradient opacity where that opacity is above 0, mixed with the
// transfer function's classification (classify_one) by the blend factor frame.mask.x,
// colour and opacity alike.
fn classify_labelled(l: u32, s: vec4<f32>, p: vec3<f32>, pos: vec3<f32>, view_dir: vec3<f32>) -> vec4<f32> {
    let row = label_row(NCOMP, l);
    var e = table_lookup(row, 0u, label_coord(s.x));
    if (e.a > 0.0 && (SHADE || GRAD_OPACITY)) {
        let g = world_gradient(gradient_at(p, s), 0u);
        if (GRAD_OPACITY) {
            e.a = e.a * table_lookup(row, 1u, (length(g) - frame.labels.z) * frame.labels.w).y;
        }
        if (SHADE) {
            e = vec4<f32>(shade(e.rgb, g, pos, view_dir), e.a);
        }
    }
    let b = frame.mask.x;
    if (b >= 1.0) {
        return e;
    }
    return mix(classify_one(s, s, p, pos, view_dir), e, b);
}

// Colour (rgb, not premultiplied) and opacity corrected for the step of one composite sample
// (scalars s; sf: the previous sample's, which PREINT classifies the segment from).
fn classify_sample(sf: vec4<f32>, s: vec4<f32>, p: vec3<f32>, pos: vec3<f32>, view_dir: vec3<f32>) -> vec4<f32> {
    let ncomp = NCOMP;
    let need_grad = SHADE || GRAD_OPACITY;
    if (!INDEPENDENT) {
        // Dependent components: 2 = (colour scalar, opacity scalar); 4 = RGB + opacity scalar.
        let oc = ncomp - 1u;
        var a = classify(0u, s[oc]).a;
        if (a <= 0.0) {
            return vec4<f32>(0.0);
        }
        var rgb = classify(0u, s.x).rgb;
        if (ncomp == 4u) {
            rgb = clamp(sample_texel(p).rgb, vec3<f32>(0.0), vec3<f32>(1.0));
        }
        if (need_grad) {
            let g = world_gradient(gradient_at(p, s), oc);
            if (GRAD_OPACITY) {
                a = a * gradient_opacity(0u, length(g));
            }
            if (SHADE) {
                rgb = shade(rgb, g, pos, view_dir);
            }
        }
        return vec4<f32>(rgb, a);
    }
    if (NCOMP == 1u) {
        if (MASK == MASK_LABELS) {
            let l = mask_at(p);
            if (labelled(l)) {
                return classify_labelled(l, s, p, pos, view_dir);
            }
        }
        return classify_one(sf, s, p, pos, view_dir);
    }
    // Independent components, mixed as VTK does: the premultiplied colours weighted and
    // added (Σ a·w·rgb, which may pass the brightest component's), opacity Σ a² / Σ a·w.
    var entry: array<vec4<f32>, 4>;
    var any = false;
    var g: Gradient;
    if (TF2D != 0u) {
        g = gradient_at(p, s);
    }
    for (var c = 0u; c < ncomp; c = c + 1u) {
        if (has_2d(c)) {
            entry[c] = table_2d(c, s[c], length(world_gradient(g, c)));
        } else {
            entry[c] = classify_segment(c, sf[c], s[c]);
        }
        any = any || entry[c].a * frame.weights[c] > 0.0;
    }
    if (!any) {
        return vec4<f32>(0.0);
    }
    var gn: Gradient;
    if (need_grad) {
        if (TF2D == 0u) {
            g = gradient_at(p, s);
        }
        if (SHADE) {
            gn = shading_gradient(p, g);
        }
    }
    var rgb_sum = vec3<f32>(0.0);
    var a_sq = 0.0;
    var total = 0.0;
    for (var c = 0u; c < ncomp; c = c + 1u) {
        var a = entry[c].a;
        let w = frame.weights[c];
        if (a <= 0.0 || w <= 0.0) {
            continue;
        }
        var rgb = entry[c].rgb;
        if (need_grad) {
            if (GRAD_OPACITY && !has_2d(c)) {
                a = a * gradient_opacity(c, length(world_gradient(g, c)));
            }
            if (SHADE) {
                rgb = shade_material(rgb, world_gradient(gn, c), pos, view_dir,
                                     frame.component_materials[c]);
            }
        }
        rgb_sum = rgb_sum + a * w * rgb;
        a_sq = a_sq + a * a;
        total = total + a * w;
    }
    if (total <= 0.0) {
        return vec4<f32>(0.0);
    }
    // (colour not premultiplied: the compositing multiplies it by the opacity again)
    let alpha = min(a_sq / total, 1.0);
    return vec4<f32>(rgb_sum / alpha, alpha);
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

// The projections (MIP, MinIP, average, additive): the running value and misc.x, the
// samples counted, after a sample of scalars `s` standing for `w` steps (1, or less for a
// midpoint ray's last, shorter step). VTK: the average takes the opacity-weighted
// normalised scalars of the samples inside its range; additive sums the same terms, the
// opacity scaled linearly by step / unit distance.
fn project(value: ptr<function, vec4<f32>>, misc: ptr<function, vec4<f32>>, s: vec4<f32>, w: f32) {
    if (BLEND == BLEND_MAXIMUM || BLEND == BLEND_MINIMUM) {
        *value = extremum(*value, s, (*misc).x == 0.0);
        (*misc).x = (*misc).x + 1.0;
    } else if (BLEND == BLEND_AVERAGE) {
        let r = frame.average_range;
        if (!has_flag(FLAG_AVERAGE_RANGE) || (s.x >= r.x && s.x <= r.y)) {
            *value = *value + w * projection_term(s, vec4<f32>(1.0));
            (*misc).x = (*misc).x + w;
        }
    } else {
        *value = *value + w * projection_term(s, frame.additive_scale);
        (*misc).x = (*misc).x + 1.0;
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
    if (color.a > frame.misc.z) {
        st.misc.y = distance_to_depth(ray, t);
        st.misc.z = 1.0;
    }
    return st;
}

// Composites c (not premultiplied) over the ray's colour, and notes the distance t where
// its opacity first passes the depth threshold (misc.z: passed; turned into a depth after
// the loop).
fn composite_over(
    color: ptr<function, vec4<f32>>,
    misc: ptr<function, vec4<f32>>,
    depth_t: ptr<function, f32>,
    c: vec4<f32>,
    t: f32,
) {
    *color = over(*color, c);
    if ((*misc).z == 0.0 && (*color).a > frame.misc.z) {
        *depth_t = t;
        (*misc).z = 1.0;
    }
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
    let pix = px.y * frame.viewport.x + px.x;
    let blend = BLEND;
    var st: PixelState;
    if (STREAMING) {
        st = state[pix];
        if (st.misc.w < 0.0) {
            return;
        }
        locate_slack = 0.5;
    }
    let ert = frame.misc.y;
    let ray = make_ray(px);
    // The whole ray segment inside the volume, near/far planes, opaque depth and clip planes.
    let dt = frame.misc.x;
    var box = box_interval(ray, vec3<f32>(0.0), frame.dims.xyz - 1.0);
    if (INTERMIX > 0u) {
        box = slab_interval(ray.origin, ray.dir, intermix.box_lo.xyz, intermix.box_hi.xyz);
    }
    var seg = vec2<f32>(max(box.x, 0.0), min(box.y, ray.far));
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
    let cl = clip_interval(ray, vec2<f32>(seg.x, term));
    var first_forced = false;
    var jit = 1.0; // VTK: g_rayOrigin += g_dirStep (no jitter): the first sample one step in
    if (has_flag(FLAG_JITTER)) {
        jit = hash01(pix ^ frame.viewport.w);
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
        if (frame.counts.x > 0u) {
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
        let forced = frame.counts.x == 0u && tg < tge && tg + jit * dt >= tge;
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
    // (written so that NaN from a degenerate ray also leaves)
    if (!(seg.x < seg.y)) {
        if (STREAMING) {
            st.misc.w = -1.0;
            state[pix] = st;
        }
        write_pixel(px, st);
        return;
    }
    var k = 0.0;
    if (STREAMING) {
        k = st.misc.w;
    }
    var suspended = false;
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
    k_end = min(k_end, range_samples);
    var color = st.color;
    var value = st.value;
    var misc = st.misc;
    // Where the opacity first passes the depth threshold, turned into a depth after the
    // loop: lavapipe runs a branch's code for all lanes whenever any lane takes it, and
    // the conversion reads the camera at a dynamic index (lib/ray.wgsl) with a gather per
    // matrix element.
    var depth_t = -1.0;
    // PREINT: the scalars of sample front_k, the last taken (composite keeps them in the
    // ray state's `value`, and front_k + 2 in misc.x: 0 there means none), and whether its
    // block was occupied.
    var front = st.value;
    var front_k = st.misc.x - 2.0;
    var front_occupied = true;
    if (RANGE_SKIP) {
        // MIP / MinIP block by block: an outer loop decides per block, as the ray enters it,
        // whether to skip the block whole or to march all its samples in the inner loop.
        // Not a test inside the sample loop: lavapipe runs a branch's code for all lanes
        // whenever any lane takes it, so a per-sample test costs the lookup every sample.
        // Skipping waits for the ray to hold a value (misc.x counts the samples taken).
        // Samples stay on the lattice: each block's run ends at the first k past its exit,
        // as SKIP's jump does. This loop leaves k at k_end, so the general loop below
        // takes no sample.
        loop {
            if (k >= k_end) {
                break;
            }
            let p0 = ray.index_origin + (seg.x + (k + jit) * dt) * ray.index_dir;
            let next = max(k + 1.0, ceil((block_exit(ray, p0) - seg.x) / dt - jit));
            if (misc.x > 0.0 && block_keeps_extremum(p0, value.x)) {
                k = next;
                continue;
            }
            let stop = min(next, k_end);
            loop {
                if (k >= stop) {
                    break;
                }
                let t = seg.x + (k + jit) * dt;
                let p = ray.index_origin + t * ray.index_dir;
                if ((!CROP || in_crop(p)) && !left_out(p)) {
                    value = extremum(value, sample_scalars(p), misc.x == 0.0);
                    misc.x = misc.x + 1.0;
                }
                k = k + 1.0;
            }
        }
    }
    if (ADAPTIVE) {
        // Quadrature::Adaptive: steps of as many sample distances as the block holding the
        // middle of the step's first sample distance allows, a coarse one ending at the
        // block's exit (never shorter than one), each sampled at its middle, its opacity
        // corrected for its length. One loop, one sample an iteration, the block's exit
        // computed only for coarse steps and skips (nested loops, or work some lanes do
        // and others not, leave lanes idle on lavapipe). The general loop below and the
        // midpoint tail take no sample after it.
        loop {
            if (k >= k_end) {
                break;
            }
            let probe = ray.index_origin + (seg.x + (k + 0.5) * dt) * ray.index_dir;
            let occ = block_texel(probe);
            let m = occ & 0xffu;
            if (SKIP && m == 0u) {
                k = max((leap_exit(ray, probe, occ >> 8u) - seg.x) / dt, k + 0.5);
                continue;
            }
            var k1 = min(k + 1.0, k_end);
            var whole = k1 == k + 1.0;
            var w = 1.0;
            if (m > 1u) {
                let h = f32(m);
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
                suspended = true;
                break;
            }
            let s = sample_scalars(p);
            var c = classify_sample(s, s, p, ray.origin + t * ray.dir, ray.dir);
            if (!whole) {
                c.a = 1.0 - pow(max(1.0 - c.a, 0.0), w);
            } else if (m >= 2u) {
                let q = (1.0 - c.a) * (1.0 - c.a);
                c.a = 1.0 - select(q, q * q, m >= 4u);
            }
            k = k1;
            if (c.a > 0.0) {
                composite_over(&color, &misc, &depth_t, c, t);
                if (color.a >= ert) {
                    break;
                }
            }
        }
    }
    loop {
        if (k >= k_end || ADAPTIVE) {
            break;
        }
        let t = seg.x + (k + jit) * dt;
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
        if (SKIP && !occupied && !(PREINT && front_occupied && front_k == k - 1.0)) {
            let next = max(k + 1.0, ceil((leap_exit(ray, lp, occ >> 8u) - seg.x) / dt - jit));
            if (blend == BLEND_AVERAGE || blend == BLEND_ADDITIVE) {
                // their terms there are 0, but the samples count
                misc.x = misc.x + min(next, k_end) - k;
            }
            k = next;
            continue;
        }
        if ((CROP && !in_crop(lp)) || left_out(p)) {
            k = k + 1.0;
            continue;
        }
        if (STREAMING && waits(p, ray.index_dir)) {
            suspended = true;
            break;
        }
        // (intermixed, the main volume's sample is read only inside its grid)
        let s = sample_scalars(select(p, clamp(p, vec3<f32>(0.0), frame.dims.xyz - 1.0), INTERMIX > 0u));
        if (blend == BLEND_COMPOSITE) {
            var sf = s;
            if (PREINT) {
                sf = front;
                if (front_k != k - 1.0) {
                    sf = front_scalars(grid_point(lp - dt * ray.index_dir), s);
                    _ = grid_point(lp);
                }
                front = s;
                front_k = k;
                front_occupied = occupied;
            }
            let pos = ray.origin + t * ray.dir;
            var c = vec4<f32>(0.0);
            if (INTERMIX == 0u || in_grid(p, frame.dims.xyz)) {
                c = classify_sample(sf, s, p, pos, ray.dir);
            }
            for (var j = 0u; j < INTERMIX; j = j + 1u) {
                color = over(color, c);
                c = intermixed_sample(j, pos, ray.dir);
            }
            if (c.a > 0.0 || INTERMIX > 0u) {
                composite_over(&color, &misc, &depth_t, c, t);
                if (color.a >= ert) {
                    break;
                }
            }
        } else {
            project(&value, &misc, s, 1.0);
        }
        k = k + 1.0;
    }
    // Quadrature::Midpoint: the part of the ray past the last whole step, sampled at its
    // middle, weighted by its length in steps: composite corrects the opacity for it,
    // average and additive weigh their terms (and average its count), MIP and MinIP take
    // the sample as it is.
    if (MIDPOINT && !ADAPTIVE && !suspended && k >= k_end && !(blend == BLEND_COMPOSITE && color.a >= ert)) {
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
            suspended = true; // (resumes here: k stays k_end)
        } else if (occupied) {
            let s = sample_scalars(p);
            if (blend == BLEND_COMPOSITE) {
                var sf = s;
                if (PREINT) {
                    sf = front;
                    if (front_k != k_end - 1.0) {
                        let start = ray.index_origin + (seg.x + k_end * dt) * ray.index_dir;
                        sf = front_scalars(grid_point(start), s);
                        _ = grid_point(lp);
                    }
                }
                var c = classify_sample(sf, s, p, ray.origin + t * ray.dir, ray.dir);
                c.a = 1.0 - pow(max(1.0 - c.a, 0.0), w);
                if (c.a > 0.0) {
                    composite_over(&color, &misc, &depth_t, c, t);
                }
            } else {
                project(&value, &misc, s, w);
            }
        } else if (inside && blend == BLEND_AVERAGE) {
            misc.x = misc.x + w; // (an empty block's samples count, their terms are 0)
        }
    }
    if (depth_t >= 0.0) {
        misc.y = distance_to_depth(ray, depth_t);
    }
    if (PREINT) {
        value = front;
        misc.x = front_k + 2.0;
    }
    st.color = color;
    st.value = value;
    st.misc = misc;
    if (STREAMING) {
        st.misc.w = select(-1.0, k, suspended);
        state[pix] = st;
        if (suspended) {
            return;
        }
    }
    write_pixel(px, st);
}
