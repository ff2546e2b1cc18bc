// Blinn–Phong at a surface point (isosurfaces, deferred.wgsl) with the scene's lights and
// VTK's light kinds as lib/shading.wgsl places them: directional, positional with
// attenuation and spotlight cone, and the headlight shining along each ray.
#include "lib/shading.wgsl"

// Sums over the lights; the caller weights them with the material.
struct LightSum {
    ambient: vec3<f32>,
    diffuse: vec3<f32>,
    specular: vec3<f32>,
}

// Unit vector from pos toward the light (xyz) and the light's attenuation there (w).
// v: unit vector toward the eye (the headlight's direction).
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

// Blinn–Phong sums for unit normal n (facing the viewer), unit vector v toward the eye and
// specular exponent s: ambient colours, diffuse n·l, specular (n·h)^s with h the half
// vector; lights behind the surface give no diffuse or specular light.
fn blinn_phong(n: vec3<f32>, pos: vec3<f32>, v: vec3<f32>, s: f32) -> LightSum {
    var sum: LightSum;
    sum.ambient = vec3<f32>(0.0);
    sum.diffuse = vec3<f32>(0.0);
    sum.specular = vec3<f32>(0.0);
    for (var i = 0u; i < NUM_LIGHTS; i = i + 1u) {
        let light = frame.lights[i];
        sum.ambient = sum.ambient + light.ambient.rgb;
        let li = light_incidence(light, pos, v);
        let ndl = dot(n, li.xyz);
        if (ndl > 0.0) {
            sum.diffuse = sum.diffuse + li.w * ndl * light.diffuse.rgb;
            let h = normalize(li.xyz + v);
            sum.specular = sum.specular + li.w * pow(max(dot(n, h), 0.0), s) * light.specular.rgb;
        }
    }
    return sum;
}
