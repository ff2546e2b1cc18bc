//! The GPU path tracer against a CPU reference path tracer of the same model, written here
//! in f64 and independently of the shader: a smooth blob of scattering medium under a
//! two-hemisphere sky, the headlight and a coloured directional light.
//!
//! The model (shaders/pathtrace.wgsl): extinction σ(x) = −ln(1 − min(α(s(x)), 0.9999)) /
//! unit distance, α the transfer function's opacity as given and s(x) the trilinearly
//! interpolated scalar (index coordinates = world coordinates here: unit spacing, origin 0,
//! voxel centres at integers, the medium inside [0, dims − 1]); single-scattering albedo the
//! transfer function's colour; Henyey–Greenstein scattering with anisotropy g; at most
//! `max_bounces` scattering events; the environment (weighted by `environment_light`) and
//! the view's directional lights (the headlight shining along each camera path) light it;
//! paths that miss the medium bring nothing (no background), and coverage is the fraction
//! of paths that met it.
//!
//! The reference estimates the same radiance by other means: delta tracking against one
//! global majorant, the environment only by the phase-sampled continuation (no
//! environment next-event estimation, so no MIS), the lights by next-event estimation with
//! ratio-tracking transmittance, no Russian roulette; its own random numbers
//! (xoshiro256**), its own orthonormal basis. The GPU (block majorants, luminance-sampled
//! environment with MIS, Russian roulette) must converge to the same image.
//!
//! The test prints what it measured and asserts a tolerance with the reason for it.
//! Images go to `target/test-images/pathtrace-reference-{gpu,cpu,flip}.png` (the FLIP error
//! map in NVIDIA's magma colours), enlarged 8×.

use ferrovol_core::*;
use glam::{DMat4, DVec3, DVec4};
use std::f64::consts::PI;
mod common;

use common::{renderer, volume};

/// Image size (pixels): small, so both tracers reach many paths per pixel.
const SIZE: u32 = 32;
/// Voxels per edge of the volume.
const DIMS: usize = 20;

/// The scene, as the CPU reference sees it (everything in f64, world = index space).
struct Scene {
    data: Vec<f64>,
    /// Opacity at scalar 0 and 1 (the transfer function's linear ramp over [0, 1]).
    alpha: [f64; 2],
    inv_unit: f64,
    albedo: DVec3,
    g: f64,
    max_bounces: u32,
    /// The largest σ anywhere (the opacity ramp rises, so at scalar 1).
    majorant: f64,
    env_weight: f64,
    /// The world direction that is up in the sky, and its upper and lower radiance.
    env_up: DVec3,
    sky: [DVec3; 2],
    /// Directional lights: toward the light (None: the headlight, toward the camera along
    /// each camera path), and colour × intensity.
    lights: Vec<(Option<DVec3>, DVec3)>,
    /// Clip → world.
    inv_view_proj: DMat4,
}

impl Scene {
    /// The trilinearly interpolated scalar at world point p (inside the box).
    fn scalar(&self, p: DVec3) -> f64 {
        let n = DIMS;
        let last = (n - 1) as f64;
        let q = p.clamp(DVec3::ZERO, DVec3::splat(last));
        let i = (q.x.floor() as usize).min(n - 2);
        let j = (q.y.floor() as usize).min(n - 2);
        let k = (q.z.floor() as usize).min(n - 2);
        let (fx, fy, fz) = (q.x - i as f64, q.y - j as f64, q.z - k as f64);
        let at = |di: usize, dj: usize, dk: usize| self.data[((k + dk) * n + j + dj) * n + i + di];
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let x00 = lerp(at(0, 0, 0), at(1, 0, 0), fx);
        let x10 = lerp(at(0, 1, 0), at(1, 1, 0), fx);
        let x01 = lerp(at(0, 0, 1), at(1, 0, 1), fx);
        let x11 = lerp(at(0, 1, 1), at(1, 1, 1), fx);
        lerp(lerp(x00, x10, fy), lerp(x01, x11, fy), fz)
    }

    fn sigma(&self, p: DVec3) -> f64 {
        let s = self.scalar(p).clamp(0.0, 1.0);
        let a = (self.alpha[0] + (self.alpha[1] - self.alpha[0]) * s).min(0.9999);
        -(1.0 - a).ln() * self.inv_unit
    }

    /// Parameter interval of the ray o + t·d inside the volume's box, from t = 0 on.
    fn box_interval(&self, o: DVec3, d: DVec3) -> (f64, f64) {
        let hi = (DIMS - 1) as f64;
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for a in 0..3 {
            if d[a].abs() < 1e-300 {
                if o[a] < 0.0 || o[a] > hi {
                    return (1.0, 0.0);
                }
                continue;
            }
            let (u, v) = ((0.0 - o[a]) / d[a], (hi - o[a]) / d[a]);
            t0 = t0.max(u.min(v));
            t1 = t1.min(u.max(v));
        }
        (t0, t1)
    }

    /// Delta tracking: the distance of the first collision in [t0, t1), None if none.
    fn collide(&self, o: DVec3, d: DVec3, t0: f64, t1: f64, rng: &mut Rng) -> Option<f64> {
        let mut t = t0;
        loop {
            t += -(1.0 - rng.next()).ln() / self.majorant;
            if t >= t1 {
                return None;
            }
            if rng.next() * self.majorant < self.sigma(o + t * d) {
                return Some(t);
            }
        }
    }

    /// Ratio tracking: an unbiased estimate of the transmittance from p out of the box
    /// along d.
    fn transmittance(&self, p: DVec3, d: DVec3, rng: &mut Rng) -> f64 {
        let (t0, t1) = self.box_interval(p, d);
        let (mut t, mut tr) = (t0, 1.0);
        loop {
            t += -(1.0 - rng.next()).ln() / self.majorant;
            if t >= t1 {
                return tr;
            }
            tr *= 1.0 - self.sigma(p + t * d) / self.majorant;
        }
    }

    /// Henyey–Greenstein density over the sphere for the cosine between propagation
    /// directions.
    fn phase(&self, cos: f64) -> f64 {
        let g = self.g;
        (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * cos).powf(1.5))
    }

    /// A direction scattered from d by Henyey–Greenstein (inverse CDF of the cosine).
    fn scatter(&self, d: DVec3, rng: &mut Rng) -> DVec3 {
        let g = self.g;
        let u = rng.next();
        let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u);
        let cos = ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0);
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = 2.0 * PI * rng.next();
        // any two unit vectors perpendicular to d and to each other
        let helper = if d.x.abs() < 0.6 { DVec3::X } else { DVec3::Y };
        let a = d.cross(helper).normalize();
        let b = d.cross(a);
        (cos * d + sin * (phi.cos() * a + phi.sin() * b)).normalize()
    }

    fn environment(&self, d: DVec3) -> DVec3 {
        self.sky[usize::from(d.dot(self.env_up) < 0.0)] * self.env_weight
    }

    /// One path through pixel (x, y): radiance and whether it met the medium.
    fn path(&self, x: u32, y: u32, rng: &mut Rng) -> ([f64; 3], bool) {
        // the camera ray through a uniformly jittered point of the pixel, from the near
        // plane to the far plane
        let px = (x as f64 + rng.next()) / SIZE as f64;
        let py = (y as f64 + rng.next()) / SIZE as f64;
        let (nx, ny) = (2.0 * px - 1.0, 1.0 - 2.0 * py);
        let unproject = |z: f64| {
            let p = self.inv_view_proj * DVec4::new(nx, ny, z, 1.0);
            p.truncate() / p.w
        };
        let (near, far) = (unproject(-1.0), unproject(1.0));
        let view_dir = (far - near).normalize();
        let (t0, t1) = self.box_interval(near, view_dir);
        let t1 = t1.min((far - near).length());
        let Some(t) = self.collide(near, view_dir, t0, t1, rng) else {
            return ([0.0; 3], false);
        };
        let mut p = near + t * view_dir;
        let mut d = view_dir;
        // (colours as DVec3: r, g, b)
        let mut beta = DVec3::ONE;
        let mut radiance = DVec3::ZERO;
        for event in 1..=self.max_bounces {
            beta *= self.albedo;
            for &(to_light, color) in &self.lights {
                let l = to_light.unwrap_or(-view_dir);
                let w = self.phase(d.dot(l)) * self.transmittance(p, l, rng);
                radiance += beta * w * color;
            }
            d = self.scatter(d, rng);
            let (s0, s1) = self.box_interval(p, d);
            match self.collide(p, d, s0, s1, rng) {
                None => {
                    radiance += beta * self.environment(d);
                    break;
                }
                Some(t) if event < self.max_bounces => p += t * d,
                Some(_) => break,
            }
        }
        (radiance.to_array(), true)
    }
}

/// xoshiro256** (Blackman & Vigna), seeded by SplitMix64.
struct Rng([u64; 4]);

impl Rng {
    fn new(seed: u64) -> Rng {
        let mut z = seed;
        Rng([0; 4].map(|_| {
            z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut x = z;
            x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            x ^ (x >> 31)
        }))
    }

    /// Uniform in [0, 1) (53 bits).
    fn next(&mut self) -> f64 {
        let s = &mut self.0;
        let out = s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        (out >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Per pixel: mean radiance and coverage, and the variance of the radiance's mean.
struct Reference {
    mean: Vec<[f64; 4]>,
    var: Vec<[f64; 3]>,
}

/// `spp` reference paths per pixel, on two threads.
fn reference(scene: &Scene, spp: u32) -> Reference {
    let n = (SIZE * SIZE) as usize;
    let threads = 2;
    // per pixel: its index, mean radiance and coverage, variance of the radiance's mean
    type Pixel = (usize, [f64; 4], [f64; 3]);
    let parts: Vec<Vec<Pixel>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|th| {
                s.spawn(move || {
                    let mut out = vec![];
                    for i in (th..n).step_by(threads) {
                        let mut rng = Rng::new(0x5eed_0000 + i as u64);
                        let (x, y) = ((i as u32) % SIZE, (i as u32) / SIZE);
                        let mut sum = [0.0f64; 4];
                        let mut sq = [0.0f64; 3];
                        for _ in 0..spp {
                            let (l, hit) = scene.path(x, y, &mut rng);
                            for c in 0..3 {
                                sum[c] += l[c];
                                sq[c] += l[c] * l[c];
                            }
                            sum[3] += f64::from(u8::from(hit));
                        }
                        let k = spp as f64;
                        let mean = sum.map(|v| v / k);
                        let var = [0, 1, 2].map(|c| (sq[c] / k - mean[c] * mean[c]).max(0.0) / k);
                        out.push((i, mean, var));
                    }
                    out
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let mut r = Reference {
        mean: vec![[0.0; 4]; n],
        var: vec![[0.0; 3]; n],
    };
    for (i, m, v) in parts.into_iter().flatten() {
        r.mean[i] = m;
        r.var[i] = v;
    }
    r
}

/// Linear radiance → 8-bit sRGB (clamped at 1), as an image would show it.
fn srgb8(v: f64) -> u8 {
    let v = v.clamp(0.0, 1.0);
    let e = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0).round() as u8
}

/// Saves an 8-bit RGB image of SIZE × SIZE pixels, enlarged 8× (nearest neighbour) so
/// that it can be looked at.
fn save_rgb(bytes: &[u8], name: &str) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/test-images");
    std::fs::create_dir_all(&dir).expect("creating target/test-images");
    let zoom = 8;
    image::RgbImage::from_fn(SIZE * zoom, SIZE * zoom, |x, y| {
        let i = 3 * ((y / zoom) * SIZE + x / zoom) as usize;
        image::Rgb([bytes[i], bytes[i + 1], bytes[i + 2]])
    })
    .save(dir.join(format!("pathtrace-reference-{name}.png")))
    .expect("writing a test image");
}

/// Renders frames until `spp` paths per pixel are accumulated; returns the mean per pixel.
fn trace(r: &mut Renderer, view: &View, p: &PathTraceParams, spp: u32) -> Vec<[f32; 4]> {
    // (a budget of exactly `spp`: the last frame adds only what is missing)
    let p = PathTraceParams {
        max_samples: spp,
        ..*p
    };
    r.set_path_tracing(&p).expect("valid path tracing settings");
    r.reset_accumulation();
    let params = RenderParams {
        blend: BlendMode::PathTrace,
        ..Default::default()
    };
    while r.accumulated_samples() < spp {
        r.render(view, &params, None).expect("a path-traced frame");
    }
    assert_eq!(r.accumulated_samples(), spp);
    r.read_accumulation().expect("the accumulation")
}

/// Paths per pixel of the GPU image (two halves with different seeds) and of the
/// reference. On lavapipe a dispatch (one path per pixel) costs ~10 ms whatever the image
/// size, so 4096 paths take about a minute; the reference's paths are ~100× cheaper.
const GPU_SPP: u32 = 4096;
const CPU_SPP: u32 = 8192;

#[test]
fn gpu_path_tracer_matches_the_cpu_reference() {
    let start = std::time::Instant::now();
    let mut r = renderer();
    // A smooth bump of density (zero from radius 9 on, so the box's faces play no part):
    // optical depth about 4 through the centre.
    let c = (DIMS - 1) as f64 / 2.0;
    let bump = |x: f64, y: f64, z: f64| {
        let q = ((x - c).powi(2) + (y - c).powi(2) + (z - c).powi(2)) / 81.0;
        (1.0 - q).max(0.0).powi(2)
    };
    let n = DIMS as u32;
    let vol = volume([n, n, n], bump);
    r.set_volume(&vol).unwrap();
    // Constant colour (the albedo, not grey) and a linear opacity ramp over the table's
    // range [0, 1]: both exact under the lookup tables' linear interpolation. A unit
    // distance of 1.5 checks the scaling of σ.
    let albedo = [0.9f32, 0.6, 0.3];
    let alpha = [0.0f32, 0.6];
    let unit = 1.5;
    let color = Piecewise::new(vec![(0.0, albedo), (1.0, albedo)]).unwrap();
    let opacity = Piecewise::new(vec![(0.0, [alpha[0]]), (1.0, [alpha[1]])]).unwrap();
    let mut ct = ComponentTransfer::new(color, opacity);
    ct.unit_distance = unit;
    r.set_transfer_function(&TransferFunction::single(ct))
        .unwrap();
    // A sky, bluish above and brownish below, whose up is tilted off every axis.
    let (above, below) = ([1.1f32, 1.4, 2.0], [0.6f32, 0.44, 0.3]);
    let mut env = Environment::hemisphere(above, below);
    env.up = DVec3::new(0.3, 1.0, -0.2).normalize();
    r.set_environment(&env).unwrap();
    // An oblique perspective view; the headlight dimmed and a strong warm light from the
    // left and a little behind (a bright rim where g = 0.5 scatters it forward).
    let bounds = vol.bounds();
    let mut view = View::fit(bounds, SIZE, SIZE);
    view.camera.azimuth(30.0);
    view.camera.elevation(20.0);
    view.camera.orthogonalize_view_up();
    view.camera.zoom(1.5);
    view.camera.reset_clipping_range(bounds);
    view.lights[0].intensity = 0.5;
    let mut sun = Light::directional(DVec3::new(-100.0, 50.0, -20.0), DVec3::ZERO, 5.0);
    sun.diffuse = [1.0, 0.8, 0.55];
    view.lights.push(sun);
    let p = PathTraceParams {
        samples_per_frame: 1024,
        max_bounces: 8,
        anisotropy: 0.5,
        environment_light: 0.8,
        ..Default::default()
    };

    let f = |v: f32| v as f64;
    let scene = Scene {
        // the voxel values as the GPU holds them (f32)
        data: (0..DIMS * DIMS * DIMS)
            .map(|i| {
                let (x, y, z) = (i % DIMS, i / DIMS % DIMS, i / (DIMS * DIMS));
                f(bump(x as f64, y as f64, z as f64) as f32)
            })
            .collect(),
        alpha: alpha.map(f),
        inv_unit: 1.0 / unit,
        albedo: DVec3::from_array(albedo.map(f)),
        g: f(p.anisotropy),
        max_bounces: p.max_bounces,
        majorant: -(1.0 - f(alpha[1])).ln() / unit,
        env_weight: f(p.environment_light),
        env_up: env.up,
        sky: [above, below].map(|c| DVec3::from_array(c.map(f))),
        lights: view
            .lights
            .iter()
            .map(|l| {
                let dir = match l.space {
                    LightSpace::Headlight => None,
                    _ => {
                        let (from, to) = l.world_placement(&view.camera);
                        Some((from - to).normalize())
                    }
                };
                (dir, DVec3::from_array(l.diffuse.map(f)) * f(l.intensity))
            })
            .collect(),
        inv_view_proj: view.camera.view_projection(view.aspect()).inverse(),
    };

    // The GPU image as two halves with different seeds: their difference measures its
    // noise.
    let t = std::time::Instant::now();
    let h1 = trace(
        &mut r,
        &view,
        &PathTraceParams { seed: 1, ..p },
        GPU_SPP / 2,
    );
    let h2 = trace(
        &mut r,
        &view,
        &PathTraceParams { seed: 2, ..p },
        GPU_SPP / 2,
    );
    let gpu_s = t.elapsed().as_secs_f64();
    let t = std::time::Instant::now();
    let cpu = reference(&scene, CPU_SPP);
    let cpu_s = t.elapsed().as_secs_f64();
    let gpu: Vec<[f64; 4]> = h1
        .iter()
        .zip(&h2)
        .map(|(a, b)| [0, 1, 2, 3].map(|c| 0.5 * (f(a[c]) + f(b[c]))))
        .collect();

    // Pixels with signal: reference luminance at least 5% of the brightest pixel's (the
    // rim, where few paths meet the thin medium, carries little light and much relative
    // noise).
    let lum = |v: &[f64]| 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
    let peak = cpu.mean.iter().map(|v| lum(v)).fold(0.0, f64::max);
    let signal: Vec<usize> = (0..cpu.mean.len())
        .filter(|&i| lum(&cpu.mean[i]) >= 0.05 * peak)
        .collect();
    // Mean relative error: Σ|gpu − ref| / Σ ref over the colour channels of those pixels
    // (the relative L1 error: each pixel weighs as much as the light it carries, so dim
    // pixels' relative noise does not swamp it). It holds the noise of both images too:
    // E|N(0, σ²)| = σ√(2/π), σ from the reference's sample variance, and for the GPU from
    // its two halves (E|h1 − h2| / 2 = σ√(2/π)).
    let (mut l1, mut total, mut noise_gpu, mut noise_cpu) = (0.0, 0.0, 0.0, 0.0);
    for &i in &signal {
        for k in 0..3 {
            l1 += (gpu[i][k] - cpu.mean[i][k]).abs();
            total += cpu.mean[i][k];
            noise_gpu += 0.5 * (f(h1[i][k]) - f(h2[i][k])).abs();
            noise_cpu += (2.0 / PI * cpu.var[i][k]).sqrt();
        }
    }
    let rel = l1 / total;
    let (noise_gpu, noise_cpu) = (noise_gpu / total, noise_cpu / total);
    // Bias: the whole image's radiance per channel and its coverage, GPU over reference − 1,
    // and its standard error from both images' noise.
    let mut sums = [[0.0f64; 4]; 2];
    let mut var = [0.0f64; 3];
    for i in 0..gpu.len() {
        for k in 0..4 {
            sums[0][k] += gpu[i][k];
            sums[1][k] += cpu.mean[i][k];
        }
        for k in 0..3 {
            var[k] += (f(h1[i][k]) - f(h2[i][k])).powi(2) / 4.0 + cpu.var[i][k];
        }
    }
    let bias = [0, 1, 2, 3].map(|k| sums[0][k] / sums[1][k] - 1.0);
    let bias_se = [0, 1, 2].map(|k| var[k].sqrt() / sums[1][k]);

    // FLIP (LDR) on 8-bit sRGB, both images exposed alike so the reference's brightest
    // channel reaches 1 (premultiplied radiance: the medium over black).
    let exposure = 1.0
        / cpu
            .mean
            .iter()
            .map(|v| v[0].max(v[1]).max(v[2]))
            .fold(0.0, f64::max);
    let to8 = |img: &[[f64; 4]]| -> Vec<u8> {
        img.iter()
            .flat_map(|v| [0, 1, 2].map(|c| srgb8(exposure * v[c])))
            .collect()
    };
    let (gpu8, cpu8) = (to8(&gpu), to8(&cpu.mean));
    save_rgb(&gpu8, "gpu");
    save_rgb(&cpu8, "cpu");
    let err = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(SIZE, SIZE, &cpu8),
        nv_flip::FlipImageRgb8::with_data(SIZE, SIZE, &gpu8),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let flip = nv_flip::FlipPool::from_image(&err).mean() as f64;
    save_rgb(&err.apply_color_lut(&nv_flip::magma_lut()).to_vec(), "flip");

    println!(
        "{SIZE}×{SIZE} pixels, {} with signal (peak luminance {peak:.3}); paths per pixel: GPU \
         {GPU_SPP} in {gpu_s:.1} s, CPU reference {CPU_SPP} in {cpu_s:.1} s; {:.1} s in all",
        signal.len(),
        start.elapsed().as_secs_f64()
    );
    println!(
        "mean relative error {:.2}% (noise alone: GPU {:.2}%, reference {:.2}%, together \
         ~{:.2}%); mean FLIP {flip:.4}",
        100.0 * rel,
        100.0 * noise_gpu,
        100.0 * noise_cpu,
        100.0 * noise_gpu.hypot(noise_cpu)
    );
    println!(
        "GPU / reference − 1 over the image: r {:+.3}%, g {:+.3}%, b {:+.3}% (standard error \
         {:.3}%, {:.3}%, {:.3}%), coverage {:+.3}%",
        100.0 * bias[0],
        100.0 * bias[1],
        100.0 * bias[2],
        100.0 * bias_se[0],
        100.0 * bias_se[1],
        100.0 * bias_se[2],
        100.0 * bias[3]
    );
    // Not a trivial image: the medium fills much of the frame with light.
    assert!(peak > 0.2, "peak luminance {peak}");
    assert!(signal.len() > 300, "{} pixels with signal", signal.len());
    // The tolerances. At these path counts the two images' noise alone gives ~1.5%
    // of relative error and ~0.015 FLIP (printed above), so these catch errors of a few
    // percent. Perturbing the reference: g = 0.45 for 0.5 gave 2.6% (FLIP 0.034), the
    // environment 3% brighter 2.3%, a red albedo of 0.88 for 0.9 3.6% (FLIP 0.046), the
    // directional light 5% brighter 2.3%, tilted by 5.5° 2.6%, no headlight 2.3%.
    assert!(rel < 0.02, "mean relative error {rel}");
    assert!(flip < 0.05, "mean FLIP {flip}");
    // Over the whole image the noise averages out (standard error ~0.1%, printed above), so
    // half a percent in any channel or in coverage is a real difference, 4 standard errors
    // out: all of the above fail it, and so do a 3% longer unit distance (coverage −1.2%,
    // relative error only 1.9%) and a ninth scattering event (r −0.52%). The GPU's 8-bit
    // trilinear filter weights and half-float environment cube stay far below it.
    for (k, b) in bias.iter().enumerate() {
        assert!(
            b.abs() < 0.005,
            "channel {k} (3: coverage): GPU / reference − 1 = {b}"
        );
    }
}
