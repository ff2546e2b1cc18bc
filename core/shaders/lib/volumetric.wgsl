// What the ray casters' volumetric shadows share (lib/shadow.wgsl for images, unstructured.wgsl
// for meshes), with the meaning VTK 9.2 gives vtkGPUVolumeRayCastMapper's
// VolumetricScatteringBlending and vtkVolumeProperty's ScatteringAnisotropy (frame.scatter:
// x the blending, y the anisotropy).
#include "lib/common.wgsl"

// Henyey–Greenstein over the cosine μ, normalised to 1 for isotropic scattering.
fn shadow_phase(mu: f32) -> f32 {
    let g = frame.scatter.y;
    if (abs(g) < 0.01) {
        return 1.0;
    }
    let d = max(1.0 + g * g - 2.0 * g * mu, 1e-12);
    return (1.0 - g * g) / (d * sqrt(d));
}

// The volumetric term's weight against the gradient shading, from VTK's gradient magnitude
// gm and the sample's opacity a: it grows with the blending where both are small; from a
// blending of 1 on, the volumetric term takes over everywhere at 2.
fn volumetric_weight(gm: f32, a: f32) -> f32 {
    let b = frame.scatter.x;
    if (b >= 1.0) {
        return (2.0 - b) * exp(-b * gm * a) + (b - 1.0);
    }
    return b * exp(-b * gm * a);
}
