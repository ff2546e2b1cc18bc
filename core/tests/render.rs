//! End-to-end accuracy tests of the ray caster on a real wgpu device (lavapipe on CI).
//!
//! Every test prints what it measured and asserts a tolerance with the reason for it.
//! Images of the interesting cases go to `target/test-images/*.png` for inspection.

use ferrovol_core::*;
use glam::DVec3;
mod common;

use common::{renderer, volume};

// ---------------------------------------------------------------------------------------
// Shared device and helpers
// ---------------------------------------------------------------------------------------

/// Two overlapping Gaussian blobs, smooth, values in [0, 1]: a volume with gradients in
/// every direction and both soft and steep parts of the transfer function.
fn blob_volume(n: u32) -> VolumeData {
    let m = (n - 1) as f64;
    volume([n; 3], |x, y, z| {
        let g = |c: [f64; 3], s: f64| {
            let r2 = (x - c[0] * m).powi(2) + (y - c[1] * m).powi(2) + (z - c[2] * m).powi(2);
            (-r2 / (2.0 * (s * m).powi(2))).exp()
        };
        (0.95 * g([0.45, 0.5, 0.55], 0.22) + 0.7 * g([0.72, 0.35, 0.4], 0.1)).min(1.0)
    })
}

fn piecewise3(points: &[(f64, [f32; 3])]) -> Piecewise<3> {
    Piecewise::new(points.to_vec()).expect("finite points")
}

fn piecewise1(points: &[(f64, f32)]) -> Piecewise<1> {
    Piecewise::new(points.iter().map(|&(x, a)| (x, [a])).collect()).expect("finite points")
}

/// The colourful, semi-transparent transfer function used with [`blob_volume`].
fn blob_transfer() -> ComponentTransfer {
    let mut c = ComponentTransfer::new(
        piecewise3(&[
            (0.05, [0.2, 0.3, 0.9]),
            (0.5, [0.9, 0.6, 0.2]),
            (1.0, [1.0, 1.0, 0.9]),
        ]),
        piecewise1(&[(0.05, 0.0), (0.5, 0.25), (1.0, 0.7)]),
    );
    c.unit_distance = 3.0;
    c
}

fn shaded() -> RenderParams {
    RenderParams {
        shading: Shading {
            enabled: true,
            ..Shading::default()
        },
        ..RenderParams::default()
    }
}

/// Writes `target/test-images/NAME.png` over black, enlarged (nearest) to about 256 px so
/// small test images can be looked at.
fn save(img: &Image, name: &str) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/test-images");
    std::fs::create_dir_all(&dir).expect("creating target/test-images");
    let f = (256 / img.width.max(img.height)).max(1);
    let (w, h) = (img.width * f, img.height * f);
    let mut big = Image {
        width: w,
        height: h,
        rgba: Vec::with_capacity((4 * w * h) as usize),
        depth: vec![1.0; (w * h) as usize],
    };
    for y in 0..h {
        for x in 0..w {
            big.rgba.extend_from_slice(&rgba(img, x / f, y / f));
        }
    }
    big.save_png(&dir.join(format!("{name}.png")), [0.0; 3])
        .expect("writing a test image");
}

fn rgba(img: &Image, x: u32, y: u32) -> [u8; 4] {
    let i = 4 * (y * img.width + x) as usize;
    [
        img.rgba[i],
        img.rgba[i + 1],
        img.rgba[i + 2],
        img.rgba[i + 3],
    ]
}

fn alpha(img: &Image, x: u32, y: u32) -> u8 {
    rgba(img, x, y)[3]
}

/// Pixels with any opacity.
fn footprint(img: &Image) -> usize {
    img.rgba.chunks(4).filter(|p| p[3] > 0).count()
}

/// (mean, max) absolute difference per channel, in 0–255 units.
fn image_diff(a: &Image, b: &Image) -> (f64, u8) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let mut sum = 0u64;
    let mut max = 0u8;
    for (x, y) in a.rgba.iter().zip(&b.rgba) {
        let d = x.abs_diff(*y);
        sum += d as u64;
        max = max.max(d);
    }
    (sum as f64 / a.rgba.len() as f64, max)
}

/// Continuous pixel coordinates (pixel (i, j) covers [i, i+1) × [j, j+1), rows top to
/// bottom) of a world point.
fn to_pixel(view: &View, p: DVec3) -> (f64, f64) {
    let c = view.camera.view_projection(view.aspect()) * p.extend(1.0);
    let n = c.truncate() / c.w;
    (
        (n.x + 1.0) * 0.5 * view.width as f64,
        (1.0 - n.y) * 0.5 * view.height as f64,
    )
}

/// The ray of pixel (x, y) as the renderer defines it: through the pixel centre, from the
/// near plane (t = 0) to the far plane (t = far), t in world units.
struct Ray {
    origin: DVec3,
    dir: DVec3,
    far: f64,
}

fn pixel_ray(view: &View, x: u32, y: u32) -> Ray {
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
fn box_interval(o: DVec3, d: DVec3, lo: DVec3, hi: DVec3) -> (f64, f64) {
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
fn index_box(v: &VolumeData) -> (DVec3, DVec3) {
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
fn ray_segment(v: &VolumeData, ray: &Ray) -> (DVec3, DVec3, f64, f64) {
    let w2i = v.index_to_data().inverse();
    let io = w2i.transform_point3(ray.origin);
    let id = w2i.transform_vector3(ray.dir);
    let (lo, hi) = index_box(v);
    let (t0, t1) = box_interval(io, id, lo, hi);
    (io, id, t0.max(0.0), t1.min(ray.far))
}

// ---------------------------------------------------------------------------------------
// f64 CPU reference of the composite integral
// ---------------------------------------------------------------------------------------

fn eval_pw<const N: usize>(f: &Piecewise<N>, x: f64) -> [f64; N] {
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
fn trilinear(v: &VolumeData, p: DVec3) -> f64 {
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
fn nearest_voxel(v: &VolumeData, p: DVec3) -> [i64; 3] {
    std::array::from_fn(|a| ((p[a] + 0.5).floor() as i64).clamp(0, v.dims[a] as i64 - 1))
}

/// The value of voxel c, its index clamped to the grid (the shader's `texel`).
fn voxel(v: &VolumeData, c: [i64; 3]) -> f64 {
    let [i, j, k] = std::array::from_fn(|a| c[a].clamp(0, v.dims[a] as i64 - 1) as u32);
    v.value(i, j, k, 0)
}

/// The scalar the renderer samples at index-space point p.
fn sample(v: &VolumeData, p: DVec3, interp: Interpolation) -> f64 {
    match interp {
        Interpolation::Linear => trilinear(v, p),
        Interpolation::Nearest => voxel(v, nearest_voxel(v, p)),
    }
}

/// Index-space gradient at p. Central differences: of the interpolated field one index step
/// either side (linear), or of the nearest voxel's six neighbours (nearest, as
/// shaders/lib/volume.wgsl gradient_at: one rounding for all six). Forward differences: one
/// step ahead against p itself.
fn gradient(v: &VolumeData, p: DVec3, interp: Interpolation, method: GradientMethod) -> DVec3 {
    let e = [DVec3::X, DVec3::Y, DVec3::Z];
    let forward = method == GradientMethod::Forward;
    match interp {
        Interpolation::Linear => DVec3::from_array(std::array::from_fn(|a| {
            if forward {
                trilinear(v, p + e[a]) - trilinear(v, p)
            } else {
                0.5 * (trilinear(v, p + e[a]) - trilinear(v, p - e[a]))
            }
        })),
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
/// functions at x_i = lo + (hi − lo)·i/1023 (core/src/transfer.rs build_tables,
/// shaders/lib/common.wgsl table_lookup).
fn classify(tf: &ComponentTransfer, s: f64, dt: f64, interp: Interpolation) -> ([f64; 3], f64) {
    let x = match interp {
        Interpolation::Linear => s,
        Interpolation::Nearest => {
            let [lo, hi] = tf.table_range();
            let last = (transfer::TABLE_SIZE - 1) as f64;
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
fn cpu_shade(color: [f64; 3], grad: DVec3, view_dir: DVec3, s: &Shading) -> [f64; 3] {
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
fn cpu_render(
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
                    rgb = cpu_shade(rgb, gw, ray.dir, &p.shading);
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

// ---------------------------------------------------------------------------------------
// 1. Beer–Lambert through a homogeneous slab
// ---------------------------------------------------------------------------------------

#[test]
fn slab_opacity_matches_beer_lambert() {
    let mut r = renderer();
    // 9 × 9 points across, 33 along z: a slab L = 32 thick (points sit at index · spacing).
    let vol = volume([9, 9, 33], |_, _, _| 0.5);
    let l = 32.0;
    // Expected opacity 0.75 = 1 − (1 − α)^(L/u) with u = 8: α = 1 − 0.25^(1/4) ≈ 0.293.
    let u = 8.0;
    let a = 1.0 - 0.25f64.powf(u / l);
    let mut tf = ComponentTransfer::new(
        piecewise3(&[(0.0, [1.0; 3]), (1.0, [1.0; 3])]),
        piecewise1(&[(0.0, a as f32), (1.0, a as f32)]),
    );
    tf.unit_distance = u;
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    let mut view = View::fit(vol.bounds(), 33, 33);
    view.camera.parallel = true;
    view.camera.reset_clipping_range(vol.bounds());
    let sigma = -(1.0 - a).ln() / u;
    let expected = 1.0 - (-sigma * l).exp();
    // dt = 1 (the default, the spacing) and 0.5 divide L (32 and 64 samples); 0.3 does not
    // (107 samples, reaching 0.1 past L). The opacity stays far below the early
    // termination threshold, so every sample counts.
    for dt in [None, Some(0.5), Some(0.3)] {
        let params = RenderParams {
            sample_distance: dt,
            ..RenderParams::default()
        };
        let img = r.render_image(&view, &params).unwrap();
        let centre = rgba(&img, 16, 16);
        let got = centre[3] as f64 / 255.0;
        let rel = (got - expected).abs() / expected;
        // white, premultiplied: colour = opacity
        assert!(
            centre[..3].iter().all(|c| c.abs_diff(centre[3]) <= 1),
            "{centre:?}"
        );
        println!(
            "slab: dt {:.2}: opacity {got:.4} expected {expected:.4} (σ {sigma:.4}/unit, L {l}) rel err {rel:.4}",
            r.sample_distance(&params).unwrap()
        );
        if dt.is_none() {
            save(&img, "slab");
        }
        // 1%: the u8 output alone is ±0.5/255 = 0.26% of 0.75; what remains is the Riemann
        // sum's end effect (a last sample reaching at most dt·σ·(1 − O)/O ≈ 0.14% for 0.3).
        assert!(
            rel < 0.01,
            "slab opacity {got:.4} vs Beer–Lambert {expected:.4} (dt {dt:?})"
        );
    }
}

// ---------------------------------------------------------------------------------------
// 2. The image does not depend on the sample distance (opacity correction)
// ---------------------------------------------------------------------------------------

#[test]
fn sample_distance_invariance() {
    let mut r = renderer();
    let vol = synth::marschner_lobb(41);
    let mut tf = ComponentTransfer::new(
        piecewise3(&[
            (0.0, [0.2, 0.4, 1.0]),
            (0.5, [1.0, 1.0, 0.4]),
            (1.0, [1.0, 0.4, 0.3]),
        ]),
        piecewise1(&[(0.0, 0.0), (0.3, 0.0), (1.0, 0.6)]),
    );
    tf.unit_distance = 0.5;
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(tf.clone()))
        .unwrap();
    let mut view = View::fit(vol.bounds(), 64, 64);
    view.camera.azimuth(30.0);
    view.camera.elevation(20.0);
    view.camera.orthogonalize_view_up();
    view.camera.reset_clipping_range(vol.bounds());
    let d = vol.spacing[0];
    let imgs: Vec<Image> = [d, d / 2.0, d / 4.0]
        .iter()
        .map(|&s| {
            r.render_image(
                &view,
                &RenderParams {
                    sample_distance: Some(s),
                    ..shaded()
                },
            )
            .unwrap()
        })
        .collect();
    save(&imgs[0], "ml_dt1");
    save(&imgs[2], "ml_dt4");
    assert!(
        footprint(&imgs[0]) > 1000,
        "the Marschner–Lobb image is almost empty"
    );
    let mut means = Vec::new();
    for (i, name) in [(0, "d vs d/4"), (1, "d/2 vs d/4")] {
        let (mean, max) = image_diff(&imgs[i], &imgs[2]);
        let mut d: Vec<u8> = imgs[i]
            .rgba
            .iter()
            .zip(&imgs[2].rgba)
            .map(|(a, b)| a.abs_diff(*b))
            .collect();
        d.sort_unstable();
        let p99 = d[d.len() * 99 / 100];
        println!("sample distance invariance: {name}: mean abs diff {mean:.3}/255, 99th percentile {p99}/255, max {max}/255");
        // Opacity correction removes the O(1) dependence on dt (16 levels on average here
        // without it, see below); what remains is the Riemann sum's O(dt) discretisation
        // error. The signal's rings are ~3 samples apart at d, so on average the images
        // agree to under a level and 99% of channels to a few levels; the worst pixel (a
        // ring seen edge-on, where a sample more or less of a thin shell falls inside) may
        // move by up to ~10%.
        assert!(mean < 1.0, "{name}: mean abs diff {mean:.3}");
        assert!(p99 <= 8, "{name}: 99th percentile abs diff {p99}");
        assert!(max <= 24, "{name}: max abs diff {max}");
        means.push(mean);
    }
    // and the difference shrinks as the sampling is refined (first order: d/2 vs d/4 is
    // about a third of d vs d/4)
    assert!(means[1] < 0.6 * means[0], "no convergence: {means:?}");

    // What the tolerance guards against: without opacity correction the samples at d/4
    // would keep the opacity meant for d, as with the unit distance divided by 4.
    tf.unit_distance /= 4.0;
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    let params = RenderParams {
        sample_distance: Some(d / 4.0),
        ..shaded()
    };
    let uncorrected = r.render_image(&view, &params).unwrap();
    let (mean_u, max_u) = image_diff(&imgs[0], &uncorrected);
    println!("sample distance invariance: d vs d/4 without opacity correction would differ by mean {mean_u:.3}/255, max {max_u}/255");
    assert!(
        mean_u > 5.0 * means[0],
        "the test cannot tell corrected from uncorrected"
    );
}

// ---------------------------------------------------------------------------------------
// 3. Early ray termination changes nothing visible
// ---------------------------------------------------------------------------------------

#[test]
fn early_termination_agrees() {
    let mut r = renderer();
    let vol = synth::marschner_lobb(41);
    let mut tf = ComponentTransfer::new(
        piecewise3(&[(0.0, [0.2, 0.4, 1.0]), (1.0, [1.0, 0.8, 0.3])]),
        piecewise1(&[(0.2, 0.0), (1.0, 1.0)]),
    );
    tf.unit_distance = 0.1;
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    let view = View::fit(vol.bounds(), 64, 64);
    let on = r.render_image(&view, &shaded()).unwrap();
    let off = r
        .render_image(
            &view,
            &RenderParams {
                termination_threshold: 1.0,
                ..shaded()
            },
        )
        .unwrap();
    save(&on, "early_termination");
    let opaque = on.rgba.chunks(4).filter(|p| p[3] >= 254).count();
    let (mean, max) = image_diff(&on, &off);
    println!(
        "early termination: {opaque} pixels terminate; mean abs diff {mean:.4}/255, max {max}/255"
    );
    assert!(
        opaque > 500,
        "the scene must be opaque enough for termination to happen"
    );
    // Rays stop once α ≥ 1 − 1/255, so what they skip adds at most (1 − α)·1 ≤ 1/255 to any
    // channel; the u8 rounding of the two results can add one more level.
    assert!(max <= 2, "max abs diff {max}/255");
}

// ---------------------------------------------------------------------------------------
// 4. MIP / MinIP find a planted extremum where it projects
// ---------------------------------------------------------------------------------------

fn brightest(img: &Image) -> (u32, u32, u8) {
    let mut best = (0, 0, 0u8);
    for y in 0..img.height {
        for x in 0..img.width {
            let p = rgba(img, x, y);
            if p[0] > best.2 {
                best = (x, y, p[0]);
            }
        }
    }
    best
}

fn check_planted(img: &Image, at: (f64, f64), label: &str) {
    let (bx, by, bv) = brightest(img);
    let dist = ((bx as f64 + 0.5 - at.0).powi(2) + (by as f64 + 0.5 - at.1).powi(2)).sqrt();
    // farthest-away bright pixel: nothing but the plant may light up
    let mut stray = 0u8;
    for y in 0..img.height {
        for x in 0..img.width {
            let d = ((x as f64 + 0.5 - at.0).powi(2) + (y as f64 + 0.5 - at.1).powi(2)).sqrt();
            if d > 6.0 {
                stray = stray.max(rgba(img, x, y)[0]);
            }
        }
    }
    println!(
        "{label}: brightest pixel ({bx}, {by}) = {bv}/255, planted voxel projects to ({:.2}, {:.2}), {dist:.2} px away; brightest pixel > 6 px away {stray}/255",
        at.0, at.1
    );
    // The pixel whose centre is nearest the projection passes within half a pixel (~0.45
    // voxel) of the planted voxel, and samples are 0.9 apart: its ray meets a point within
    // about half a voxel of the peak on every axis, where trilinear interpolation gives at
    // least 0.6 + 0.4·0.5³ = 0.65, more than any ray through the 0.6 shell alone can see.
    // The blob is ~3 px wide, so the brightest pixel must be within 1.5 px of the projection.
    assert!(
        dist <= 1.5,
        "{label}: brightest pixel {dist:.2} px from the planted voxel"
    );
    assert!(
        bv as f64 >= 0.65 * 255.0,
        "{label}: planted maximum shows as {bv}/255"
    );
    assert!(
        stray <= 2,
        "{label}: {stray}/255 far from the planted voxel"
    );
}

#[test]
fn mip_finds_planted_maximum() {
    let mut r = renderer();
    let n = 32u32;
    let plant = [20u32, 9, 14];
    // a 3×3×3 blob: 1 at the centre, 0.6 around it, so linear interpolation keeps the peak
    let field = |x: f64, y: f64, z: f64| {
        let d = [
            x - plant[0] as f64,
            y - plant[1] as f64,
            z - plant[2] as f64,
        ];
        if d.iter().all(|c| *c == 0.0) {
            1.0
        } else if d.iter().all(|c| c.abs() <= 1.0) {
            0.6
        } else {
            0.0
        }
    };
    let vol = volume([n; 3], field).with_spacing([1.0, 1.2, 0.9]).unwrap();
    let mut view = View::fit(vol.bounds(), 64, 64);
    view.camera.azimuth(25.0);
    view.camera.elevation(15.0);
    view.camera.orthogonalize_view_up();
    view.camera.reset_clipping_range(vol.bounds());
    let world = vol.index_to_data().transform_point3(DVec3::new(
        plant[0] as f64,
        plant[1] as f64,
        plant[2] as f64,
    ));
    let at = to_pixel(&view, world);

    r.set_volume(&vol).unwrap();
    // white, opacity = value: a pixel shows the maximum it found as its grey level
    let tf = ComponentTransfer::new(
        piecewise3(&[(0.0, [1.0; 3]), (1.0, [1.0; 3])]),
        piecewise1(&[(0.0, 0.0), (1.0, 1.0)]),
    );
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    let mip = r
        .render_image(
            &view,
            &RenderParams {
                blend: BlendMode::Maximum,
                ..RenderParams::default()
            },
        )
        .unwrap();
    save(&mip, "mip");
    check_planted(&mip, at, "MIP");

    // MinIP of the inverted volume with an inverted opacity map shows the same picture.
    let inv = volume([n; 3], |x, y, z| 1.0 - field(x, y, z))
        .with_spacing([1.0, 1.2, 0.9])
        .unwrap();
    let tf = ComponentTransfer::new(
        piecewise3(&[(0.0, [1.0; 3]), (1.0, [1.0; 3])]),
        piecewise1(&[(0.0, 1.0), (1.0, 0.0)]),
    );
    r.set_volume(&inv).unwrap();
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    let img = r
        .render_image(
            &view,
            &RenderParams {
                blend: BlendMode::Minimum,
                ..RenderParams::default()
            },
        )
        .unwrap();
    save(&img, "minip");
    check_planted(&img, at, "MinIP");
    // min(1 − v) = 1 − max(v), and the opacity map is mirrored: the same picture
    let (mean, max) = image_diff(&mip, &img);
    println!("MIP vs MinIP of the inverted volume: mean abs diff {mean:.4}/255, max {max}/255");
    assert!(
        max <= 1,
        "MIP and MinIP pictures differ by {max}/255 (1 − v rounds in f32)"
    );
}

// ---------------------------------------------------------------------------------------
// 5. A camera inside the volume
// ---------------------------------------------------------------------------------------

#[test]
fn camera_inside_volume() {
    let mut r = renderer();
    let ball = |c: [f64; 3]| {
        move |x: f64, y: f64, z: f64| {
            let d = ((x - c[0]).powi(2) + (y - c[1]).powi(2) + (z - c[2]).powi(2)).sqrt();
            ((5.0 - d) / 2.0).clamp(0.0, 1.0)
        }
    };
    let mut tf = ComponentTransfer::new(
        piecewise3(&[(0.0, [1.0, 0.6, 0.2]), (1.0, [1.0, 0.9, 0.6])]),
        piecewise1(&[(0.2, 0.0), (1.0, 1.0)]),
    );
    tf.unit_distance = 0.5;
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    let mut view = View::fit([0.0, 32.0, 0.0, 32.0, 0.0, 32.0], 64, 64);
    // the camera at the centre of the volume, looking down −z with a 60° view angle
    view.camera.position = DVec3::new(16.0, 16.0, 16.0);
    view.camera.focal_point = DVec3::new(16.0, 16.0, 0.0);
    view.camera.view_up = DVec3::Y;
    view.camera.view_angle = 60.0;
    view.camera
        .reset_clipping_range([0.0, 32.0, 0.0, 32.0, 0.0, 32.0]);

    // a ball ahead of the camera (z = 6 < 16)
    let ahead = volume([33; 3], ball([16.0, 16.0, 6.0]));
    r.set_volume(&ahead).unwrap();
    let img = r.render_image(&view, &shaded()).unwrap();
    save(&img, "camera_inside_ahead");
    let fp = footprint(&img);
    let centre = rgba(&img, 32, 32);
    let depth = img.depth[(32 * 64 + 32) as usize];
    // The ball's opacity starts where its value passes 0.2, at radius 4.6; seen from 10
    // away it subtends asin(0.46), in a 60° view 64 px high.
    let exp_radius_px = (0.46f64).asin().tan() / 30f64.to_radians().tan() * 32.0;
    let exp_fp = std::f64::consts::PI * exp_radius_px * exp_radius_px;
    println!("camera inside, ball ahead: footprint {fp} px (≈{exp_fp:.0} expected), centre pixel {centre:?}, depth {depth:.4}");
    assert!(
        centre[3] == 255 && centre[0] > 50,
        "the ball ahead must be visible: {centre:?}"
    );
    assert!(
        depth.is_finite() && depth > 0.0 && depth < 1.0,
        "depth {depth}"
    );
    // Footprint within ±10% of the projected ball: the rim's pixels (~180, 7%) may fall
    // either way, and only rays starting at the camera see exactly this disc.
    assert!(
        (fp as f64) > 0.9 * exp_fp && (fp as f64) < 1.1 * exp_fp,
        "footprint {fp}"
    );

    // the same ball behind the camera (z = 26 > 16): nothing to see
    let behind = volume([33; 3], ball([16.0, 16.0, 26.0]));
    r.set_volume(&behind).unwrap();
    let img = r.render_image(&view, &shaded()).unwrap();
    save(&img, "camera_inside_behind");
    let max = img.rgba.iter().max().copied().unwrap_or(0);
    println!(
        "camera inside, ball behind: footprint {}, max channel {max}",
        footprint(&img)
    );
    assert_eq!(max, 0, "structure behind the camera was rendered");
    assert!(
        img.depth.iter().all(|&d| d == 1.0),
        "depth must stay at 1 with nothing visible"
    );
}

// ---------------------------------------------------------------------------------------
// 6. Silhouettes of an opaque box
// ---------------------------------------------------------------------------------------

fn box_corners(lo: DVec3, hi: DVec3) -> [DVec3; 8] {
    std::array::from_fn(|c| {
        DVec3::new(
            if c & 1 != 0 { hi.x } else { lo.x },
            if c & 2 != 0 { hi.y } else { lo.y },
            if c & 4 != 0 { hi.z } else { lo.z },
        )
    })
}

/// First and last column, first and last row of the pixels whose centres fall inside the
/// bounding box of the projected points (world).
fn projected_extents(view: &View, points: [DVec3; 8]) -> [f64; 4] {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in points {
        let (px, py) = to_pixel(view, p);
        x0 = x0.min(px);
        x1 = x1.max(px);
        y0 = y0.min(py);
        y1 = y1.max(py);
    }
    [
        (x0 - 0.5).ceil(),
        (x1 - 0.5).floor(),
        (y0 - 0.5).ceil(),
        (y1 - 0.5).floor(),
    ]
}

/// First and last column, first and last row of a mask's set pixels.
fn mask_extents(mask: &[bool], w: u32, h: u32) -> Option<[f64; 4]> {
    let cols: Vec<u32> = (0..w)
        .filter(|&x| (0..h).any(|y| mask[(y * w + x) as usize]))
        .collect();
    let rows: Vec<u32> = (0..h)
        .filter(|&y| (0..w).any(|x| mask[(y * w + x) as usize]))
        .collect();
    Some([*cols.first()?, *cols.last()?, *rows.first()?, *rows.last()?].map(|v| v as f64))
}

/// Renders the whole volume as an opaque box and compares its silhouette with the
/// analytic one: per pixel (does the pixel's ray meet the box?) and by pixel extents of the
/// projected corners.
fn check_silhouette(vol: &VolumeData, view: &View, name: &str) {
    let mut r = renderer();
    r.set_volume(vol).unwrap();
    let tf = ComponentTransfer::new(
        piecewise3(&[(0.0, [1.0; 3]), (1.0, [1.0; 3])]),
        piecewise1(&[(0.0, 0.0), (0.5, 0.0), (0.51, 1.0), (1.0, 1.0)]),
    );
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    let img = r.render_image(view, &RenderParams::default()).unwrap();
    save(&img, name);
    let (w, h) = (view.width, view.height);
    // analytic mask: the pixel centre's ray meets the box
    let hit: Vec<bool> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let (_, _, t0, t1) = ray_segment(vol, &pixel_ray(view, x, y));
            t0 < t1
        })
        .collect();
    let gpu: Vec<bool> = img.rgba.chunks(4).map(|p| p[3] > 127).collect();
    let mut mismatches = 0;
    let mut off_edge = 0;
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let i = (y * w as i64 + x) as usize;
            if hit[i] != gpu[i] {
                mismatches += 1;
                let edge = (-1..=1).any(|dy| {
                    (-1..=1).any(|dx| {
                        let (u, v) = (x + dx, y + dy);
                        u >= 0
                            && v >= 0
                            && u < w as i64
                            && v < h as i64
                            && hit[(v * w as i64 + u) as usize] != hit[i]
                    })
                });
                if !edge {
                    off_edge += 1;
                }
            }
        }
    }
    let m = vol.index_to_data();
    let (lo, hi) = index_box(vol);
    let expect = projected_extents(view, box_corners(lo, hi).map(|p| m.transform_point3(p)));
    let got = mask_extents(&gpu, w, h).unwrap_or_else(|| panic!("{name}: empty silhouette"));
    let worst = (0..4)
        .map(|i| (got[i] - expect[i]).abs())
        .fold(0.0, f64::max);
    let area = gpu.iter().filter(|&&b| b).count();
    let area_exp = hit.iter().filter(|&&b| b).count();
    println!(
        "{name}: silhouette columns {}..{} rows {}..{} vs analytic {}..{} / {}..{}: worst {worst} px; {area} px vs {area_exp} analytic, {mismatches} differ ({off_edge} away from the edge)",
        got[0], got[1], got[2], got[3], expect[0], expect[1], expect[2], expect[3]
    );
    // Pixel extents agree to one pixel (a pixel centre lying within float rounding of an
    // edge may go either way); every differing pixel must lie on the silhouette's edge.
    assert!(worst <= 1.0, "{name}: extents off by {worst} px");
    assert_eq!(
        off_edge, 0,
        "{name}: {off_edge} pixels differ away from the silhouette edge"
    );
    assert!(
        mismatches * 50 <= area_exp,
        "{name}: {mismatches} of {area_exp} pixels differ"
    );
}

fn parallel_view(vol: &VolumeData, w: u32, h: u32, azimuth: f64, elevation: f64) -> View {
    let b = vol.bounds();
    let mut view = View::fit(b, w, h);
    view.camera.azimuth(azimuth);
    view.camera.elevation(elevation);
    view.camera.orthogonalize_view_up();
    view.camera.parallel = true;
    view.camera.reset_clipping_range(b);
    view
}

#[test]
fn parallel_projection_silhouette() {
    let vol = volume([17, 9, 13], |_, _, _| 1.0)
        .with_origin([-3.0, 2.0, 1.0])
        .unwrap();
    check_silhouette(
        &vol,
        &parallel_view(&vol, 96, 80, 35.0, 25.0),
        "silhouette_parallel",
    );
    check_silhouette(
        &vol,
        &parallel_view(&vol, 96, 80, 0.0, 0.0),
        "silhouette_parallel_front",
    );
}

#[test]
fn anisotropic_spacing_silhouette() {
    let vol = volume([16, 8, 6], |_, _, _| 1.0)
        .with_spacing([1.0, 2.0, 3.0])
        .unwrap();
    check_silhouette(
        &vol,
        &parallel_view(&vol, 96, 96, 30.0, 20.0),
        "silhouette_anisotropic",
    );
    check_silhouette(
        &vol,
        &parallel_view(&vol, 96, 96, 90.0, 0.0),
        "silhouette_anisotropic_side",
    );
}

#[test]
fn rotated_direction_silhouette() {
    let (s, c) = 30f64.to_radians().sin_cos();
    let rot = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
    let vol = volume([20, 10, 8], |_, _, _| 1.0)
        .with_direction(rot)
        .unwrap()
        .with_origin([4.0, -2.0, 0.0])
        .unwrap();
    // straight down z the silhouette is the rotated rectangle itself
    check_silhouette(
        &vol,
        &parallel_view(&vol, 96, 96, 0.0, 0.0),
        "silhouette_rotated",
    );
    check_silhouette(
        &vol,
        &parallel_view(&vol, 96, 96, 40.0, 30.0),
        "silhouette_rotated_oblique",
    );
}

// ---------------------------------------------------------------------------------------
// 7. The GPU image against an f64 CPU reference
// ---------------------------------------------------------------------------------------

/// Mean absolute error (0–255 units) and PSNR (dB) of the GPU image against the reference.
fn compare_to_reference(img: &Image, reference: &[[f64; 4]]) -> (f64, f64, f64) {
    let mut sum = 0.0;
    let mut sq = 0.0;
    let mut max: f64 = 0.0;
    for (p, q) in img.rgba.chunks(4).zip(reference) {
        for c in 0..4 {
            let e = (p[c] as f64 - q[c].clamp(0.0, 1.0) * 255.0).abs();
            sum += e;
            sq += e * e;
            max = max.max(e);
        }
    }
    let n = (img.rgba.len()) as f64;
    let mse = sq / n;
    (
        sum / n,
        10.0 * (255.0 * 255.0 / mse.max(1e-12)).log10(),
        max,
    )
}

fn reference_image(refc: &[[f64; 4]], w: u32, h: u32) -> Image {
    Image {
        width: w,
        height: h,
        rgba: refc
            .iter()
            .flat_map(|p| p.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
            .collect(),
        depth: vec![1.0; (w * h) as usize],
    }
}

#[test]
fn cpu_reference_composite_shaded() {
    let mut r = renderer();
    let aniso = blob_volume(24)
        .with_spacing([1.0, 0.8, 1.2])
        .unwrap()
        .with_origin([-5.0, 3.0, 0.5])
        .unwrap();
    // a direction matrix turning the grid about z then x: the gradient must follow it
    let m = glam::DMat3::from_rotation_z(30f64.to_radians())
        * glam::DMat3::from_rotation_x(40f64.to_radians());
    let dir: Direction = [0, 1, 2].map(|r| [0, 1, 2].map(|c| m.col(c)[r]));
    let rotated = aniso.clone().with_direction(dir).unwrap();
    // the same blob as 8-bit data (normalised texture storage), its transfer function
    // stretched to 0–255
    let base = blob_volume(24);
    let bytes = (0..base.num_points())
        .map(|i| (base.scalars.get(i) * 255.0).round() as u8)
        .collect();
    let u8vol = VolumeData::new(base.dims, 1, Scalars::U8(bytes))
        .unwrap()
        .with_spacing([1.0, 0.8, 1.2])
        .unwrap();
    let stretch = |f: &Piecewise<1>| {
        Piecewise::new(f.points.iter().map(|&(x, v)| (x * 255.0, v)).collect()).unwrap()
    };
    let tf = blob_transfer();
    let mut tf255 = tf.clone();
    tf255.opacity = stretch(&tf.opacity);
    tf255.color = Piecewise::new(
        tf.color
            .points
            .iter()
            .map(|&(x, v)| (x * 255.0, v))
            .collect(),
    )
    .unwrap();
    let central = GradientMethod::Central;
    let cases = [
        ("cpu_reference_front", &aniso, &tf, 0.0, 0.0, central),
        ("cpu_reference_oblique", &aniso, &tf, 35.0, -25.0, central),
        ("cpu_reference_rotated", &rotated, &tf, 20.0, 30.0, central),
        ("cpu_reference_u8", &u8vol, &tf255, 35.0, -25.0, central),
        (
            "cpu_reference_forward",
            &aniso,
            &tf,
            35.0,
            -25.0,
            GradientMethod::Forward,
        ),
    ];
    for (name, vol, tf, az, el, gradient) in cases {
        r.set_volume(vol).unwrap();
        r.set_transfer_function(&TransferFunction::single(tf.clone()))
            .unwrap();
        let mut view = View::fit(vol.bounds(), 64, 64);
        view.camera.azimuth(az);
        view.camera.elevation(el);
        view.camera.orthogonalize_view_up();
        view.camera.reset_clipping_range(vol.bounds());
        let params = RenderParams {
            gradient,
            ..shaded()
        };
        let dt = r.sample_distance(&params).unwrap();
        let img = r.render_image(&view, &params).unwrap();
        let (refc, _) = cpu_render(vol, tf, &view, &params, dt);
        save(&img, name);
        save(&reference_image(&refc, 64, 64), &format!("{name}_cpu"));
        let (mae, psnr, max) = compare_to_reference(&img, &refc);
        let fp = footprint(&img);
        println!(
            "{name}: stored as {:?}, footprint {fp} px, mean abs error {mae:.3}/255, max {max:.1}/255, PSNR {psnr:.1} dB (dt {dt})",
            r.volume_format().unwrap()
        );
        assert!(fp > 400, "{name}: the image is almost empty ({fp} px)");
        // f32 arithmetic and texture filtering against f64, u8 output (±0.5), and the
        // 1024-entry tables standing in for the piecewise functions each cost a fraction of
        // a level; 35 dB (RMS < 4.5 levels) and a mean under 1.5 levels leave room for the
        // odd sample that lands on the other side of the ray's exit in f32 and for 8-bit
        // texture filtering.
        assert!(psnr >= 35.0, "{name}: PSNR {psnr:.1} dB");
        assert!(mae < 1.5, "{name}: mean abs error {mae:.3}/255");
        if gradient == GradientMethod::Forward {
            // the two methods differ by less than the bounds above: the image must also be
            // clearly nearer the forward reference than the central one
            let other = RenderParams {
                gradient: GradientMethod::Central,
                ..params.clone()
            };
            let (refc_central, _) = cpu_render(vol, tf, &view, &other, dt);
            let (_, psnr_central, _) = compare_to_reference(&img, &refc_central);
            println!("{name}: against central differences PSNR {psnr_central:.1} dB");
            assert!(
                psnr > psnr_central + 6.0,
                "{name}: forward differences not told from central ({psnr:.1} against {psnr_central:.1} dB)"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// 8. Bricking is invisible
// ---------------------------------------------------------------------------------------

#[test]
fn bricked_equals_unbricked() {
    let mut r = renderer();
    let vol = blob_volume(24);
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let b = vol.bounds();
    let mut views = Vec::new();
    let mut oblique = View::fit(b, 64, 64);
    oblique.camera.azimuth(30.0);
    oblique.camera.elevation(20.0);
    oblique.camera.orthogonalize_view_up();
    oblique.camera.reset_clipping_range(b);
    views.push(("oblique", oblique));
    views.push(("front", View::fit(b, 64, 64)));
    let mut par = View::fit(b, 64, 64);
    par.camera.azimuth(-50.0);
    par.camera.elevation(10.0);
    par.camera.orthogonalize_view_up();
    par.camera.parallel = true;
    par.camera.reset_clipping_range(b);
    views.push(("parallel", par));
    let mut inside = View::fit(b, 64, 64);
    inside.camera.position = DVec3::new(16.5, 14.5, 15.0);
    inside.camera.focal_point = DVec3::new(5.0, 9.0, 6.0);
    inside.camera.view_angle = 70.0;
    inside.camera.orthogonalize_view_up();
    inside.camera.reset_clipping_range(b);
    views.push(("inside", inside));

    r.set_volume(&vol).unwrap();
    assert_eq!(r.brick_count(), 1);
    let whole: Vec<Image> = views
        .iter()
        .map(|(_, v)| r.render_image(v, &shaded()).unwrap())
        .collect();
    r.set_volume_with(
        &vol,
        UploadOptions {
            max_brick_points: Some(12),
            ..Default::default()
        },
    )
    .unwrap();
    let bricks = r.brick_count();
    assert!(bricks > 1);
    let mut failures = Vec::new();
    for ((name, v), one) in views.iter().zip(&whole) {
        let split = r.render_image(v, &shaded()).unwrap();
        let (mean, max) = image_diff(one, &split);
        let bad = one
            .rgba
            .iter()
            .zip(&split.rgba)
            .filter(|(a, b)| a.abs_diff(**b) > 2)
            .count();
        println!("bricked ({bricks} bricks) vs one brick, {name} view: mean abs diff {mean:.4}/255, max {max}/255, {bad} channels off by more than 2");
        save(one, &format!("bricked_{name}_one"));
        save(&split, &format!("bricked_{name}_split"));
        // Samples lie on the same per-ray lattice in every brick and bricks overlap by two
        // points, so only f32 rounding of a sample on a brick face (which brick takes it)
        // and of the per-brick ray setup differ: at most a level or two.
        if max > 2 {
            failures.push(format!(
                "{name}: max abs diff {max}/255 ({bad} channels > 2)"
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "bricked rendering differs: {failures:?}"
    );
}

// ---------------------------------------------------------------------------------------
// 9. Only what changed is uploaded
// ---------------------------------------------------------------------------------------

#[test]
fn incremental_updates() {
    let mut r = renderer();
    let vol = blob_volume(16);
    let before = r.stats();
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let mut view = View::fit(vol.bounds(), 32, 32);
    r.render_image(&view, &shaded()).unwrap();
    let s0 = r.stats();
    view.camera.azimuth(40.0);
    view.camera.elevation(10.0);
    view.camera.orthogonalize_view_up();
    r.render_image(&view, &shaded()).unwrap();
    let s1 = r.stats();
    let mut tf = blob_transfer();
    tf.opacity = piecewise1(&[(0.2, 0.0), (1.0, 0.9)]);
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    r.render_image(&view, &shaded()).unwrap();
    let s2 = r.stats();
    println!("stats: before {before:?}\n  after set_volume + first frame {s0:?}\n  after camera change {s1:?}\n  after transfer function change {s2:?}");
    assert_eq!(
        s0.volume_uploads,
        before.volume_uploads + 1,
        "set_volume uploads once"
    );
    assert_eq!(
        s1.volume_uploads, s0.volume_uploads,
        "a camera change re-uploaded the volume"
    );
    assert_eq!(
        s1.table_uploads, s0.table_uploads,
        "a camera change rebuilt the tables"
    );
    assert_eq!(
        s1.occupancy_updates, s0.occupancy_updates,
        "a camera change reclassified the occupancy grid"
    );
    assert_eq!(s1.frames, s0.frames + 1);
    assert_eq!(
        s2.volume_uploads, s1.volume_uploads,
        "a transfer function change re-uploaded the volume"
    );
    assert_eq!(
        s2.table_uploads,
        s1.table_uploads + 1,
        "a transfer function change must rebuild the tables once"
    );
    assert_eq!(s2.frames, s1.frames + 1);
}

// ---------------------------------------------------------------------------------------
// 10. Depth in, depth out
// ---------------------------------------------------------------------------------------

#[test]
fn depth_input_terminates_rays() {
    let mut r = renderer();
    let vol = blob_volume(24);
    let tf = blob_transfer();
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(tf.clone()))
        .unwrap();
    let b = vol.bounds();
    let view = View::fit(b, 64, 64); // looking down −z
    let zc = 0.5 * (b[4] + b[5]);
    // window depth of the plane z = zc, per pixel
    let depth_in: Vec<f32> = (0..64)
        .flat_map(|y| (0..64).map(move |x| (x, y)))
        .map(|(x, y)| {
            let ray = pixel_ray(&view, x, y);
            let t = (zc - ray.origin.z) / ray.dir.z;
            view.camera
                .window_depth(view.aspect(), ray.origin + t * ray.dir) as f32
        })
        .collect();
    let params = shaded();
    let full = r.render_image(&view, &params).unwrap();
    r.render(&view, &params, Some(&depth_in)).unwrap();
    let cut = r.read_image().unwrap();
    // the same cut made by a clipping plane keeping z ≥ zc (the half facing the camera)
    let clip = ClipPlane {
        origin: DVec3::new(0.0, 0.0, zc),
        normal: DVec3::Z,
    };
    let clipped = r
        .render_image(
            &view,
            &RenderParams {
                clip_planes: vec![clip],
                ..shaded()
            },
        )
        .unwrap();
    save(&full, "depth_full");
    save(&cut, "depth_cut");
    let sum = |img: &Image| img.rgba.chunks(4).map(|p| p[3] as u64).sum::<u64>();
    let (a_full, a_cut) = (sum(&full), sum(&cut));
    let c_full = alpha(&full, 32, 32);
    let c_cut = alpha(&cut, 32, 32);
    let (mean, max) = image_diff(&cut, &clipped);
    println!(
        "depth input: total alpha {a_full} → {a_cut}, centre alpha {c_full} → {c_cut}; vs clip plane at the same z: mean abs diff {mean:.4}/255, max {max}/255"
    );
    assert!(
        a_cut < a_full && c_cut < c_full,
        "the depth image did not terminate rays"
    );
    assert!(c_cut > 0, "the front half must still show");
    // The depth test and the clipping plane end the same rays at the same place; only the
    // f32 round trip of the depth value (≈1e-6 of the range) can move a sample across.
    assert!(
        max <= 2,
        "depth-terminated and clipped images differ by {max}/255"
    );

    // Depth output: < 1 where the volume is seen, 1 on the background, and at the first
    // sample with opacity, as the f64 reference finds it.
    let dt = r.sample_distance(&params).unwrap();
    let (_, ref_depth) = cpu_render(&vol, &tf, &view, &params, dt);
    let mut seen_but_far = 0;
    let mut bg_not_far = 0;
    let mut depth_err: f64 = 0.0;
    let mut compared = 0;
    let mut off_by_step = 0;
    for ((px, &d), &rd) in full.rgba.chunks(4).zip(&full.depth).zip(&ref_depth) {
        if px[3] > 0 && d >= 1.0 {
            seen_but_far += 1;
        }
        if rd == 1.0 && d != 1.0 {
            bg_not_far += 1;
        }
        if rd < 1.0 && d < 1.0 {
            let e = (rd - d as f64).abs();
            depth_err = depth_err.max(e);
            off_by_step += (e > 1e-4) as usize;
            compared += 1;
        }
    }
    // One sample step at the volume's front, in window depth: the most a sample decided
    // differently (an opacity just above zero in f32 but not in f64) can move the depth.
    let front = DVec3::new(11.5, 11.5, b[5]);
    let step = (view.camera.window_depth(1.0, front)
        - view.camera.window_depth(1.0, front - DVec3::Z * dt))
    .abs();
    println!(
        "depth output: {seen_but_far} visible pixels at depth 1, {bg_not_far} background pixels below 1, max |depth − reference| {depth_err:.2e} over {compared} px, {off_by_step} off by > 1e-4 (one step = {step:.2e})"
    );
    assert_eq!(seen_but_far, 0, "pixels with opacity but no depth");
    assert!(
        bg_not_far <= 20,
        "{bg_not_far} background pixels got a depth"
    );
    assert!(compared > 800, "only {compared} pixels with depth");
    // A sample whose opacity is just above zero through the 1024-entry table (a scalar a
    // fraction of an entry below the opacity function's first non-zero point) but zero in
    // f64 moves the depth by one step; nothing may move it further, and nearly all pixels
    // must agree to f32 precision.
    assert!(
        depth_err <= step * 1.01,
        "depth output off by {depth_err:.2e} (one step is {step:.2e})"
    );
    assert!(
        off_by_step * 50 <= compared,
        "{off_by_step} of {compared} depths differ by more than 1e-4"
    );
}

// ---------------------------------------------------------------------------------------
// 11. Errors name the problem
// ---------------------------------------------------------------------------------------

#[test]
fn errors() {
    let mut r = renderer();
    let good = blob_volume(8);

    let mut nan = good.clone();
    if let Scalars::F32(v) = &mut nan.scalars {
        v[3 + 8 * (2 + 8 * 5)] = f32::NAN;
    }
    let e = r.set_volume(&nan).unwrap_err().to_string();
    println!("NaN volume: {e}");
    assert!(e.contains("NaN") && e.contains("(3, 2, 5)"), "{e}");

    let mut flat = good.clone();
    flat.spacing = [1.0, 0.0, 1.0];
    let e = r.set_volume(&flat).unwrap_err().to_string();
    println!("zero spacing: {e}");
    assert!(e.contains("spacing along y"), "{e}");

    let e = VolumeData::new([4, 4, 4], 1, Scalars::F32(vec![0.0; 10]))
        .unwrap_err()
        .to_string();
    println!("wrong length: {e}");
    assert!(e.contains("expected 64"), "{e}");

    r.set_volume(&good).unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let view = View::fit(good.bounds(), 16, 16);
    let e = r
        .render(
            &view,
            &RenderParams {
                sample_distance: Some(0.0),
                ..Default::default()
            },
            None,
        )
        .unwrap_err()
        .to_string();
    println!("sample distance 0: {e}");
    assert!(e.contains("sample distance"), "{e}");
    let plane = ClipPlane {
        origin: DVec3::ZERO,
        normal: DVec3::X,
    };
    let e = r
        .render(
            &view,
            &RenderParams {
                clip_planes: vec![plane; 7],
                ..Default::default()
            },
            None,
        )
        .unwrap_err()
        .to_string();
    println!("7 clip planes: {e}");
    assert!(e.contains("7 clipping planes"), "{e}");
    let e = r
        .render(
            &view,
            &RenderParams {
                termination_threshold: 0.0,
                ..Default::default()
            },
            None,
        )
        .unwrap_err()
        .to_string();
    println!("termination threshold 0: {e}");
    assert!(e.contains("termination threshold"), "{e}");
    let e = r
        .render(
            &View {
                width: 0,
                ..view.clone()
            },
            &RenderParams::default(),
            None,
        )
        .unwrap_err()
        .to_string();
    println!("0-wide image: {e}");
    assert!(e.contains("image size"), "{e}");
    let e = r
        .render(&view, &RenderParams::default(), Some(&[0.5; 3]))
        .unwrap_err()
        .to_string();
    println!("short depth image: {e}");
    assert!(e.contains("depth image"), "{e}");
    let mut bad_tf = blob_transfer();
    bad_tf.unit_distance = 0.0;
    let e = r
        .set_transfer_function(&TransferFunction::single(bad_tf))
        .unwrap_err()
        .to_string();
    println!("unit distance 0: {e}");
    assert!(e.contains("unit distance"), "{e}");
    // the renderer still works after all that
    r.render_image(&view, &RenderParams::default()).unwrap();
    drop(r);

    // a fresh renderer: no volume, then no transfer function
    let mut fresh = Renderer::new(Context::new().unwrap()).unwrap();
    let e = fresh
        .render(&view, &RenderParams::default(), None)
        .unwrap_err()
        .to_string();
    println!("no volume: {e}");
    assert!(
        e.contains("no volume") || e.contains("no transfer function"),
        "{e}"
    );
    fresh.set_volume(&good).unwrap();
    let e = fresh
        .render(&view, &RenderParams::default(), None)
        .unwrap_err()
        .to_string();
    println!("no transfer function: {e}");
    assert!(e.contains("no transfer function"), "{e}");
    let e = fresh.read_image().unwrap_err().to_string();
    println!("read before render: {e}");
    assert!(e.contains("nothing has been rendered"), "{e}");
}

// ---------------------------------------------------------------------------------------
// 12. Other blend modes, cropping and clipping
// ---------------------------------------------------------------------------------------

#[test]
fn blend_modes_cropping_clipping() {
    let mut r = renderer();
    let vol = blob_volume(24);
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::ramp([0.0, 1.0], 0.8))
        .unwrap();
    let b = vol.bounds();
    let view = View::fit(b, 64, 64);
    let composite = r.render_image(&view, &RenderParams::default()).unwrap();
    let fp_composite = footprint(&composite);
    save(&composite, "blend_composite");

    for mode in [BlendMode::Average, BlendMode::Additive] {
        let img = r
            .render_image(
                &view,
                &RenderParams {
                    blend: mode,
                    ..RenderParams::default()
                },
            )
            .unwrap();
        save(&img, &format!("blend_{mode:?}").to_lowercase());
        // Every ray through the volume ends as an opaque grey: black where it met only
        // (nearly) transparent values, as in the blob's far corners.
        let mut grey = 0;
        let mut black = 0;
        let mut not_grey = 0;
        let mut brightest = 0u8;
        for p in img.rgba.chunks(4) {
            if p[3] > 0 {
                if p[0] != p[1] || p[1] != p[2] || p[3] != 255 {
                    not_grey += 1;
                } else if p[0] > 0 {
                    grey += 1;
                } else {
                    black += 1;
                }
                brightest = brightest.max(p[0]);
            }
        }
        let centre = rgba(&img, 32, 32);
        println!("{mode:?}: {grey} non-black grey pixels, {black} black, {not_grey} others, brightest {brightest}/255, centre {centre:?}");
        assert_eq!(
            not_grey, 0,
            "{mode:?}: a pixel with opacity is not an opaque grey"
        );
        // the blob shows over most of the volume's ~1760-pixel projection
        assert!(grey > 1000, "{mode:?}: only {grey} non-black grey pixels");
        assert!(
            centre[3] == 255 && centre[0] > 20,
            "{mode:?}: centre {centre:?}"
        );
        // rays that miss the volume stay empty
        assert_eq!(rgba(&img, 0, 0), [0; 4], "{mode:?}: background");
    }

    // cropping to the middle third keeps the centre and loses the rest
    let third = |a: usize| {
        (
            b[2 * a] + (b[2 * a + 1] - b[2 * a]) / 3.0,
            b[2 * a] + 2.0 * (b[2 * a + 1] - b[2 * a]) / 3.0,
        )
    };
    let (x, y, z) = (third(0), third(1), third(2));
    let crop = Cropping {
        planes: [x.0, x.1, y.0, y.1, z.0, z.1],
        regions: Cropping::SUBVOLUME,
    };
    let cropped = r
        .render_image(
            &view,
            &RenderParams {
                cropping: Some(crop),
                ..RenderParams::default()
            },
        )
        .unwrap();
    save(&cropped, "cropped_subvolume");
    let fp_crop = footprint(&cropped);
    // the cropped box seen from the front spans the middle third: ~ (1/3 · 1.1)² of the
    // whole box's projection, far below the blob's footprint
    println!(
        "cropping: footprint {fp_crop} px vs {fp_composite} uncropped; centre alpha {} vs {}",
        alpha(&cropped, 32, 32),
        alpha(&composite, 32, 32)
    );
    assert!(
        fp_crop > 0 && (fp_crop as f64) < 0.5 * fp_composite as f64,
        "cropped footprint {fp_crop}"
    );
    assert!(alpha(&cropped, 32, 32) > 0);
    // The kept region is the box between the planes (data = world here): its projection
    // bounds what is seen. Every ray through it has a sample inside unless its chord is
    // shorter than a step, so the extents agree to a pixel.
    let expect = projected_extents(
        &view,
        box_corners(DVec3::new(x.0, y.0, z.0), DVec3::new(x.1, y.1, z.1)),
    );
    let mask: Vec<bool> = cropped.rgba.chunks(4).map(|p| p[3] > 0).collect();
    let got = mask_extents(&mask, 64, 64).unwrap();
    let worst = (0..4)
        .map(|i| (got[i] - expect[i]).abs())
        .fold(0.0, f64::max);
    println!("cropping: extents {got:?} vs the projected crop box {expect:?}: worst {worst} px");
    assert!(worst <= 1.0, "cropped extents {got:?} vs {expect:?}");

    // a clipping plane through the centre, normal +x, keeps the right half
    let clip = ClipPlane {
        origin: DVec3::new(0.5 * (b[0] + b[1]), 0.0, 0.0),
        normal: DVec3::X,
    };
    let clipped = r
        .render_image(
            &view,
            &RenderParams {
                clip_planes: vec![clip],
                ..RenderParams::default()
            },
        )
        .unwrap();
    save(&clipped, "clipped_half");
    let fp_clip = footprint(&clipped);
    let ratio = fp_clip as f64 / fp_composite as f64;
    let left = (0..64)
        .flat_map(|y| (0..32).map(move |x| (x, y)))
        .filter(|&(x, y)| alpha(&clipped, x, y) > 0)
        .count();
    let right_changed = (0..64)
        .flat_map(|y| (32..64).map(move |x| (x, y)))
        .filter(|&(x, y)| rgba(&clipped, x, y) != rgba(&composite, x, y))
        .count();
    println!("clip plane: footprint {fp_clip} px of {fp_composite} ({ratio:.3}); {left} pixels shown left of the centre, {right_changed} changed right of it");
    // The blob's main lobe sits near the centre but its second lobe is right of it, so the
    // kept half holds a bit more than half; perspective adds a little at the cut.
    assert!(
        (0.4..0.7).contains(&ratio),
        "clipped footprint ratio {ratio:.3}"
    );
    // The camera sits on x = centre, so rays left of the centre never reach x ≥ centre and
    // rays right of it never leave it: the left half is empty, the right half untouched.
    assert_eq!(left, 0, "the clipped half still shows ({left} px)");
    assert_eq!(
        right_changed, 0,
        "the kept half changed ({right_changed} px)"
    );
}

// ---------------------------------------------------------------------------------------
// 13. Nearest-neighbour interpolation against the f64 reference
// ---------------------------------------------------------------------------------------

/// Pixels with some channel more than `levels` away from the reference.
fn pixels_off_by_more(img: &Image, reference: &[[f64; 4]], levels: f64) -> usize {
    img.rgba
        .chunks(4)
        .zip(reference)
        .filter(|(p, q)| {
            (0..4).any(|c| (p[c] as f64 - q[c].clamp(0.0, 1.0) * 255.0).abs() > levels)
        })
        .count()
}

#[test]
fn cpu_reference_nearest() {
    let mut r = renderer();
    // small enough that a voxel covers ~2 pixels, so nearest's blocks show
    let vol = blob_volume(24)
        .with_spacing([1.0, 0.8, 1.2])
        .unwrap()
        .with_origin([-5.0, 3.0, 0.5])
        .unwrap();
    let tf = blob_transfer();
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(tf.clone()))
        .unwrap();
    let (w, h) = (64u32, 64u32);
    let npix = (w * h) as usize;
    for (view_name, az, el) in [("front", 0.0, 0.0), ("oblique", 35.0, -25.0)] {
        let mut view = View::fit(vol.bounds(), w, h);
        view.camera.azimuth(az);
        view.camera.elevation(el);
        view.camera.orthogonalize_view_up();
        view.camera.reset_clipping_range(vol.bounds());
        for shade in [false, true] {
            let name = format!(
                "nearest_{view_name}_{}",
                if shade { "shaded" } else { "unshaded" }
            );
            let params = RenderParams {
                interpolation: Interpolation::Nearest,
                shading: Shading {
                    enabled: shade,
                    ..Shading::default()
                },
                ..RenderParams::default()
            };
            let dt = r.sample_distance(&params).unwrap();
            let img = r.render_image(&view, &params).unwrap();
            let (refc, _) = cpu_render(&vol, &tf, &view, &params, dt);
            save(&img, &name);
            save(&reference_image(&refc, w, h), &format!("{name}_cpu"));
            let (mae, psnr, max) = compare_to_reference(&img, &refc);
            let big = pixels_off_by_more(&img, &refc, 8.0);
            // What the test tells apart: the same GPU image against the linear reference,
            // and the renderer's own linear image against the nearest reference.
            let linear = RenderParams {
                interpolation: Interpolation::Linear,
                ..params.clone()
            };
            let (ref_lin, _) = cpu_render(&vol, &tf, &view, &linear, dt);
            let (mae_lin, psnr_lin, _) = compare_to_reference(&img, &ref_lin);
            let img_lin = r.render_image(&view, &linear).unwrap();
            let (mae_gl, psnr_gl, _) = compare_to_reference(&img_lin, &refc);
            let fp = footprint(&img);
            println!(
                "{name}: footprint {fp} px, vs nearest reference: mean abs error {mae:.3}/255, max {max:.1}/255, PSNR {psnr:.1} dB, {big} of {npix} px off by > 8/255 (dt {dt}); vs linear reference: mean {mae_lin:.3}/255, PSNR {psnr_lin:.1} dB; GPU linear image vs nearest reference: mean {mae_gl:.3}/255, PSNR {psnr_gl:.1} dB"
            );
            assert!(fp > 400, "{name}: the image is almost empty ({fp} px)");
            // As for linear interpolation (cpu_reference_composite_shaded): f32 against
            // f64 and the u8 output cost a fraction of a level on average; the tables are
            // no approximation here, the reference reads the same entries.
            assert!(psnr >= 35.0, "{name}: PSNR {psnr:.1} dB");
            assert!(mae < 1.5, "{name}: mean abs error {mae:.3}/255");
            // Nearest classification is discontinuous: a sample whose p + 0.5 lies within
            // f32 rounding of a voxel boundary (or whose scalar lies within rounding of a
            // half-way point between table entries) takes the neighbouring voxel (entry)
            // on one side and not the other, and that one sample's colour and opacity
            // jump. On a smooth volume that moves a pixel by a few levels at most, and
            // such samples are rare: at most 1% of the pixels may be off by more than 8.
            assert!(
                big * 100 < npix,
                "{name}: {big} of {npix} pixels off by more than 8/255"
            );
            // On this smooth blob nearest and linear interpolation differ by only a few
            // tenths of a level on average, well inside the bounds above: they alone would
            // pass a renderer that ignored the setting. The reference's own agreement (u8
            // rounding and little else) is several times tighter, so the nearest reference
            // must fit at least three times better than the linear one, and the renderer's
            // linear image must not fit it as well.
            assert!(
                3.0 * mae < mae_lin && 3.0 * mae < mae_gl,
                "{name}: the nearest image is not told from a linear one (mean abs error {mae:.3} vs the nearest reference, {mae_lin:.3} vs the linear one; linear image vs the nearest reference {mae_gl:.3})"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// 14. Rays only over the volume's projected rectangle, the rest cleared
// ---------------------------------------------------------------------------------------

/// Pixels whose square [x, x+1) × [y, y+1) touches the bounding rectangle of the
/// projected corners of the volume's box: no pixel outside can have a ray through the box
/// (its centre is at least half a pixel from the projection). `None` when a corner is
/// not in front of the camera (the projection is not bounded by the corners).
fn box_footprint(vol: &VolumeData, view: &View) -> Option<Vec<bool>> {
    let vp = view.camera.view_projection(view.aspect());
    let m = vol.index_to_data();
    let (lo, hi) = index_box(vol);
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in box_corners(lo, hi) {
        let c = vp * m.transform_point3(p).extend(1.0);
        if c.w <= 0.0 {
            return None;
        }
        let x = (c.x / c.w + 1.0) * 0.5 * view.width as f64;
        let y = (1.0 - c.y / c.w) * 0.5 * view.height as f64;
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    Some(
        (0..view.height)
            .flat_map(|y| (0..view.width).map(move |x| (x as f64, y as f64)))
            .map(|(x, y)| x + 1.0 > x0 && x < x1 && y + 1.0 > y0 && y < y1)
            .collect(),
    )
}

/// (max abs channel difference, pixels whose depth differs in any bit) of two frames.
fn frame_diff(a: &Image, b: &Image) -> (u8, usize) {
    let (_, max) = image_diff(a, b);
    let depth = a
        .depth
        .iter()
        .zip(&b.depth)
        .filter(|(x, y)| x.to_bits() != y.to_bits())
        .count();
    (max, depth)
}

#[test]
fn outside_rectangle_is_cleared() {
    let mut r = renderer();
    let vol = blob_volume(24);
    let tf = TransferFunction::single(blob_transfer());
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&tf).unwrap();
    let b = vol.bounds();
    let (w, h) = (96u32, 80u32);
    let npix = (w * h) as usize;
    let params = shaded();
    let mut small = View::fit(b, w, h);
    small.camera.azimuth(30.0);
    small.camera.elevation(20.0);
    small.camera.orthogonalize_view_up();
    small.camera.reset_clipping_range(b);
    let mut zoomed = small.clone();
    zoomed.camera.zoom(4.0);
    zoomed.camera.reset_clipping_range(b);

    // 1. The zoomed frame: the box covers the whole image (a full-image dispatch) and the
    // blob's core shows everywhere.
    let zoom_img = r.render_image(&zoomed, &params).unwrap();
    save(&zoom_img, "rect_zoomed");
    let zoom_hits = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let (_, _, t0, t1) = ray_segment(&vol, &pixel_ray(&zoomed, x, y));
            t0 < t1
        })
        .count();
    let zoom_fp = footprint(&zoom_img);

    // 2. The small frame right after it, on the same renderer and targets.
    let fp_mask = box_footprint(&vol, &small).expect("the box is in front of the camera");
    let img = r.render_image(&small, &params).unwrap();
    save(&img, "rect_small");
    let inside = fp_mask.iter().filter(|&&m| m).count();
    let mut outside = 0;
    let mut stale = 0; // outside pixels the zoomed frame had drawn
    let mut bad_color = 0;
    let mut bad_depth = 0;
    let mut first_bad = None;
    for (i, &m) in fp_mask.iter().enumerate() {
        if m {
            continue;
        }
        outside += 1;
        stale += (zoom_img.rgba[4 * i + 3] > 0) as usize;
        let c = &img.rgba[4 * i..4 * i + 4];
        let d = img.depth[i];
        bad_color += (c != [0u8; 4]) as usize;
        bad_depth += (d != 1.0) as usize;
        if (c != [0u8; 4] || d != 1.0) && first_bad.is_none() {
            first_bad = Some((i as u32 % w, i as u32 / w, [c[0], c[1], c[2], c[3]], d));
        }
    }
    let small_fp = footprint(&img);
    let small_fp_out = img
        .rgba
        .chunks(4)
        .zip(&fp_mask)
        .filter(|(p, &m)| p[3] > 0 && !m)
        .count();

    // 3. The same small view by a renderer that never drew anything else.
    let mut fresh = Renderer::new(Context::new().unwrap()).unwrap();
    fresh.set_volume(&vol).unwrap();
    fresh.set_transfer_function(&tf).unwrap();
    let fresh_img = fresh.render_image(&small, &params).unwrap();
    let (max_fresh, depth_fresh) = frame_diff(&img, &fresh_img);
    println!(
        "rect: zoomed frame: {zoom_hits} of {npix} px on the box, {zoom_fp} with opacity; small frame: analytic footprint {inside} px, {outside} outside it ({stale} of them drawn by the zoomed frame), {small_fp} px with opacity ({small_fp_out} outside the footprint); outside: {bad_color} px not rgba 0, {bad_depth} px depth not 1 (first {first_bad:?}); vs a fresh renderer: max abs diff {max_fresh}/255, {depth_fresh} depths differ"
    );
    assert_eq!(zoom_hits, npix, "the zoomed box must cover the image");
    assert!(
        zoom_fp * 10 >= npix * 9,
        "the zoomed frame must fill the image ({zoom_fp} of {npix} px)"
    );
    assert!(inside > 0 && small_fp > 0, "empty footprint");
    // the test means something only where the zoomed frame left pixels to clear
    assert!(
        outside * 4 >= npix && stale * 10 >= outside * 9,
        "too little outside the footprint: {outside} px, {stale} drawn before"
    );
    // Outside the footprint no ray meets the box: the pixels are cleared, never left from
    // the zoomed frame, and exactly so (clear values, not computed ones).
    assert_eq!(
        (bad_color, bad_depth),
        (0, 0),
        "pixels outside the footprint not cleared (first: {first_bad:?})"
    );
    // Inside, every pixel is written by the rays: nothing of the previous frame remains.
    assert_eq!(
        (max_fresh, depth_fresh),
        (0, 0),
        "the small frame depends on the frame before it"
    );

    // 4. The volume entirely off-screen (the camera shifted sideways by three box
    // widths): an empty rectangle, everything cleared.
    let mut away = small.clone();
    let right = away
        .camera
        .direction()
        .cross(away.camera.view_up)
        .normalize();
    let shift = right * 3.0 * (b[1] - b[0]);
    away.camera.position += shift;
    away.camera.focal_point += shift;
    away.camera.reset_clipping_range(b);
    let away_mask = box_footprint(&vol, &away).expect("the box is in front of the camera");
    r.render_image(&zoomed, &params).unwrap();
    let away_img = r.render_image(&away, &params).unwrap();
    let away_inside = away_mask.iter().filter(|&&m| m).count();
    let away_color = away_img.rgba.iter().filter(|&&c| c != 0).count();
    let away_depth = away_img.depth.iter().filter(|&&d| d != 1.0).count();
    println!(
        "rect: volume off-screen after the zoomed frame: footprint {away_inside} px, {away_color} channels not 0, {away_depth} depths not 1"
    );
    assert_eq!(away_inside, 0, "the shifted view still sees the box");
    assert_eq!(
        (away_color, away_depth),
        (0, 0),
        "an off-screen volume left pixels uncleared"
    );

    // 5. The camera inside the volume (a corner behind the camera: the full-image path),
    // right after the small frame, against the fresh renderer and the f64 reference.
    let mut inside_view = small.clone();
    inside_view.camera.position = DVec3::new(10.5, 11.0, 12.5);
    inside_view.camera.focal_point = DVec3::new(2.0, 5.0, 4.0);
    inside_view.camera.view_angle = 70.0;
    inside_view.camera.orthogonalize_view_up();
    inside_view.camera.reset_clipping_range(b);
    assert!(
        box_footprint(&vol, &inside_view).is_none(),
        "the camera must be inside the box"
    );
    r.render_image(&small, &params).unwrap();
    let in_img = r.render_image(&inside_view, &params).unwrap();
    save(&in_img, "rect_camera_inside");
    let in_fresh = fresh.render_image(&inside_view, &params).unwrap();
    let (max_in, depth_in) = frame_diff(&in_img, &in_fresh);
    let dt = r.sample_distance(&params).unwrap();
    let (refc, _) = cpu_render(&vol, &blob_transfer(), &inside_view, &params, dt);
    let (mae, psnr, max) = compare_to_reference(&in_img, &refc);
    let in_fp = footprint(&in_img);
    println!(
        "rect: camera inside: {in_fp} of {npix} px with opacity; vs a fresh renderer: max abs diff {max_in}/255, {depth_in} depths differ; vs the f64 reference: mean abs error {mae:.3}/255, max {max:.1}/255, PSNR {psnr:.1} dB"
    );
    // Every ray starts inside the blob's core (value ≈ 0.9 at the camera), so every pixel
    // has opacity.
    assert_eq!(in_fp, npix, "pixels without opacity with the camera inside");
    assert_eq!(
        (max_in, depth_in),
        (0, 0),
        "the frame depends on the one before"
    );
    // as cpu_reference_composite_shaded
    assert!(psnr >= 35.0, "camera inside: PSNR {psnr:.1} dB");
    assert!(mae < 1.5, "camera inside: mean abs error {mae:.3}/255");
}

/// Volumetric shadows (VTK's VolumetricScatteringBlending): a shadow ray toward a light
/// from the side darkens the far half of the blob; blending 0 changes nothing; what they
/// cannot do is refused. (Their agreement with VTK 9.2 is the regression suite's:
/// wavelet-volumetric-*, ct-volumetric-shadows.)
#[test]
fn volumetric_shadows_darken_the_far_side() {
    let mut r = renderer();
    let vol = blob_volume(32);
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let mut view = View::fit(vol.bounds(), 64, 64);
    let b = vol.bounds();
    let centre = DVec3::new(b[0] + b[1], b[2] + b[3], b[4] + b[5]) * 0.5;
    // from −x in the world; the camera looks along −z with +x to the right
    view.lights = vec![Light::directional(centre - DVec3::X * 100.0, centre, 1.0)];
    let mut p = shaded();
    let plain = r.render_image(&view, &p).unwrap();
    p.shading.volumetric_blending = 2.0;
    p.shading.global_illumination_reach = 1.0;
    let shadowed = r.render_image(&view, &p).unwrap();
    save(&plain, "volumetric_off");
    save(&shadowed, "volumetric_on");
    // mean luminance of the left (lit) and right (shadowed) halves
    let half = |img: &Image, right: bool| {
        let mut sum = 0.0;
        for y in 0..img.height {
            for x in 0..img.width / 2 {
                let x = if right { x + img.width / 2 } else { x };
                let px = rgba(img, x, y);
                sum += px[0] as f64 + px[1] as f64 + px[2] as f64;
            }
        }
        sum
    };
    let (l, rt) = (half(&shadowed, false), half(&shadowed, true));
    println!("volumetric shadows, light from −x: left half {l:.0}, right half {rt:.0}");
    assert!(rt < 0.7 * l, "the far side is not darker: {l} vs {rt}");
    p.shading.volumetric_blending = 0.0;
    let off = r.render_image(&view, &p).unwrap();
    assert_eq!(off.rgba, plain.rgba, "blending 0 is off");
    p.shading.volumetric_blending = 2.5;
    let e = r.render_image(&view, &p).unwrap_err().to_string();
    assert!(e.contains("volumetric scattering blending"), "{e}");
    p.shading.volumetric_blending = 1.0;
    r.set_volume_with(
        &vol,
        UploadOptions {
            max_brick_points: Some(12),
            ..Default::default()
        },
    )
    .unwrap();
    let e = r.render_image(&view, &p).unwrap_err().to_string();
    println!("bricked: {e}");
    assert!(e.contains("one brick"), "{e}");
}

/// Precomputed gradients give the on-the-fly gradients: shaded and gradient-opacity frames
/// of a blob, one brick and several, with and without them (max difference ≤ 1 level: the
/// half-float store).
#[test]
fn precomputed_gradients_equal_on_the_fly() {
    let mut r = renderer();
    let vol = blob_volume(40);
    let mut tf = blob_transfer();
    tf.gradient_opacity = Some(piecewise1(&[(0.0, 0.2), (0.05, 1.0)]));
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    let view = View::fit(vol.bounds(), 80, 80);
    for bricks in [None, Some(16)] {
        let mut images = vec![];
        for pre in [false, true] {
            r.set_volume_with(
                &vol,
                UploadOptions {
                    max_brick_points: bricks,
                    precompute_gradients: Some(pre),
                    ..Default::default()
                },
            )
            .unwrap();
            images.push(r.render_image(&view, &shaded()).unwrap());
        }
        let (mean, max) = image_diff(&images[0], &images[1]);
        println!(
            "{} brick(s): precomputed against on-the-fly gradients: mean {mean:.4}/255, max {max}/255",
            r.brick_count()
        );
        save(
            &images[1],
            &format!("precomputed_gradients_{}", r.brick_count()),
        );
        assert!(footprint(&images[0]) > 1000);
        assert!(max <= 1, "precomputed gradients differ by {max} levels");
    }
}
