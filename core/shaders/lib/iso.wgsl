// The isosurface uniforms shared by the first-hit pass (firsthit.wgsl) and deferred shading
// (deferred.wgsl). Mirrored in core/src/gpu/uniforms.rs (IsoUniforms); a unit test checks the
// layouts. MAX_ISO, SPECULAR_CONE / SPECULAR_IMPORTANCE and ISO_FLAG_BACKGROUND (the
// environment fills the pixels the surfaces leave uncovered) are declared from Rust.

struct Iso {
    env_rotation: mat4x4<f32>,    // world direction → environment direction (+Y up)
    values: array<vec4<f32>, 2>,  // the iso-values, four per vec4
    colors: array<vec4<f32>, 8>,  // per iso-value: rgb, opacity
    shininess: vec4<f32>,         // |∇| at the low end, 1 / |∇| range, exponent low, exponent high
    ao: vec4<f32>,                // x: occlusion ray length (world units)
    env: vec4<f32>,               // x: environment light weight; y: Schlick F0 (< 0: no
                                  // Fresnel); z: solid angle of a level-0 cube texel; w: last mip
    counts: vec4<u32>,            // iso-values, bisection steps, max layers, AO directions
    options: vec4<u32>,           // AO steps, specular samples, specular mode, flags
    shade_rect: vec4<u32>,        // pixels the deferred pass covers: x0, y0, x1, y1
    scatter: vec4<f32>,           // scattering between the surfaces: x absorption scale / unit
                                  // distance, y traced directions, z Fresnel F0
}

@group(0) @binding(SLOT_ISO) var<uniform> iso_ubo: Iso;
// A private copy filled by each entry point (`iso = iso_ubo;`), as lib/common.wgsl's
// `frame`.
var<private> iso: Iso;

fn iso_value(i: u32) -> f32 {
    return iso.values[i / 4u][i % 4u];
}

// Of the iso-values whose bits `crossed` holds (crossed at distances th), the nearest.
fn nearest_crossing(crossed: u32, th: array<f32, MAX_ISO>) -> u32 {
    var t = th;
    var which = 0u;
    var best = 3.4e38;
    for (var i = 0u; i < MAX_ISO; i = i + 1u) {
        if ((crossed & (1u << i)) != 0u && t[i] < best) {
            best = t[i];
            which = i;
        }
    }
    return which;
}
