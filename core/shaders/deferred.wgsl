// Deferred shading of the G-buffer firsthit.wgsl (for a mesh, firsthit_mesh.wgsl) wrote.
// Per pixel, its surface layers front to back, each
//   - lit by the scene's lights (Blinn–Phong, lib/surface.wgsl), ambient scaled by AO;
//   - lit by the environment: diffuse from the irradiance cube at the normal, specular from
//     the environment cube on the Phong lobe cos^s around the reflection vector (the simple
//     cone scheme or importance sampling with pdf-based mip filtering), both scaled by AO;
//   - specular weighted by Schlick's Fresnel term when enabled; the exponent s from the
//     gradient magnitude (or constant);
// and composited with its iso-value's opacity; then the environment behind, if asked for.
//
// Scattering restricted to the isosurfaces (the lecture's fast path, SCATTER > 0): light
// enters at the first surface, travels inward along the view ray to the next surface (or
// out of the volume), absorbed by the medium between (extinction from the transfer
// function's opacity, as the path tracer reads it), scatters there (Lambertian, the
// inner surface's colour as albedo), and leaves toward the environment. The preview
// (SCATTER 1) assumes the way out absorbs as much as the way in (the transmittance
// squared) and reads the irradiance cube at the inner surface; the traced version
// (SCATTER 2) marches iso.scatter.y cosine-distributed directions from the inner surface
// out of the volume and reads the environment where each leaves (at the mip level its share
// of the hemisphere calls for). The first surface's own
// shading and the scattered light are blended by Schlick's Fresnel term, and the first
// surface is then opaque.
#include "lib/common.wgsl"
#include "lib/ray.wgsl"
#include "lib/volume.wgsl"
#include "lib/surface.wgsl"
#include "lib/envmap.wgsl"
#include "lib/iso.wgsl"
#include "lib/blanking.wgsl"
#include "lib/rectilinear.wgsl"

// 0: no scattering; 1: the preview; 2: traced (pipeline constant).
override SCATTER: u32 = 0u;
// The component whose isosurfaces are drawn (core/src/passes/iso.rs, iso_component).
override ISO_COMP: u32 = 0u;
// The surfaces of an unstructured volume (firsthit_mesh.wgsl wrote them): no image volume is
// bound (group 1 is not read), and the scattering between the surfaces is not drawn.
override MESH: bool = false;

@group(0) @binding(2) var<storage, read> state: array<PixelState>;
@group(0) @binding(SLOT_OUT_COLOR) var out_color: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(SLOT_OUT_DEPTH) var out_depth: texture_storage_2d<r32float, write>;
@group(0) @binding(8) var g_position: texture_2d_array<f32>;
@group(0) @binding(9) var g_normal: texture_2d_array<f32>;
@group(0) @binding(10) var g_extra: texture_2d_array<f32>;
@group(0) @binding(11) var env_cube: texture_cube<f32>;
@group(0) @binding(12) var irradiance_cube: texture_cube<f32>;
@group(0) @binding(13) var env_sampler: sampler;
// Random unit vectors, uniform over the sphere (the cone scheme's precomputed directions).
@group(0) @binding(14) var<storage, read> lobe_dirs: array<vec4<f32>>;
// A binary mask (Renderer::set_mask): the medium between the surfaces is empty where the
// nearest point holds 0, as the surfaces leave those samples out (MASK_BINARY).
@group(0) @binding(15) var mask_tex: texture_3d<u32>;
override MASK: u32 = MASK_NONE;

fn env_direction(d: vec3<f32>) -> vec3<f32> {
    return (iso.env_rotation * vec4<f32>(d, 0.0)).xyz;
}

fn env_radiance(d: vec3<f32>, lod: f32) -> vec3<f32> {
    return textureSampleLevel(env_cube, env_sampler, d, lod).rgb;
}

// The specular exponent of a surface with gradient magnitude m.
fn shininess(m: f32) -> f32 {
    let u = clamp((m - iso.shininess.x) * iso.shininess.y, 0.0, 1.0);
    return mix(iso.shininess.z, iso.shininess.w, u);
}

// The environment seen through the normalised Phong lobe cos^s around the unit
// environment-space reflection vector r: ∫ L(ω) cos^s(ω, r) dω / ∫ cos^s(ω, r) dω over the
// hemisphere around r (a constant environment gives the constant).
fn specular_environment(r: vec3<f32>, s: f32) -> vec3<f32> {
    let count = iso.options.y;
    var sum = vec3<f32>(0.0);
    if (iso.options.z == SPECULAR_CONE) {
        // The simple scheme: random unit vectors p turned into r's hemisphere, blended with r
        // (d = α·r + (1 − α)·p, normalised) and weighted by the lobe. α makes the blend's
        // widest direction (p ⟂ r) the angle where the lobe has fallen to 1%.
        let cos_max = pow(0.01, 1.0 / max(s, 1e-3));
        let tan_max = sqrt(max(1.0 - cos_max * cos_max, 0.0)) / max(cos_max, 1e-4);
        let a = 1.0 / (1.0 + tan_max);
        var wsum = 0.0;
        let nd = arrayLength(&lobe_dirs);
        for (var i = 0u; i < count; i = i + 1u) {
            var p = lobe_dirs[i % nd].xyz;
            if (dot(r, p) < 0.0) {
                p = -p;
            }
            let d = normalize(a * r + (1.0 - a) * p);
            let w = pow(max(dot(d, r), 0.0), s);
            sum = sum + w * env_radiance(d, 0.0);
            wsum = wsum + w;
        }
        if (wsum <= 0.0) {
            return env_radiance(r, 0.0);
        }
        return sum / wsum;
    }
    // Importance sampling: Hammersley directions distributed as the lobe, each read from
    // the mip level whose texels cover the solid angle its pdf gives it.
    let b = basis_around(r);
    for (var i = 0u; i < count; i = i + 1u) {
        let l = phong_lobe(hammersley(i, count), s);
        let pdf = (s + 1.0) / (2.0 * PI) * pow(l.z, s);
        sum = sum + env_radiance(b * l, filtered_lod(pdf, count, iso.env.z, iso.env.w));
    }
    return sum / f32(count);
}

// Shaded colour (not premultiplied) of one surface layer.
fn shade_surface(color: vec3<f32>, pos: vec3<f32>, n: vec3<f32>, gmag: f32, ao: f32, v: vec3<f32>) -> vec3<f32> {
    let s = shininess(gmag);
    var fresnel = 1.0;
    if (iso.env.y >= 0.0) {
        let f0 = iso.env.y;
        fresnel = f0 + (1.0 - f0) * pow(1.0 - clamp(dot(n, v), 0.0, 1.0), 5.0);
    }
    let m = frame.material;
    let lights = blinn_phong(n, pos, v, s);
    var rgb = color * (m.x * ao * lights.ambient + m.y * lights.diffuse) + m.z * fresnel * lights.specular;
    let w = iso.env.x;
    if (w > 0.0) {
        let irr = textureSampleLevel(irradiance_cube, env_sampler, env_direction(n), 0.0).rgb;
        var spec = vec3<f32>(0.0);
        if (m.z > 0.0) {
            let r = env_direction(2.0 * dot(n, v) * n - v);
            spec = specular_environment(normalize(r), s);
        }
        rgb = rgb + w * ao * (m.y * color * irr + m.z * fresnel * spec);
    }
    return clamp(rgb, vec3<f32>(0.0), vec3<f32>(1.0));
}

// Extinction per world unit at world point x (the first component's opacity α as
// −ln(1 − α) per unit distance, scaled).
fn absorption_at(x: vec3<f32>) -> f32 {
    let p = grid_point((frame.world_to_index * vec4<f32>(x, 1.0)).xyz);
    if ((MASK == MASK_BINARY && mask_value(mask_tex, p) == 0u) || blanked(p)) {
        return 0.0;
    }
    let a = min(raw_alpha(ISO_COMP, sample_scalars(p)[ISO_COMP]), 0.9999);
    return -log(1.0 - a) * iso.scatter.x;
}

// Optical depth from x along the unit direction d over `len` world units (midpoint rule
// in steps of at most the sample distance).
fn optical_depth(x: vec3<f32>, d: vec3<f32>, len: f32) -> f32 {
    let n = min(u32(ceil(max(len, 0.0) / frame.sample_distance)), 8192u);
    let h = len / f32(max(n, 1u));
    var tau = 0.0;
    for (var i = 0u; i < n; i = i + 1u) {
        tau = tau + absorption_at(x + (f32(i) + 0.5) * h * d) * h;
    }
    return tau;
}

// World distance from x along the unit direction d to where it leaves the volume.
fn volume_exit(x: vec3<f32>, d: vec3<f32>) -> f32 {
    let seg = box_interval(ray_from(x, d), vec3<f32>(0.0), frame.dims.xyz - 1.0);
    return max(seg.y, 0.0);
}

// The light scattered back toward the viewer by the inner surface at x1 (normal n1 facing
// the viewer, albedo c1), reached through transmittance t_in from the first surface.
fn scattered_light(x1: vec3<f32>, n1: vec3<f32>, c1: vec3<f32>, t_in: f32, px: vec2<u32>) -> vec3<f32> {
    if (SCATTER == 1u) {
        let irr = textureSampleLevel(irradiance_cube, env_sampler, env_direction(n1), 0.0).rgb;
        return c1 * irr * t_in * t_in;
    }
    // cosine-distributed directions (the irradiance cube's weighting), the Hammersley set
    // turned by a per-pixel angle
    let count = u32(iso.scatter.y);
    let b = basis_around(n1);
    let turn = 2.0 * PI * hash01(px.y * 65536u + px.x);
    var sum = vec3<f32>(0.0);
    for (var k = 0u; k < count; k = k + 1u) {
        let u = hammersley(k, count);
        let l = cosine_hemisphere(vec2<f32>(u.x, fract(u.y + turn / (2.0 * PI))));
        let w = b * l;
        let start = x1 + 1e-3 * frame.sample_distance * w;
        let tau = optical_depth(start, w, volume_exit(start, w));
        // each direction reads the mip level whose texels cover the solid angle it stands
        // for (filtered importance sampling, as the specular lobe): a small bright sun is
        // spread over the directions instead of lighting a few pixels
        let lod = filtered_lod(max(l.z, 1e-3) / PI, count, iso.env.z, iso.env.w);
        sum = sum + exp(-tau) * env_radiance(env_direction(w), lod);
    }
    return c1 * (sum / f32(max(count, 1u))) * t_in;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    frame = frame_ubo;
    if (!MESH) {
        enter_volume();
    }
    iso = iso_ubo;
    let r = iso.shade_rect;
    let px = gid.xy + r.xy;
    if (px.x >= r.z || px.y >= r.w) {
        return;
    }
    let fr = frame.rect;
    var layers = 0u;
    if (px.x >= fr.x && px.x < fr.z && px.y >= fr.y && px.y < fr.w) {
        layers = min(u32(state[px.y * frame.width + px.x].color.x), iso.counts.z);
    }
    let ray = make_ray(px);
    let v = -ray.dir;
    let c = vec2<i32>(px);
    var color = vec4<f32>(0.0);
    var depth = 1.0;
    var depth_set = false;
    if (!MESH && SCATTER > 0u && layers > 0u) {
        let gp = textureLoad(g_position, c, 0, 0);
        let gn = textureLoad(g_normal, c, 0, 0);
        let ge = textureLoad(g_extra, c, 0, 0);
        let c0 = iso.colors[min(u32(gp.w), MAX_ISO - 1u)].rgb;
        // the next surface inward along the view ray, or where the ray leaves the volume
        var x1 = gp.xyz + ray.dir * volume_exit(gp.xyz, ray.dir);
        var n1 = gn.xyz;
        var c1 = c0;
        if (layers > 1u) {
            let gp1 = textureLoad(g_position, c, 1, 0);
            x1 = gp1.xyz;
            n1 = textureLoad(g_normal, c, 1, 0).xyz;
            c1 = iso.colors[min(u32(gp1.w), MAX_ISO - 1u)].rgb;
        }
        let t_in = exp(-optical_depth(gp.xyz, ray.dir, distance(gp.xyz, x1)));
        let inner = iso.env.x * scattered_light(x1, n1, c1, t_in, px);
        let f0 = iso.scatter.z;
        let f = f0 + (1.0 - f0) * pow(1.0 - clamp(dot(gn.xyz, v), 0.0, 1.0), 5.0);
        let surface = shade_surface(c0, gp.xyz, gn.xyz, gn.w, ge.y, v);
        color = vec4<f32>(clamp(f * surface + (1.0 - f) * inner, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
        depth = ge.x;
        layers = 0u;
    }
    for (var l = 0u; l < layers; l = l + 1u) {
        let gp = textureLoad(g_position, c, i32(l), 0);
        let gn = textureLoad(g_normal, c, i32(l), 0);
        let ge = textureLoad(g_extra, c, i32(l), 0);
        let surface = iso.colors[min(u32(gp.w), MAX_ISO - 1u)];
        let rgb = shade_surface(surface.rgb, gp.xyz, gn.xyz, gn.w, ge.y, v);
        let w = (1.0 - color.a) * surface.a;
        color = vec4<f32>(color.rgb + w * rgb, color.a + w);
        if (!depth_set && color.a > frame.depth_threshold) {
            depth = ge.x;
            depth_set = true;
        }
    }
    if ((iso.options.w & ISO_FLAG_BACKGROUND) != 0u) {
        let bg = env_radiance(env_direction(ray.dir), 0.0);
        color = vec4<f32>(color.rgb + (1.0 - color.a) * bg, 1.0);
    }
    textureStore(out_color, c, clamp(color, vec4<f32>(0.0), vec4<f32>(1.0)));
    textureStore(out_depth, c, vec4<f32>(depth, 0.0, 0.0, 0.0));
}
