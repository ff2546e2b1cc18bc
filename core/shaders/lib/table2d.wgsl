// 2D transfer functions (vtkVolumeProperty's TF_2D): per component with one (bit c of
// TF2D), rows of colour and opacity over its scalar range (x) and gradient magnitude (y),
// the components' tables stacked (core/src/resources/tables.rs). Ray casting reads the
// opacity per sample, as VTK does; the path tracer as the 1D functions' (per unit
// distance).
#include "lib/common.wgsl"
@group(0) @binding(SLOT_TABLES_2D) var tables_2d: texture_2d<f32>;
override TF2D: u32 = 0u;

fn has_2d(c: u32) -> bool {
    return (TF2D & (1u << c)) != 0u;
}

// Component c's 2D table at scalar s and gradient magnitude m (world units), read as VTK
// reads its texture: texel centres at (i + ½) / size of the range, clamped to the edge,
// bilinear (nearest with NEAREST).
fn table_2d(c: u32, s: f32, m: f32) -> vec4<f32> {
    let dims = vec2<f32>(textureDimensions(tables_2d));
    let h = dims.y / f32(NCOMP);
    let u = clamp((s - frame.t2d_lo[c]) * frame.t2d_inv_width[c], 0.0, 1.0) * dims.x - 0.5;
    let v = clamp(m * frame.t2d_inv_gmax[c], 0.0, 1.0) * h - 0.5;
    let x = clamp(u, 0.0, dims.x - 1.0);
    let y = clamp(v, 0.0, h - 1.0);
    let base = f32(c) * h;
    if (NEAREST) {
        let xi = clamp(floor(u + 0.5), 0.0, dims.x - 1.0);
        let yi = clamp(floor(v + 0.5), 0.0, h - 1.0);
        return textureLoad(tables_2d, vec2<i32>(i32(xi), i32(base + yi)), 0);
    }
    let x0 = floor(x);
    let y0 = floor(y);
    let x1 = min(x0 + 1.0, dims.x - 1.0);
    let y1 = min(y0 + 1.0, h - 1.0);
    let t00 = textureLoad(tables_2d, vec2<i32>(i32(x0), i32(base + y0)), 0);
    let t10 = textureLoad(tables_2d, vec2<i32>(i32(x1), i32(base + y0)), 0);
    let t01 = textureLoad(tables_2d, vec2<i32>(i32(x0), i32(base + y1)), 0);
    let t11 = textureLoad(tables_2d, vec2<i32>(i32(x1), i32(base + y1)), 0);
    return mix(mix(t00, t10, x - x0), mix(t01, t11, x - x0), y - y0);
}
