// The volume as the ray-casting passes see it: one brick at a time (group 1), sampled in
// index space and converted back to scalar units.

struct Brick {
    // index-space box this pass marches through (the brick's own cells)
    core_lo: vec4<f32>,
    core_hi: vec4<f32>,
    // first point index held by the texture, and 1 / the texture's size in points; the
    // texture extends past the core by an overlap so interpolation and gradients see no seam
    tex_lo: vec4<f32>,
    tex_inv_size: vec4<f32>,
}

@group(1) @binding(0) var<uniform> brick_ubo: Brick;
// A private copy filled by each entry point (`brick = brick_ubo;`), as lib/common.wgsl's
// `frame`.
var<private> brick: Brick;
@group(1) @binding(1) var volume_tex: texture_3d<f32>;
@group(1) @binding(2) var volume_sampler: sampler;
// The first component's central differences per texel (shaders/gradient.wgsl), where the
// upload made them (PRECOMPUTED_GRADIENT); otherwise the volume texture again, unused.
@group(1) @binding(3) var gradient_tex: texture_3d<f32>;

// Read gradients from gradient_tex (one fetch) instead of six volume fetches: the same
// values (a pipeline constant; single-component volumes only).
override PRECOMPUTED_GRADIENT: bool = false;
// Forward differences (3 samples) instead of central ones (6). A pipeline constant, not a
// flag: lavapipe runs both sides of a branch on a uniform value, so a flag would cost the
// 6 samples and the 3.
override FORWARD_DIFF: bool = false;

// Raw texel value (normalised storage) at index-space point p.
fn sample_texel(p: vec3<f32>) -> vec4<f32> {
    let tc = (p - brick.tex_lo.xyz + 0.5) * brick.tex_inv_size.xyz;
    return textureSampleLevel(volume_tex, volume_sampler, tc, 0.0);
}

// Scalars (data units) of every component at texture coordinate tc.
fn scalars_at(tc: vec3<f32>) -> vec4<f32> {
    return textureSampleLevel(volume_tex, volume_sampler, tc, 0.0) * frame.scalar_scale + frame.scalar_shift;
}

// Scalars (data units) of every component at index-space point p.
fn sample_scalars(p: vec3<f32>) -> vec4<f32> {
    return sample_texel(p) * frame.scalar_scale + frame.scalar_shift;
}

struct Gradient {
    x: vec4<f32>,  // d/di of each component
    y: vec4<f32>,
    z: vec4<f32>,
}

// Index-space gradient of every component: central differences (6 samples) or forward
// differences from the centre value s (3 samples).
fn gradient_at(p: vec3<f32>, s: vec4<f32>) -> Gradient {
    // neighbours one voxel away, offset directly in texture coordinates
    let tc = (p - brick.tex_lo.xyz + 0.5) * brick.tex_inv_size.xyz;
    if (PRECOMPUTED_GRADIENT && !FORWARD_DIFF) {
        let d = textureSampleLevel(gradient_tex, volume_sampler, tc, 0.0).xyz;
        var g: Gradient;
        g.x = vec4<f32>(d.x, 0.0, 0.0, 0.0);
        g.y = vec4<f32>(d.y, 0.0, 0.0, 0.0);
        g.z = vec4<f32>(d.z, 0.0, 0.0, 0.0);
        return g;
    }
    let dx = vec3<f32>(brick.tex_inv_size.x, 0.0, 0.0);
    let dy = vec3<f32>(0.0, brick.tex_inv_size.y, 0.0);
    let dz = vec3<f32>(0.0, 0.0, brick.tex_inv_size.z);
    var g: Gradient;
    if (FORWARD_DIFF) {
        g.x = scalars_at(tc + dx) - s;
        g.y = scalars_at(tc + dy) - s;
        g.z = scalars_at(tc + dz) - s;
    } else {
        g.x = 0.5 * (scalars_at(tc + dx) - scalars_at(tc - dx));
        g.y = 0.5 * (scalars_at(tc + dy) - scalars_at(tc - dy));
        g.z = 0.5 * (scalars_at(tc + dz) - scalars_at(tc - dz));
    }
    return g;
}

// World-space gradient of component c.
fn world_gradient(g: Gradient, c: u32) -> vec3<f32> {
    return (frame.gradient_to_world * vec4<f32>(g.x[c], g.y[c], g.z[c], 0.0)).xyz;
}
