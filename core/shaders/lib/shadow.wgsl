// Volumetric shadows (single scattering) of the ray caster, with the meaning VTK 9.2 gives
// vtkGPUVolumeRayCastMapper::VolumetricScatteringBlending, GlobalIlluminationReach and
// vtkVolumeProperty::ScatteringAnisotropy, so that the same settings give the same image:
// at each sample, a shadow ray toward each light marches the step-corrected opacity
// (transmittance T = Π (1 − α)) in steps of the primary ray's length, starting one step
// out, at most the reach; the volumetric colour is Σ T·p(μ)·c·kd·I_diffuse + ka·I_ambient
// with p the Henyey–Greenstein phase normalised to 1 when isotropic and μ the cosine
// between the light's travel direction and the direction to the eye; it is mixed with the
// gradient shading by a weight that grows with the blending where the gradient and the
// opacity are small. Distances are measured in texture space (the volume's point box
// mapped to the unit cube), as VTK's are. Needs lib/common.wgsl and lib/volume.wgsl.
#include "lib/common.wgsl"
#include "lib/volume.wgsl"
#include "lib/shading.wgsl"
#include "lib/volumetric.wgsl"

// The shadow and jitter offset of the current pixel (dvr.wgsl sets it: VTK reuses the
// primary ray's jitter, 0 without jittering).
var<private> shadow_jitter: f32 = 0.0;

// VTK's texture coordinates: the unit cube over the texture's texels, so that point i
// sits at (i + 0.5) / N and the box reaches half a voxel past the outer points (shadow rays
// start counting from there).
fn index_to_tex(v: vec3<f32>) -> vec3<f32> {
    return (v + 0.5) / frame.dims.xyz;
}

fn tex_to_index(v: vec3<f32>) -> vec3<f32> {
    return v * frame.dims.xyz - 0.5;
}

// Light positions and directions reach VTK's shader through its eye-to-texture matrix,
// which maps the outer points (not the texels) to the unit cube.
fn light_tex(v: vec4<f32>) -> vec3<f32> {
    return (frame.world_to_index * v).xyz / max(frame.dims.xyz - 1.0, vec3<f32>(1.0));
}

// World direction → unit texture-space direction (as light_tex).
fn tex_direction(d: vec3<f32>) -> vec3<f32> {
    return normalize(light_tex(vec4<f32>(d, 0.0)));
}

// The opacity one shadow step takes away at texture point x.
fn shadow_alpha(x: vec3<f32>, grad_opacity: bool) -> f32 {
    let p = tex_to_index(x);
    let s = sample_scalars(p);
    var a = classify(0u, s.x).a;
    if (grad_opacity && a > 0.0) {
        a = a * gradient_opacity(0u, length(world_gradient(gradient_at(p, s), 0u)));
    }
    return a;
}

// One shadow step: the sample at t (jittered within the step), then t moves on.
fn shadow_step(s0: vec3<f32>, n: vec3<f32>, maxdist: f32, dt: f32, grad_opacity: bool,
               t: ptr<function, f32>, tr: ptr<function, f32>) {
    if (*t < maxdist) {
        let x = s0 + (*t + min(maxdist - *t, dt) * shadow_jitter) * n;
        *tr = *tr * (1.0 - shadow_alpha(x, grad_opacity));
        *t = *t + dt;
    }
}

// Transmittance from texture point p along the unit texture direction n, at most `limit`
// texture units (the distance to a positional light) and the reach, in steps of dt.
fn shadow_transmittance(p: vec3<f32>, n: vec3<f32>, limit: f32, dt: f32, grad_opacity: bool) -> f32 {
    let s0 = p + dt * n;
    // (axis components below 0.001 count as ±0.001, as VTK's slab test does)
    let nn = select(vec3<f32>(0.001), vec3<f32>(-0.001), n < vec3<f32>(0.0));
    let m = select(n, nn, abs(n) < vec3<f32>(0.001));
    let t0 = -s0 / m;
    let t1 = (vec3<f32>(1.0) - s0) / m;
    let near = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), min(t0.z, t1.z));
    let far = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
    // Shadow samples can lie a whole number of steps from the exit or the reach (a
    // headlight's shadow ray runs back along the primary ray), so comparisons with those
    // distances are decided by rounding (rings in the image). As exact arithmetic would: a
    // shadow ray one step long is kept, a sample exactly at its end is not taken.
    let eps = 1e-3 * dt;
    if (far < near || far < dt - eps) {
        return 1.0;
    }
    let maxdist = min(min(far, frame.scatter.z), limit) - eps;
    if (maxdist < 0.001) {
        return 1.0;
    }
    var tr = 1.0;
    var t = 0.0;
    // Eight steps per iteration: lavapipe stops an invocation's loops after 65535
    // iterations in all, which long shadow rays at every sample would reach.
    loop {
        if (t >= maxdist || tr <= 0.0) {
            break;
        }
        shadow_step(s0, n, maxdist, dt, grad_opacity, &t, &tr);
        shadow_step(s0, n, maxdist, dt, grad_opacity, &t, &tr);
        shadow_step(s0, n, maxdist, dt, grad_opacity, &t, &tr);
        shadow_step(s0, n, maxdist, dt, grad_opacity, &t, &tr);
        shadow_step(s0, n, maxdist, dt, grad_opacity, &t, &tr);
        shadow_step(s0, n, maxdist, dt, grad_opacity, &t, &tr);
        shadow_step(s0, n, maxdist, dt, grad_opacity, &t, &tr);
        shadow_step(s0, n, maxdist, dt, grad_opacity, &t, &tr);
    }
    return tr;
}

// VTK's gradient magnitude in the volumetric blending, from the world gradient `grad` that
// shades the sample: central differences over two voxels per unit length, of the normalised
// scalar, or of the opacity where the normals come from the opacity (`of_opacity`).
fn vtk_gradient_magnitude(grad: vec3<f32>, of_opacity: bool) -> f32 {
    if (of_opacity) {
        return 2.0 * length(grad);
    }
    return length(grad) * frame.scatter.w;
}

// The sample's colour with volumetric shadows: `color` the transfer function's colour, `a`
// its step-corrected opacity (before gradient opacity), `gm` VTK's gradient magnitude
// (vtk_gradient_magnitude), `surface` the gradient-shaded colour, p the index-space point,
// pos the world point, view_dir the ray's direction.
fn volumetric_shade(color: vec3<f32>, a: f32, gm: f32, surface: vec3<f32>,
                    p: vec3<f32>, pos: vec3<f32>, view_dir: vec3<f32>, grad_opacity: bool) -> vec3<f32> {
    let pt = index_to_tex(p);
    let dt = length((frame.world_to_index * vec4<f32>(view_dir * frame.sample_distance, 0.0)).xyz / frame.dims.xyz);
    let eye = tex_direction(-view_dir);
    let kd = frame.material.y;
    let ka = frame.material.x;
    var v = vec3<f32>(0.0);
    for (var i = 0u; i < NUM_LIGHTS; i = i + 1u) {
        let light = frame.lights[i];
        var n = eye;
        var mu = -1.0;
        var limit = 3.0e38;
        var atten = 1.0;
        if (light.position.w > 0.5 && light.position.w < 1.5) {
            let lt = light_tex(vec4<f32>(light.position.xyz, 1.0));
            n = normalize(lt - pt);
            mu = dot(-n, eye);
            limit = distance(lt, pt + dt * n);
            let lw = light.position.xyz;
            let dist = distance(lw, pos);
            let a3 = light.attenuation;
            atten = 1.0 / max(a3.x + a3.y * dist + a3.z * dist * dist, 1e-20);
            if (light.spot.w > -1.5) {
                let cos_a = dot(normalize(pos - lw), light.spot.xyz);
                atten = select(0.0, atten * pow(max(cos_a, 0.0), light.diffuse.w), cos_a > light.spot.w);
            }
        } else if (light.position.w < 0.5) {
            n = tex_direction(light.position.xyz);
            mu = dot(-n, eye);
        }
        let tr = shadow_transmittance(pt, n, limit, dt, grad_opacity);
        v = v + tr * shadow_phase(mu) * atten * kd * color * light.diffuse.rgb;
        // (a headlight's ambient colour stands for the surface shading's ambient term, ka
        // times the sample colour, as VTK's headlight path has it; VTK's volumetric term
        // adds the headlight's own ambient colour, black for its automatic headlight)
        if (light.position.w < 1.5) {
            v = v + ka * light.ambient.rgb;
        }
    }
    return clamp(mix(surface, v, volumetric_weight(gm, a)), vec3<f32>(0.0), vec3<f32>(1.0));
}
