// The surface-like scattering of the hybrid model (the path tracer where the gradient is
// strong, and the BSDF check): a BSDF oriented by the normalised gradient, written as a
// phase function over the sphere (h = f·|cos θ|, so ∫ h dω is the albedo). Three lobes,
// chosen with fixed probabilities and evaluated as one mixture:
//   - specular reflection, uncoloured: GGX microfacets (roughness α), Smith's separable
//     shadowing, weighted by Schlick's Fresnel term F at the viewing angle;
//   - diffuse reflection, coloured: Lambert, weight (1 − F)(1 − t);
//   - transmission, coloured: the "inward-looking" Phong lobe cos^m around the continued
//     propagation direction, kept where it passes through the surface, weight (1 − F)·t.
// Each lobe integrates to at most 1 and the weights sum to 1, so the albedo is at most
// the colour's. Needs PI, basis_around, cosine_hemisphere and phong_lobe (lib/envmap.wgsl).
#include "lib/envmap.wgsl"

struct Bsdf {
    n: vec3<f32>,      // unit normal on the side the path comes from
    color: vec3<f32>,  // albedo of the diffuse and transmissive lobes
    fresnel: f32,      // F: probability of the specular lobe
    alpha: f32,        // GGX roughness
    transmission: f32, // t: share of the non-specular part that is transmitted
    exponent: f32,     // m: the transmissive Phong lobe's exponent
}

// The BSDF at a point with gradient direction `grad` (any length > 0, either sign) for a
// path propagating along the unit direction d: GGX roughness alpha, Fresnel reflectance f0
// at normal incidence, transmitted share t of the non-specular part, Phong exponent m of
// the transmissive lobe.
fn bsdf_at(grad: vec3<f32>, d: vec3<f32>, color: vec3<f32>, alpha: f32, f0: f32, t: f32, m: f32) -> Bsdf {
    var b: Bsdf;
    let n = normalize(grad);
    b.n = select(n, -n, dot(n, d) > 0.0);
    let c = clamp(-dot(b.n, d), 0.0, 1.0);
    b.fresnel = f0 + (1.0 - f0) * pow(1.0 - c, 5.0);
    b.color = color;
    b.alpha = alpha;
    b.transmission = t;
    b.exponent = m;
    return b;
}

fn ggx_d(nh: f32, a2: f32) -> f32 {
    let q = nh * nh * (a2 - 1.0) + 1.0;
    return a2 / (PI * q * q);
}

fn smith_g1(c: f32, a2: f32) -> f32 {
    return 2.0 * c / (c + sqrt(a2 + (1.0 - a2) * c * c));
}

// The BSDF's value (rgb, per steradian) for the outgoing direction w of a path that
// arrived along d, and the density (a) with which bsdf_sample draws w.
fn bsdf_eval(b: Bsdf, d: vec3<f32>, w: vec3<f32>) -> vec4<f32> {
    let v = -d;
    let cv = max(dot(b.n, v), 1e-4);
    let cl = dot(b.n, w);
    let a2 = b.alpha * b.alpha;
    let ws = b.fresnel;
    let wd = (1.0 - b.fresnel) * (1.0 - b.transmission);
    let wt = (1.0 - b.fresnel) * b.transmission;
    // specular: the half vector's density D·(n·h), mapped to w by 1 / (4 |v·h|); a half
    // vector on the far side of v (v·h < 0) also reflects into w, but nothing is reflected
    // then (the sampler still draws such directions)
    var spec = 0.0;
    var spec_pdf = 0.0;
    let hv = v + w;
    if (dot(hv, hv) > 1e-12) {
        var h = normalize(hv);
        if (dot(b.n, h) < 0.0) {
            h = -h;
        }
        let nh = dot(b.n, h);
        let vh = dot(v, h);
        let dd = ggx_d(nh, a2);
        spec_pdf = dd * nh / (4.0 * max(abs(vh), 1e-6));
        if (cl > 0.0 && vh > 0.0) {
            spec = dd * smith_g1(cv, a2) * smith_g1(cl, a2) / (4.0 * cv);
        }
    }
    let diff_pdf = max(cl, 0.0) / PI;
    let trans_pdf = (b.exponent + 1.0) / (2.0 * PI) * pow(max(dot(d, w), 0.0), b.exponent);
    let trans = select(0.0, trans_pdf, cl < 0.0);
    let value = ws * spec + b.color * (wd * diff_pdf + wt * trans);
    return vec4<f32>(value, ws * spec_pdf + wd * diff_pdf + wt * trans_pdf);
}

// A direction drawn from the mixture of the three lobes (density: bsdf_eval(...).a); u.x
// picks the lobe, u.yz the direction in it.
fn bsdf_sample(b: Bsdf, d: vec3<f32>, u: vec3<f32>) -> vec3<f32> {
    let v = -d;
    if (u.x < b.fresnel) {
        // GGX: cos²θh = (1 − u) / (1 + (α² − 1) u)
        let a2 = b.alpha * b.alpha;
        let c2 = (1.0 - u.y) / (1.0 + (a2 - 1.0) * u.y);
        let c = sqrt(max(c2, 0.0));
        let s = sqrt(max(1.0 - c2, 0.0));
        let phi = 2.0 * PI * u.z;
        let h = basis_around(b.n) * vec3<f32>(s * cos(phi), s * sin(phi), c);
        return reflect(-v, h);
    }
    if (u.x < b.fresnel + (1.0 - b.fresnel) * (1.0 - b.transmission)) {
        return basis_around(b.n) * cosine_hemisphere(u.yz);
    }
    return basis_around(d) * phong_lobe(u.yz, b.exponent);
}
