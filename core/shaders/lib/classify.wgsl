// A composite sample's colour and opacity (shaders/dvr.wgsl): the transfer functions of one,
// dependent or independent components, a label map, 2D tables, pre-integration of the
// segment from the previous sample, gradient opacity, shading (by the scalar's or the
// opacity's gradient) and volumetric shadows.
#include "lib/common.wgsl"
#include "lib/volume.wgsl"
#include "lib/blanking.wgsl"
#include "lib/table2d.wgsl"
#include "lib/shading.wgsl"
#include "lib/shadow.wgsl"

// Pipeline constants (core/src/passes/dvr_variant.rs, DvrVariant).
// Components classified each by its own function and mixed (VTK's IndependentComponents).
override INDEPENDENT: bool = true;
override SHADE: bool = false;
override GRAD_OPACITY: bool = false;
// Volumetric shadows (lib/shadow.wgsl; one component, shading on).
override VOLUMETRIC: bool = false;
// VTK's ComputeNormalFromOpacity (independent components): shading normals from the gradient
// of each component's step-corrected opacity, gradient opacity included, instead of the
// scalar's. The scalar gradient still drives gradient opacity at the sample.
override OPACITY_NORMAL: bool = false;
// Pre-integrated classification (RenderParams::preintegration; composite, one or independent
// components): each sample classifies the ray segment from the previous lattice point, the
// scalar taken to run linearly between them, from the pre-integration tables; shading and
// gradient opacity stay the sample's own (the back of the segment).
override PREINT: bool = false;

// A mask (Renderer::set_mask), one value per point of the grid: MASK_BINARY leaves out the
// samples whose nearest point holds 0, MASK_LABELS classifies samples by their nearest
// point's label (classify_labelled); the blanking mask's placeholder otherwise.
@group(0) @binding(SLOT_MASK) var mask_tex: texture_3d<u32>;
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
@group(0) @binding(SLOT_PREINT_TABLES) var preint_tables: texture_2d<f32>;

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
