//! The f64 CPU reference of the ray caster: pixel rays as the renderer defines them, the
//! volume sampled, differentiated and classified as the shaders do, the headlight's Phong
//! shading, and the composite ray integral.

use ferrovol_core::*;
use glam::DVec3;

/// Continuous pixel coordinates (pixel (i, j) covers [i, i+1) × [j, j+1), rows top to
/// bottom) of a world point.
pub fn to_pixel(view: &View, p: DVec3) -> (f64, f64) {
    let c = view.camera.view_projection(view.aspect()) * p.extend(1.0);
    let n = c.truncate() / c.w;
    (
        (n.x + 1.0) * 0.5 * view.width as f64,
        (1.0 - n.y) * 0.5 * view.height as f64,
    )
}

/// The ray of pixel (x, y) as the renderer defines it: through the pixel centre, from the
/// near plane (t = 0) to the far plane (t = far), t in world units.
pub struct Ray {
    pub origin: DVec3,
    pub dir: DVec3,
    pub far: f64,
}

pub fn pixel_ray(view: &View, x: u32, y: u32) -> Ray {
    let inv = view.camera.view_projection(view.aspect()).inverse();
    let nx = 2.0 * (x as f64 + 0.5) / view.width as f64 - 1.0;
    let ny = 1.0 - 2.0 * (y as f64 + 0.5) / view.height as f64;
    let near = inv.project_point3(DVec3::new(nx, ny, -1.0));
    let far = inv.project_point3(DVec3::new(nx, ny, 1.0));
    let len = (far - near).length();
    Ray {
        origin: near,
        dir: (far - near) / len,
        far: len,
    }
}

/// Entry and exit of the ray o + t·d through the box [lo, hi]; (∞, −∞) on a miss.
pub fn box_interval(o: DVec3, d: DVec3, lo: DVec3, hi: DVec3) -> (f64, f64) {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for a in 0..3 {
        if d[a] == 0.0 {
            if o[a] < lo[a] || o[a] > hi[a] {
                return (f64::INFINITY, f64::NEG_INFINITY);
            }
            continue;
        }
        let (u, v) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
        t0 = t0.max(u.min(v));
        t1 = t1.min(u.max(v));
    }
    (t0, t1)
}

/// The volume's index-space box [0, dims − 1].
pub fn index_box(v: &VolumeData) -> (DVec3, DVec3) {
    (
        DVec3::ZERO,
        DVec3::new(
            v.dims[0] as f64 - 1.0,
            v.dims[1] as f64 - 1.0,
            v.dims[2] as f64 - 1.0,
        ),
    )
}

/// The part of a pixel's ray inside the volume, clamped to the near and far planes.
pub fn ray_segment(v: &VolumeData, ray: &Ray) -> (DVec3, DVec3, f64, f64) {
    let w2i = v.index_to_data().inverse();
    let io = w2i.transform_point3(ray.origin);
    let id = w2i.transform_vector3(ray.dir);
    let (lo, hi) = index_box(v);
    let (t0, t1) = box_interval(io, id, lo, hi);
    (io, id, t0.max(0.0), t1.min(ray.far))
}

/// The piecewise-linear function at x in f64 (constant beyond its end points).
pub fn eval_pw<const N: usize>(f: &Piecewise<N>, x: f64) -> [f64; N] {
    let p = &f.points;
    let to64 = |v: [f32; N]| v.map(|c| c as f64);
    if x <= p[0].0 {
        return to64(p[0].1);
    }
    if x >= p[p.len() - 1].0 {
        return to64(p[p.len() - 1].1);
    }
    let i = p.partition_point(|q| q.0 <= x);
    let (x0, v0) = p[i - 1];
    let (x1, v1) = p[i];
    let f = if x1 > x0 { (x - x0) / (x1 - x0) } else { 1.0 };
    let mut out = [0.0; N];
    for c in 0..N {
        out[c] = v0[c] as f64 + (v1[c] as f64 - v0[c] as f64) * f;
    }
    out
}

/// Trilinear interpolation at index-space point p, clamped to the edge (the texture
/// sampler's ClampToEdge: texel centres at integer p).
pub fn trilinear(v: &VolumeData, p: DVec3) -> f64 {
    let mut i0 = [0u32; 3];
    let mut f = [0.0; 3];
    for a in 0..3 {
        let n = v.dims[a];
        let x = p[a].clamp(0.0, (n - 1) as f64);
        let fl = (x.floor() as u32).min(n.saturating_sub(2));
        i0[a] = fl;
        f[a] = x - fl as f64;
    }
    let at = |di: u32, dj: u32, dk: u32| {
        let i = (i0[0] + di).min(v.dims[0] - 1);
        let j = (i0[1] + dj).min(v.dims[1] - 1);
        let k = (i0[2] + dk).min(v.dims[2] - 1);
        v.value(i, j, k, 0)
    };
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    let c00 = lerp(at(0, 0, 0), at(1, 0, 0), f[0]);
    let c10 = lerp(at(0, 1, 0), at(1, 1, 0), f[0]);
    let c01 = lerp(at(0, 0, 1), at(1, 0, 1), f[0]);
    let c11 = lerp(at(0, 1, 1), at(1, 1, 1), f[0]);
    lerp(lerp(c00, c10, f[1]), lerp(c01, c11, f[1]), f[2])
}

/// The voxel a nearest-neighbour fetch at index-space point p takes: floor(p + 0.5),
/// clamped to the grid (shaders/lib/volume.wgsl sample_texel with NEAREST).
pub fn nearest_voxel(v: &VolumeData, p: DVec3) -> [i64; 3] {
    std::array::from_fn(|a| ((p[a] + 0.5).floor() as i64).clamp(0, v.dims[a] as i64 - 1))
}

/// The value of voxel c, its index clamped to the grid (the shader's `texel`).
pub fn voxel(v: &VolumeData, c: [i64; 3]) -> f64 {
    let [i, j, k] = std::array::from_fn(|a| c[a].clamp(0, v.dims[a] as i64 - 1) as u32);
    v.value(i, j, k, 0)
}

/// The cubic B-spline of the points at index-space point p, the grid clamped at its edges
/// (the texture sampler's ClampToEdge).
pub fn cubic_bspline(v: &VolumeData, p: DVec3) -> f64 {
    let weights = |f: f64| {
        let g = 1.0 - f;
        [
            g * g * g / 6.0,
            (4.0 - 6.0 * f * f + 3.0 * f * f * f) / 6.0,
            (4.0 - 6.0 * g * g + 3.0 * g * g * g) / 6.0,
            f * f * f / 6.0,
        ]
    };
    let base: [i64; 3] = std::array::from_fn(|a| p[a].floor() as i64 - 1);
    let w: [[f64; 4]; 3] = std::array::from_fn(|a| weights(p[a] - p[a].floor()));
    let mut sum = 0.0;
    for k in 0..4 {
        for j in 0..4 {
            for i in 0..4 {
                let c = [base[0] + i as i64, base[1] + j as i64, base[2] + k as i64];
                sum += w[0][i] * w[1][j] * w[2][k] * voxel(v, c);
            }
        }
    }
    sum
}

/// The scalar the renderer samples at index-space point p.
pub fn sample(v: &VolumeData, p: DVec3, interp: Interpolation) -> f64 {
    match interp {
        Interpolation::Linear => trilinear(v, p),
        Interpolation::Nearest => voxel(v, nearest_voxel(v, p)),
        Interpolation::Cubic => cubic_bspline(v, p),
    }
}

/// Index-space gradient at p. Central differences: of the interpolated field one index step
/// either side (linear), or of the nearest voxel's six neighbours (nearest, as
/// shaders/lib/volume.wgsl gradient_at: one rounding for all six). Forward differences: one
/// step ahead against p itself.
pub fn gradient(v: &VolumeData, p: DVec3, interp: Interpolation, method: GradientMethod) -> DVec3 {
    let e = [DVec3::X, DVec3::Y, DVec3::Z];
    let forward = method == GradientMethod::Forward;
    match interp {
        Interpolation::Linear | Interpolation::Cubic => {
            DVec3::from_array(std::array::from_fn(|a| {
                if forward {
                    trilinear(v, p + e[a]) - trilinear(v, p)
                } else {
                    0.5 * (trilinear(v, p + e[a]) - trilinear(v, p - e[a]))
                }
            }))
        }
        Interpolation::Nearest => {
            let c = nearest_voxel(v, p);
            DVec3::from_array(std::array::from_fn(|a| {
                let (mut lo, mut hi) = (c, c);
                hi[a] += 1;
                if forward {
                    voxel(v, hi) - voxel(v, c)
                } else {
                    lo[a] -= 1;
                    0.5 * (voxel(v, hi) - voxel(v, lo))
                }
            }))
        }
    }
}

/// Colour and opacity corrected for a step of `dt` of scalar s. Linear: the piecewise
/// functions themselves (the renderer's 1024-entry tables, read linearly, stand in for
/// them to a fraction of a level). Nearest: the table entry the renderer reads, entry
/// i = round(u·1023) of the table over the component's table range, which holds the
/// functions at x_i = lo + (hi − lo)·i/1023 (the transfer tables' build_tables,
/// shaders/lib/common.wgsl table_lookup).
pub fn classify(tf: &ComponentTransfer, s: f64, dt: f64, interp: Interpolation) -> ([f64; 3], f64) {
    let x = match interp {
        Interpolation::Linear | Interpolation::Cubic => s,
        Interpolation::Nearest => {
            let [lo, hi] = tf.table_range();
            let last = (TABLE_SIZE - 1) as f64;
            let u = ((s - lo) / (hi - lo)).clamp(0.0, 1.0);
            let i = (u * last + 0.5).floor();
            lo + (hi - lo) * i / last
        }
    };
    let a0 = eval_pw(&tf.opacity, x)[0].clamp(0.0, 1.0);
    let a = 1.0 - (1.0 - a0).powf(dt / tf.unit_distance);
    (eval_pw(&tf.color, x), a)
}

/// Phong shading as shaders/lib/shading.wgsl, for `view`'s headlight (at the camera,
/// lighting each sample along its ray as VTK's headlight path does; white
/// ambient/diffuse/specular, intensity 1).
pub fn shade(color: [f64; 3], grad: DVec3, view_dir: DVec3, s: &Shading) -> [f64; 3] {
    let glen = grad.length();
    let ambient = 1.0; // Σ lights' ambient colour: the headlight's is white
    let mut diffuse = 0.0;
    let mut specular = 0.0;
    if glen > 0.0 {
        let mut n = -grad / glen;
        let v = -view_dir;
        let l = v;
        let mut ndl = n.dot(l);
        if ndl < 0.0 && s.two_sided {
            n = -n;
            ndl = -ndl;
        }
        if ndl > 0.0 {
            diffuse += ndl;
            let r = 2.0 * ndl * n - l;
            let rdv = r.dot(v);
            if rdv > 0.0 {
                specular += rdv.powf(s.specular_power as f64);
            }
        }
    }
    color.map(|c| {
        (c * (s.ambient as f64 * ambient + s.diffuse as f64 * diffuse)
            + s.specular as f64 * specular)
            .clamp(0.0, 1.0)
    })
}

/// f64 reference of the composite ray integral: premultiplied RGBA per pixel in [0, 1]
/// and the window depth of the first sample with any opacity (1 where none). Samples,
/// gradients and the transfer function are interpolated as `p.interpolation` says.
pub fn render(
    v: &VolumeData,
    tf: &ComponentTransfer,
    view: &View,
    p: &RenderParams,
    dt: f64,
) -> (Vec<[f64; 4]>, Vec<f64>) {
    assert_eq!(
        view.lights.len(),
        1,
        "the reference knows the headlight only"
    );
    assert_eq!(view.lights[0].space, LightSpace::Headlight);
    let interp = p.interpolation;
    let cam = &view.camera;
    let w2i = v.index_to_data().inverse();
    let grad_to_world = w2i.transpose();
    let ert = p.termination_threshold as f64;
    let mut out = Vec::with_capacity((view.width * view.height) as usize);
    let mut depth = Vec::with_capacity(out.capacity());
    for y in 0..view.height {
        for x in 0..view.width {
            let ray = pixel_ray(view, x, y);
            let (io, id, t0, t1) = ray_segment(v, &ray);
            let mut acc = [0.0f64; 4];
            let mut d = 1.0;
            // VTK 9.2's lattice: the first sample one step inside (taken even when that is
            // past the exit, clamped to the edge), then every step up to and including the
            // exit.
            let mut k = 1.0;
            loop {
                let t = t0 + k * dt;
                if t0 >= t1 || (t > t1 && k > 1.0) {
                    break;
                }
                k += 1.0;
                let pi = io + t * id;
                let s = sample(v, pi, interp);
                let (mut rgb, a) = classify(tf, s, dt, interp);
                if a <= 0.0 {
                    continue;
                }
                if p.shading.enabled {
                    let g = gradient(v, pi, interp, p.gradient);
                    let gw = grad_to_world.transform_vector3(g);
                    rgb = shade(rgb, gw, ray.dir, &p.shading);
                }
                let w = (1.0 - acc[3]) * a;
                for c in 0..3 {
                    acc[c] += w * rgb[c];
                }
                acc[3] += w;
                if d == 1.0 && acc[3] > p.depth_threshold as f64 {
                    d = cam.window_depth(view.aspect(), ray.origin + t * ray.dir);
                }
                if acc[3] >= ert {
                    break;
                }
            }
            out.push(acc);
            depth.push(d);
        }
    }
    (out, depth)
}
