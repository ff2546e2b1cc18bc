//! Environment maps: irradiance of analytic environments and of the default sky, specular
//! sampling (a constant environment, convergence against a brute-force integral).
//! Environment files are ferrovol-io's (io/tests/images.rs).

use super::{iso, lit, sphere_view};
use crate::common::gpu::renderer;
use crate::common::images::save;
use ferrovol_core::*;
use glam::DVec3;

#[test]
fn irradiance_of_analytic_environments() {
    let mut r = renderer();
    // A constant environment: E/π is the constant (a white Lambertian surface reflects it).
    let c = [0.2f32, 0.5, 1.0];
    r.set_environment(&Environment::constant(c)).unwrap();
    let irr = r.read_irradiance().unwrap();
    let mut worst = 0.0f64;
    for face in &irr.faces {
        for t in face {
            for k in 0..3 {
                worst = worst.max(((t[k] - c[k]) / c[k]).abs() as f64);
            }
        }
    }
    println!("constant environment: max relative irradiance error {worst:.2e}");
    assert!(worst < 0.01, "within 1% (half-float storage: 5e-4)");
    // Sky 1 above the horizon, 0 below: E/π = (1 + n_y) / 2.
    r.set_environment(&Environment::hemisphere([1.0; 3], [0.0; 3]))
        .unwrap();
    let irr = r.read_irradiance().unwrap();
    let (mut worst, mut sum, mut n) = (0.0f64, 0.0, 0);
    for f in 0..6 {
        for y in 0..irr.size {
            for x in 0..irr.size {
                let d = irr.texel_direction(f, x, y);
                let want = 0.5 * (1.0 + d.y);
                let got = irr.faces[f][(y * irr.size + x) as usize][0] as f64;
                worst = worst.max((got - want).abs());
                sum += (got - want).abs();
                n += 1;
            }
        }
    }
    println!(
        "hemisphere sky: irradiance vs (1 + n_y)/2: max error {worst:.4}, mean {:.4}",
        sum / n as f64
    );
    // 512 cosine-weighted Hammersley directions through the mip chain: the horizon's
    // step is blurred over the footprint of a sample, a few hundredths at worst.
    assert!(worst < 0.02, "within 2% of the closed form");
}

/// π-normalised irradiance of `sky` at normal n by quadrature on the CPU: the sky on a fine
/// grid, the sun's disk analytically (a small disk: its solid angle times its cosine).
fn sky_irradiance(sky: &Sky, n: DVec3) -> [f64; 3] {
    let (nt, np) = (400, 800);
    let mut e = [0.0; 3];
    // the disk is added analytically below; its halo is smooth and stays in the grid
    let no_sun = Sky {
        sun_radius_deg: 0.0,
        ..sky.clone()
    };
    // frame around n
    let t = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let u = n.cross(t).normalize();
    let v = n.cross(u);
    for i in 0..nt {
        // cos θ = sqrt(1 − ξ): cosine-weighted strata, the estimator is the mean radiance
        let xi = (i as f64 + 0.5) / nt as f64;
        let ct = (1.0 - xi).sqrt();
        let st = (1.0 - ct * ct).sqrt();
        for j in 0..np {
            let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / np as f64;
            let d = n * ct + (u * phi.cos() + v * phi.sin()) * st;
            for (ek, lk) in e.iter_mut().zip(no_sun.radiance(d)) {
                *ek += lk;
            }
        }
    }
    let m = (nt * np) as f64;
    let sun = sky.sun_direction.normalize();
    let omega = 2.0 * std::f64::consts::PI * (1.0 - (sky.sun_radius_deg as f64).to_radians().cos());
    let cos = n.dot(sun).max(0.0);
    for (ek, sk) in e.iter_mut().zip(sky.sun_color) {
        *ek = *ek / m + sk as f64 * omega * cos / std::f64::consts::PI;
    }
    e
}

#[test]
fn irradiance_of_the_default_sky() {
    let mut r = renderer();
    let sky = Sky::default();
    let env = Environment::sky(sky.clone());
    let t0 = std::time::Instant::now();
    r.set_environment(&env).unwrap();
    println!("environment maps built in {:?}", t0.elapsed());
    let irr = r.read_irradiance().unwrap();
    let sun = sky.sun_direction.normalize();
    let mut worst = 0.0f64;
    for n in [
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::X,
        DVec3::NEG_Z,
        sun,
        DVec3::new(-1.0, 0.3, 0.2).normalize(),
    ] {
        // the texel n falls in, compared at its own direction
        let (f, u, v) = cube_face_coords(n);
        let (x, y) = ((u * irr.size as f64) as u32, (v * irr.size as f64) as u32);
        let n = irr.texel_direction(f, x, y);
        let want = sky_irradiance(&sky, n);
        let got = irr.faces[f][(y * irr.size + x) as usize];
        let rel = (0..3)
            .map(|k| ((got[k] as f64 - want[k]) / want[k]).abs())
            .fold(0.0, f64::max);
        println!(
            "n = {:>5.2?}: GPU {:.4?} CPU {:.4?} (rel. error {rel:.4})",
            n.to_array(),
            &got[..3],
            want
        );
        worst = worst.max(rel);
    }
    // The sun covers 1/3300 of the sphere and carries a third of the irradiance facing it:
    // the mip chain must keep its energy (solid-angle-weighted downsampling), and each of
    // the 2048 directions reads a footprint of a few degrees, so the sun's share is
    // estimated to a few percent of itself (measured: 1.8% at worst).
    assert!(
        worst < 0.03,
        "the default sky's irradiance within 3% of quadrature"
    );
}

/// Specular light only (no lights, no diffuse or ambient), so a pixel is the environment
/// seen through the specular lobe.
fn specular_only() -> RenderParams {
    lit(0.0, 0.0, 1.0)
}

#[test]
fn specular_of_a_constant_environment_is_the_constant() {
    let mut r = renderer();
    let vol = synth::sphere(48, 0.8);
    r.set_volume(&vol).unwrap();
    r.set_environment(&Environment::constant([0.5; 3])).unwrap();
    let view = sphere_view(&vol, 64, false);
    for (mode, shininess) in [
        (SpecularMode::Importance, Shininess::Constant(20.0)),
        (SpecularMode::Importance, Shininess::Constant(400.0)),
        (SpecularMode::Importance, Shininess::default()),
        (SpecularMode::Cone, Shininess::Constant(20.0)),
        (SpecularMode::Cone, Shininess::default()),
    ] {
        let mut p = iso(&[(0.0, [1.0; 3], 1.0)]);
        p.environment_light = 1.0;
        p.specular = mode;
        p.shininess = shininess;
        p.specular_samples = 16;
        r.set_isosurface(&p).unwrap();
        let img = r.render_image(&view, &specular_only()).unwrap();
        let g = r.read_gbuffer().unwrap();
        let (mut n, mut worst) = (0, 0.0f32);
        for y in 0..64 {
            for x in 0..64 {
                if g.counts[(y * 64 + x) as usize] > 0 {
                    n += 1;
                    let px = img.pixel(x, y);
                    for c in &px[..3] {
                        worst = worst.max((c - 0.5).abs());
                    }
                }
            }
        }
        println!("{mode:?} {shininess:?}: {n} pixels, max |specular − 0.5| = {worst:.4}");
        assert!(n > 1500);
        // 0.5 is exact in half floats; the RGBA8 output rounds 127.5 to 127 or 128
        assert!(
            worst <= 0.5 / 255.0 + 1e-4,
            "a constant environment reflects the constant"
        );
    }
    // Schlick's Fresnel term: 0.5 · (F0 + (1 − F0)(1 − n·v)^5) per pixel
    let f0 = 0.04;
    let mut p = iso(&[(0.0, [1.0; 3], 1.0)]);
    p.environment_light = 1.0;
    p.fresnel = Some(f0 as f32);
    r.set_isosurface(&p).unwrap();
    let img = r.render_image(&view, &specular_only()).unwrap();
    let g = r.read_gbuffer().unwrap();
    let (mut worst, mut lo, mut hi) = (0.0f64, f64::MAX, 0.0f64);
    for y in 0..64 {
        for x in 0..64 {
            let Some(h) = g.hits(x, y).first().copied() else {
                continue;
            };
            let v = (view.camera.position - h.position).normalize();
            let want = 0.5 * (f0 + (1.0 - f0) * (1.0 - h.normal.dot(v).clamp(0.0, 1.0)).powi(5));
            let got = img.pixel(x, y)[0] as f64;
            worst = worst.max((got - want).abs());
            lo = lo.min(got);
            hi = hi.max(got);
        }
    }
    println!(
        "Fresnel F0 = {f0}: specular {lo:.3} (facing) to {hi:.3} (grazing), max error {worst:.4}"
    );
    assert!(worst <= 1.0 / 255.0, "Schlick's term within 8-bit rounding");
    assert!(lo < 0.03 && hi > 0.2);
}

/// The normalised Phong lobe cos^s around r over the environment "1 above the horizon, 0
/// below": the lobe's mass above the horizon, by quadrature.
fn lobe_above_horizon(r: DVec3, s: f64) -> f64 {
    let sb = r.y.clamp(-1.0, 1.0);
    let cb = (1.0 - sb * sb).sqrt();
    let n = 4000;
    let mut sum = 0.0;
    for i in 0..n {
        // w uniform ↔ cos θ = w^(1/(s+1)) distributed as the lobe
        let w = (i as f64 + 0.5) / n as f64;
        let ct = w.powf(1.0 / (s + 1.0));
        let st = (1.0 - ct * ct).max(0.0).sqrt();
        let (a, b) = (ct * sb, st * cb);
        sum += if b <= 1e-15 {
            (a > 0.0) as i32 as f64
        } else {
            let x = -a / b;
            if x <= -1.0 {
                1.0
            } else if x >= 1.0 {
                0.0
            } else {
                x.acos() / std::f64::consts::PI
            }
        };
    }
    sum / n as f64
}

#[test]
fn specular_sampling_converges() {
    let mut r = renderer();
    let vol = synth::sphere(48, 0.8);
    r.set_volume(&vol).unwrap();
    r.set_environment(&Environment::hemisphere([1.0; 3], [0.0; 3]))
        .unwrap();
    let view = sphere_view(&vol, 64, false);
    let s = 20.0;
    let eye = view.camera.position;
    let mut errors = Vec::new();
    // the reference per pixel, from the (always identical) G-buffer of the first frame
    let mut reference: Vec<Option<f64>> = Vec::new();
    for mode in [SpecularMode::Cone, SpecularMode::Importance] {
        for n in [1, 4, 16, 64, 256] {
            let mut p = iso(&[(0.0, [1.0; 3], 1.0)]);
            p.environment_light = 1.0;
            p.specular = mode;
            p.shininess = Shininess::Constant(s as f32);
            p.specular_samples = n;
            r.set_isosurface(&p).unwrap();
            let img = r.render_image(&view, &specular_only()).unwrap();
            if n == 16 {
                save(&img, &format!("iso-specular-{mode:?}-16"));
            }
            if reference.is_empty() {
                let g = r.read_gbuffer().unwrap();
                reference = (0..64 * 64)
                    .map(|i| {
                        g.hits(i % 64, i / 64).first().map(|h| {
                            let v = (eye - h.position).normalize();
                            let refl = (2.0 * h.normal.dot(v) * h.normal - v).normalize();
                            lobe_above_horizon(refl, s)
                        })
                    })
                    .collect();
            }
            let (mut sq, mut count) = (0.0, 0);
            for y in 0..64 {
                for x in 0..64 {
                    let Some(want) = reference[(y * 64 + x) as usize] else {
                        continue;
                    };
                    let got = img.pixel(x, y)[0] as f64;
                    sq += (got - want).powi(2);
                    count += 1;
                }
            }
            let rms = (sq / count as f64).sqrt();
            println!("{mode:?} N = {n:>3}: RMS error {rms:.4} over {count} pixels");
            errors.push((mode, n, rms));
        }
    }
    let e = |m: SpecularMode, n: u32| {
        errors
            .iter()
            .find(|x| x.0 == m && x.1 == n)
            .map(|x| x.2)
            .unwrap()
    };
    // Importance sampling beats the cone scheme at equal sample counts.
    for n in [4, 16, 64, 256] {
        assert!(
            e(SpecularMode::Importance, n) < e(SpecularMode::Cone, n),
            "N = {n}"
        );
    }
    // The cone scheme is plain Monte Carlo: its error falls like 1/√N (×4 from 4 to 64;
    // asked: at least ×2).
    let cone_ratio = e(SpecularMode::Cone, 4) / e(SpecularMode::Cone, 64);
    let is_ratio = e(SpecularMode::Importance, 1) / e(SpecularMode::Importance, 64);
    println!("error ratio N=4→64: cone {cone_ratio:.2}; importance N=1→64 {is_ratio:.2}");
    assert!(cone_ratio > 2.0);
    assert!(is_ratio > 2.0);
    // With 64 lobe samples the filtered estimate is within a few 8-bit levels on average.
    assert!(e(SpecularMode::Importance, 64) < 0.02);
}
