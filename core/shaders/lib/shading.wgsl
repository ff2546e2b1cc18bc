// Phong local illumination with VTK's volume shading conventions
// (vtkVolumeShaderComposer.h): the normal is the negated normalised gradient; ambient and
// diffuse modulate the sample colour, specular adds the lights' specular colour (white
// highlights); the specular term uses the reflection vector, as VTK does; with two-sided
// lighting a light behind the surface lights its back. Where the gradient vanishes there
// is no normal and only the ambient term remains.
#include "lib/common.wgsl"

// Whether any light is positional (a pipeline constant: directional-only scenes, the
// common case with VTK's headlight, carry no attenuation or spotlight code).
override POSITIONAL_LIGHTS: bool = true;
// Number of lights (a pipeline constant, so the light loop unrolls).
override NUM_LIGHTS: u32 = 1u;

// Unit vector from pos toward the light (xyz) and the light's attenuation there (w).
// v: unit vector toward the eye (the headlight's direction). light.position.w: 0
// directional, 1 positional, 2 headlight (from the camera along each ray).
fn light_incidence(light: Light, pos: vec3<f32>, v: vec3<f32>) -> vec4<f32> {
    var l = select(light.position.xyz, v, light.position.w > 1.5);
    var atten = 1.0;
    if (POSITIONAL_LIGHTS && light.position.w > 0.5 && light.position.w < 1.5) {
        let lv = light.position.xyz - pos;
        let d = length(lv);
        l = lv / max(d, 1e-20);
        let a = light.attenuation;
        atten = 1.0 / max(a.x + a.y * d + a.z * d * d, 1e-20);
        if (light.spot.w > -1.5) {
            let cos_a = dot(-l, light.spot.xyz);
            if (cos_a < light.spot.w) {
                atten = 0.0;
            } else {
                atten = atten * pow(max(cos_a, 0.0), light.diffuse.w);
            }
        }
    }
    return vec4<f32>(l, atten);
}

fn shade(color: vec3<f32>, grad: vec3<f32>, pos: vec3<f32>, view_dir: vec3<f32>) -> vec3<f32> {
    return shade_material(color, grad, pos, view_dir, frame.material);
}

// shade() with the material m (ambient, diffuse, specular, specular power).
fn shade_material(color: vec3<f32>, grad: vec3<f32>, pos: vec3<f32>, view_dir: vec3<f32>,
                  m: vec4<f32>) -> vec3<f32> {
    let l = lighting(grad, pos, view_dir, m);
    return clamp(color * l.scale + l.add, vec3<f32>(0.0), vec3<f32>(1.0));
}

// What the lights make of a colour c at a point: c · scale + add, clamped to [0, 1].
struct Lighting {
    scale: vec3<f32>, // the material's ambient and diffuse terms, summed over the lights
    add: vec3<f32>,   // its specular term
}

// The lights at pos, with gradient grad, for the material m (ambient, diffuse, specular,
// specular power).
fn lighting(grad: vec3<f32>, pos: vec3<f32>, view_dir: vec3<f32>, m: vec4<f32>) -> Lighting {
    let glen = length(grad);
    var ambient = vec3<f32>(0.0);
    var diffuse = vec3<f32>(0.0);
    var specular = vec3<f32>(0.0);
    let has_normal = glen > frame.gradient_epsilon;
    var n = vec3<f32>(0.0);
    if (has_normal) {
        n = -grad / glen;
    }
    let v = -view_dir;
    for (var i = 0u; i < NUM_LIGHTS; i = i + 1u) {
        let light = frame.lights[i];
        ambient = ambient + light.ambient.rgb;
        if (!has_normal) {
            continue;
        }
        let li = light_incidence(light, pos, v);
        let l = li.xyz;
        let atten = li.w;
        var nl = n;
        var ndl = dot(nl, l);
        if (ndl < 0.0 && has_flag(FLAG_TWO_SIDED)) {
            nl = -nl;
            ndl = -ndl;
        }
        if (ndl > 0.0) {
            diffuse = diffuse + atten * ndl * light.diffuse.rgb;
            let r = 2.0 * ndl * nl - l;
            let rdv = dot(r, v);
            if (rdv > 0.0) {
                specular = specular + atten * pow(rdv, m.w) * light.specular.rgb;
            }
        }
    }
    var out: Lighting;
    out.scale = m.x * ambient + m.y * diffuse;
    out.add = m.z * specular;
    return out;
}
