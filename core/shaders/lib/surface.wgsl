// Blinn–Phong at a surface point (isosurfaces, deferred.wgsl) with the scene's lights and
// VTK's light kinds as lib/shading.wgsl places them (light_incidence): directional, positional with
// attenuation and spotlight cone, and the headlight shining along each ray.
#include "lib/shading.wgsl"
#include "lib/common.wgsl"

// Sums over the lights; the caller weights them with the material.
struct LightSum {
    ambient: vec3<f32>,
    diffuse: vec3<f32>,
    specular: vec3<f32>,
}

// Blinn–Phong sums for unit normal n (facing the viewer), unit vector v toward the eye and
// specular exponent s: ambient colours, diffuse n·l, specular (n·h)^s with h the half
// vector. A light behind the surface lights it from its back with two-sided lighting
// (FLAG_TWO_SIDED, VTK's TwoSidedLighting: the normal flipped toward it), else not at all.
fn blinn_phong(n: vec3<f32>, pos: vec3<f32>, v: vec3<f32>, s: f32) -> LightSum {
    var sum: LightSum;
    sum.ambient = vec3<f32>(0.0);
    sum.diffuse = vec3<f32>(0.0);
    sum.specular = vec3<f32>(0.0);
    for (var i = 0u; i < NUM_LIGHTS; i = i + 1u) {
        let light = frame.lights[i];
        sum.ambient = sum.ambient + light.ambient.rgb;
        let li = light_incidence(light, pos, v);
        var nl = n;
        var ndl = dot(n, li.xyz);
        if (ndl < 0.0 && has_flag(FLAG_TWO_SIDED)) {
            nl = -n;
            ndl = -ndl;
        }
        if (ndl > 0.0) {
            sum.diffuse = sum.diffuse + li.w * ndl * light.diffuse.rgb;
            let h = normalize(li.xyz + v);
            sum.specular = sum.specular + li.w * pow(max(dot(nl, h), 0.0), s) * light.specular.rgb;
        }
    }
    return sum;
}
