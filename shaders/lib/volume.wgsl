// The volume as the ray-casting passes see it: one brick at a time (group 1), sampled in
// index space and converted back to scalar units.

struct Brick {
    // index-space box this pass marches through (the brick's own cells)
    core_lo: vec4<f32>,
    core_hi: vec4<f32>,
    // first point index held by the texture, and the texture's size in points; the texture
    // extends past the core by an overlap so interpolation and gradients see no seam
    tex_lo: vec4<f32>,
    tex_size: vec4<f32>,
    tex_inv_size: vec4<f32>,
}

@group(1) @binding(0) var<uniform> brick: Brick;
@group(1) @binding(1) var volume_tex: texture_3d<f32>;
@group(1) @binding(2) var volume_sampler: sampler;

// Raw value of the texel at integer texture coordinate c, clamped to the brick's texture.
fn texel(c: vec3<i32>) -> vec4<f32> {
    let hi = vec3<i32>(brick.tex_size.xyz) - 1;
    return textureLoad(volume_tex, clamp(c, vec3<i32>(0), hi), 0);
}

// Raw texel value (normalised storage) at index-space point p.
fn sample_texel(p: vec3<f32>) -> vec4<f32> {
    let q = p - brick.tex_lo.xyz + 0.5;
    if (NEAREST) {
        return texel(vec3<i32>(floor(q)));
    }
    return textureSampleLevel(volume_tex, volume_sampler, q * brick.tex_inv_size.xyz, 0.0);
}

// Scalars (data units) of every component at index-space point p.
fn sample_scalars(p: vec3<f32>) -> vec4<f32> {
    return sample_texel(p) * frame.scalar_scale + frame.scalar_shift;
}

// Scalars of the texel at integer texture coordinate c.
fn scalars_at_texel(c: vec3<i32>) -> vec4<f32> {
    return texel(c) * frame.scalar_scale + frame.scalar_shift;
}

struct Gradient {
    x: vec4<f32>,  // d/di of each component
    y: vec4<f32>,
    z: vec4<f32>,
}

// Index-space gradient of every component: central differences (6 samples) or forward
// differences from the centre value s (3 samples).
fn gradient_at(p: vec3<f32>, s: vec4<f32>) -> Gradient {
    var g: Gradient;
    if (NEAREST) {
        // the six neighbours of the nearest texel, one rounding for all of them
        let c = vec3<i32>(floor(p - brick.tex_lo.xyz + 0.5));
        let ex = vec3<i32>(1, 0, 0);
        let ey = vec3<i32>(0, 1, 0);
        let ez = vec3<i32>(0, 0, 1);
        if (has_flag(FLAG_FORWARD_DIFF)) {
            g.x = scalars_at_texel(c + ex) - s;
            g.y = scalars_at_texel(c + ey) - s;
            g.z = scalars_at_texel(c + ez) - s;
        } else {
            g.x = 0.5 * (scalars_at_texel(c + ex) - scalars_at_texel(c - ex));
            g.y = 0.5 * (scalars_at_texel(c + ey) - scalars_at_texel(c - ey));
            g.z = 0.5 * (scalars_at_texel(c + ez) - scalars_at_texel(c - ez));
        }
        return g;
    }
    if (has_flag(FLAG_FORWARD_DIFF)) {
        g.x = sample_scalars(p + vec3<f32>(1.0, 0.0, 0.0)) - s;
        g.y = sample_scalars(p + vec3<f32>(0.0, 1.0, 0.0)) - s;
        g.z = sample_scalars(p + vec3<f32>(0.0, 0.0, 1.0)) - s;
    } else {
        g.x = 0.5 * (sample_scalars(p + vec3<f32>(1.0, 0.0, 0.0)) - sample_scalars(p - vec3<f32>(1.0, 0.0, 0.0)));
        g.y = 0.5 * (sample_scalars(p + vec3<f32>(0.0, 1.0, 0.0)) - sample_scalars(p - vec3<f32>(0.0, 1.0, 0.0)));
        g.z = 0.5 * (sample_scalars(p + vec3<f32>(0.0, 0.0, 1.0)) - sample_scalars(p - vec3<f32>(0.0, 0.0, 1.0)));
    }
    return g;
}

// World-space gradient of component c.
fn world_gradient(g: Gradient, c: u32) -> vec3<f32> {
    return (frame.gradient_to_world * vec4<f32>(g.x[c], g.y[c], g.z[c], 0.0)).xyz;
}
