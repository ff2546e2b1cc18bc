// Directions and sample sets for image-based lighting, shared by the environment passes
// (environment.wgsl: cube build, mip chain, irradiance), the first-hit pass (ambient
// occlusion directions) and deferred shading (specular lobe sampling). No bindings here.
//
// Cube faces follow Vulkan's cube-map convention (the hardware's), in the layer order
// +X, −X, +Y, −Y, +Z, −Z; core/src/params/environment.rs mirrors `cube_direction` for the CPU.

const PI: f32 = 3.14159265358979;

// Direction (not normalised) through the point st ∈ [0, 1]² of cube face `face`, s to the
// right and t downwards in the face image.
fn cube_direction(face: u32, st: vec2<f32>) -> vec3<f32> {
    let sc = 2.0 * st.x - 1.0;
    let tc = 2.0 * st.y - 1.0;
    switch face {
        case 0u: { return vec3<f32>(1.0, -tc, -sc); }
        case 1u: { return vec3<f32>(-1.0, -tc, sc); }
        case 2u: { return vec3<f32>(sc, 1.0, tc); }
        case 3u: { return vec3<f32>(sc, -1.0, -tc); }
        case 4u: { return vec3<f32>(sc, -tc, 1.0); }
        default: { return vec3<f32>(-sc, -tc, -1.0); }
    }
}

// Van der Corput radical inverse in base 2.
fn radical_inverse(i: u32) -> f32 {
    return f32(reverseBits(i)) * 2.3283064365386963e-10;
}

// The i-th of n Hammersley points in [0, 1)², the first coordinate centred in its stratum
// (so no point sits on the pole or the horizon of the mappings below).
fn hammersley(i: u32, n: u32) -> vec2<f32> {
    return vec2<f32>((f32(i) + 0.5) / f32(n), radical_inverse(i));
}

// An orthonormal basis whose third column is the unit vector n (Duff et al., "Building an
// Orthonormal Basis, Revisited", JCGT 2017).
fn basis_around(n: vec3<f32>) -> mat3x3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let u = vec3<f32>(b, s + n.y * n.y * a, -n.y);
    return mat3x3<f32>(t, u, n);
}

// Local direction (z up) from u ∈ [0, 1)², cosine-weighted: pdf = cos θ / π.
fn cosine_hemisphere(u: vec2<f32>) -> vec3<f32> {
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(1.0 - u.x, 0.0)));
}

// Local direction (z up) from u ∈ [0, 1)², uniform over the hemisphere: pdf = 1 / (2π).
fn uniform_hemisphere(u: vec2<f32>) -> vec3<f32> {
    let z = u.x;
    let r = sqrt(max(1.0 - z * z, 0.0));
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(r * cos(phi), r * sin(phi), z);
}

// Local direction (z = the lobe axis) from u ∈ [0, 1)², distributed as the normalised Phong
// lobe cos^s θ: pdf = (s + 1) / (2π) · cos^s θ.
fn phong_lobe(u: vec2<f32>, s: f32) -> vec3<f32> {
    let c = pow(u.x, 1.0 / (s + 1.0));
    let r = sqrt(max(1.0 - c * c, 0.0));
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(r * cos(phi), r * sin(phi), c);
}

// Mip level for a sample of pdf `pdf` (per steradian) among n: the level whose texels
// cover the solid angle the sample stands for (Colbert & Křivánek, "GPU-Based Importance
// Sampling", GPU Gems 3, ch. 20: ½·log2(Ωs / Ωp) + 1). `texel_sr` is a texel's solid angle
// at level 0.
fn filtered_lod(pdf: f32, n: u32, texel_sr: f32, max_lod: f32) -> f32 {
    let omega_s = 1.0 / (f32(n) * max(pdf, 1e-8));
    return clamp(0.5 * log2(omega_s / texel_sr) + 1.0, 0.0, max_lod);
}
