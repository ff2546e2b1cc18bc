// Turning a ray's final state into the output pixel: premultiplied RGBA and a window
// depth. For the projection modes (maximum, minimum, average, additive) the transfer
// function is applied here, once, to the value the ray found (shaders/dvr.wgsl).
#include "lib/common.wgsl"

@group(0) @binding(SLOT_OUT_COLOR) var out_color: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(SLOT_OUT_DEPTH) var out_depth: texture_storage_2d<r32float, write>;

// Premultiplied colour of a projected value (maximum, minimum): the transfer function
// applied to the value found, un-corrected opacity; dependent components as in composite
// (2: colour table on the first, opacity on the second; 4: the data's RGB, opacity on the
// fourth); independent components mixed as VTK does (colour and opacity summed, weighted).
fn classify_value(v: vec4<f32>) -> vec4<f32> {
    let ncomp = frame.components;
    if (!has_flag(FLAG_INDEPENDENT)) {
        let oc = ncomp - 1u;
        let a = raw_alpha(0u, v[oc]);
        var rgb = classify(0u, v.x).rgb;
        if (ncomp == 4u) {
            // the data's RGB as the texture holds it (sample_scalars' scale undone)
            let texel = (v - frame.scalar_shift) / frame.scalar_scale;
            rgb = clamp(texel.rgb, vec3<f32>(0.0), vec3<f32>(1.0));
        }
        return vec4<f32>(rgb * a, a);
    }
    var out = vec4<f32>(0.0);
    for (var c = 0u; c < ncomp; c = c + 1u) {
        let e = classify(c, v[c]);
        let a = raw_alpha(c, v[c]) * frame.weights[c];
        out = out + vec4<f32>(e.rgb * a, a);
    }
    return out;
}

// FLAG_PIECE (set by the ray caster): the whole volume's ray takes this many samples, and
// whether it leaves the whole volume in this piece.
var<private> piece_samples: f32 = 0.0;
var<private> piece_last: bool = true;

// Whether this piece's pixel closes an additive or average sum (the whole ray has samples
// and leaves the whole volume here), with samples of its own or not.
fn closes_sum(blend: u32) -> bool {
    return has_flag(FLAG_PIECE) && piece_last && piece_samples > 0.0 &&
        (blend == BLEND_AVERAGE || blend == BLEND_ADDITIVE);
}

fn write_pixel(px: vec2<u32>, st: PixelState) {
    let blend = frame.blend;
    var color = vec4<f32>(0.0);
    var depth = 1.0;
    if (blend == BLEND_COMPOSITE || blend == BLEND_SLICE) {
        color = st.color;
        if (st.misc.z > 0.0) {
            depth = st.misc.y;
        }
    } else if (st.misc.x > 0.0 || closes_sum(blend)) {
        if (blend == BLEND_AVERAGE || blend == BLEND_ADDITIVE) {
            // VTK: a grey level, opaque, from the opacity-weighted normalised scalars. A
            // piece's is opaque where the ray leaves the whole; in the pieces before, the
            // average's share of the whole ray, nearly transparent (alpha 1/255, not 0,
            // which IceT takes for an empty pixel), which compositing "over" adds to the
            // rest (the shares add up to at most 1), and the additive sum g with alpha g:
            // "over" then gives 1 − Π(1 − g), the sum where it is small and 1 where any
            // piece's is, never more than 1 (IceT's 8-bit "over" does not clamp).
            var v = st.value;
            if (blend == BLEND_AVERAGE) {
                v = v / select(st.misc.x, max(piece_samples, 1.0), has_flag(FLAG_PIECE));
            }
            var g = v.x;
            if (has_flag(FLAG_INDEPENDENT)) {
                g = dot(v, frame.weights * vec4<f32>(vec4<u32>(0u, 1u, 2u, 3u) < vec4<u32>(frame.components)));
            }
            let grey = clamp(g, 0.0, 1.0);
            var alpha = 1.0;
            if (has_flag(FLAG_PIECE) && !piece_last) {
                alpha = select(1.0 / 255.0, grey, blend == BLEND_ADDITIVE);
            }
            color = vec4<f32>(vec3<f32>(grey), alpha);
        } else {
            color = classify_value(st.value);
            if (has_flag(FLAG_EXTREMUM_DEPTH)) {
                // (dependent components: their extremum is the opacity component's)
                let key = select(0u, frame.components - 1u, !has_flag(FLAG_INDEPENDENT));
                let u = clamp(scalar_coord(0u, st.value[key]), 0.0, 1.0);
                depth = 0.5 * select(u, 1.0 - u, blend == BLEND_MAXIMUM);
            }
        }
    }
    textureStore(out_color, vec2<i32>(px), clamp(color, vec4<f32>(0.0), vec4<f32>(1.0)));
    textureStore(out_depth, vec2<i32>(px), vec4<f32>(depth, 0.0, 0.0, 0.0));
}
