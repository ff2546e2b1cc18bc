//! First hit with bisection on a sphere distance field, nested translucent layers,
//! ambient occlusion, bricking, depth input, clipping and cropping, scattering between
//! isosurfaces, and the errors of the API.

use super::{iso, lit, params, sphere_view};
use crate::common::gpu::{assert_error, renderer};
use crate::common::images::save;
use crate::common::metrics::corner_accessibility;
use crate::common::raycast::trilinear;
use crate::common::scenes::{radial, volume, with_clip_plane};
use ferrovol_core::*;
use glam::DVec3;

/// Gradient of the interpolated field by central differences of `h` voxels.
fn gradient(v: &VolumeData, p: DVec3, h: f64) -> DVec3 {
    let e = |a: DVec3| (trilinear(v, p + a * h) - trilinear(v, p - a * h)) / (2.0 * h);
    DVec3::new(e(DVec3::X), e(DVec3::Y), e(DVec3::Z))
}

/// Hits of a sphere's distance field against the field the renderer interpolates and the
/// analytic sphere: (hits, max and mean distance to the interpolated isosurface, max
/// distance to the sphere, mean and max normal error in degrees).
fn sphere_hits(r: &mut Renderer, vol: &VolumeData, scale: f64, name: &str) -> [f64; 6] {
    let center = DVec3::splat(31.5);
    let radius = 0.8 * 31.5;
    r.set_volume(vol).unwrap();
    let p = iso(&[(0.0, [0.9, 0.85, 0.8], 1.0)]);
    assert_eq!(p.bisection_steps, 8, "the default is what this test checks");
    r.set_isosurface(&p).unwrap();
    let mut view = View::fit(vol.bounds(), 160, 160);
    view.camera.zoom(2.0);
    let img = r.render_image(&view, &params()).unwrap();
    save(&img, &format!("iso-{name}"));
    let g = r.read_gbuffer().unwrap();
    let (mut n, mut max_interp, mut sum_interp, mut max_sphere) = (0usize, 0.0f64, 0.0, 0.0f64);
    let (mut sum_angle, mut max_angle) = (0.0, 0.0f64);
    for y in 0..g.height {
        for x in 0..g.width {
            let hits = g.hits(x, y);
            let Some(h) = hits.first() else { continue };
            n += 1;
            // distance to the isosurface of the interpolated field, to first order
            let f = trilinear(vol, h.position);
            let gr = gradient(vol, h.position, 1e-4);
            let d = f.abs() / gr.length();
            max_interp = max_interp.max(d);
            sum_interp += d;
            max_sphere = max_sphere.max(((h.position - center).length() - radius).abs());
            let a = h
                .normal
                .angle_between((h.position - center).normalize())
                .to_degrees();
            sum_angle += a;
            max_angle = max_angle.max(a);
            assert_eq!(h.iso_index, 0);
            assert!((h.ambient_access - 1.0).abs() < 1e-6);
            // |∇f| in scalar units per world unit: the distance field's slope is `scale`
            assert!((h.gradient_magnitude / scale - 1.0).abs() < 0.05);
        }
    }
    let mean_angle = sum_angle / n as f64;
    println!(
        "{name}: {n} hits: distance to the interpolated isosurface max {max_interp:.2e} mean \
         {:.2e} voxel; to the analytic sphere max {max_sphere:.2e} voxel; normal error mean \
         {mean_angle:.3}° max {max_angle:.3}°",
        sum_interp / n as f64
    );
    [
        n as f64,
        max_interp,
        sum_interp / n as f64,
        max_sphere,
        mean_angle,
        max_angle,
    ]
}

#[test]
fn bisection_hits_the_sphere() {
    let mut r = renderer();
    // lit by the default sky (what another test left set must not light these images)
    r.set_environment(&Environment::default()).unwrap();
    let radius = 0.8 * 31.5;
    let f32_sphere = synth::sphere(64, 0.8);
    // the same field as int16 in 1/100 voxel (CT-like storage: 16-bit normalised texture)
    let i16_sphere = VolumeData::new(
        [64; 3],
        1,
        Scalars::I16(
            (0..64usize.pow(3))
                .map(|i| (f32_sphere.scalars.get(i) * 100.0).round() as i16)
                .collect(),
        ),
    )
    .unwrap();
    for (vol, scale, name) in [
        (&f32_sphere, 1.0, "sphere-f32"),
        (&i16_sphere, 100.0, "sphere-i16"),
    ] {
        let [n, max_interp, _, max_sphere, mean_angle, _] = sphere_hits(&mut r, vol, scale, name);
        assert!(
            n > 12000.0,
            "the sphere covers most of the image ({n} hits)"
        );
        // Bisection's accuracy: the crossing of the field the renderer interpolates.
        assert!(
            max_interp < 1e-3,
            "hits within 1e-3 voxel of the isosurface"
        );
        // The analytic sphere differs from the trilinear interpolant's zero set by at most
        // ½·¼·tr(Hessian) = 1/(4R) voxel (the interpolation error of |p − c| in a cell),
        // plus 1/200 voxel of int16 rounding.
        assert!(
            max_sphere < 1.0 / (4.0 * radius) + 5e-3 + 1e-3,
            "hits within the trilinear reconstruction bound of the analytic sphere"
        );
        assert!(mean_angle < 0.5, "normals within 0.5° on average");
    }
}

/// Lighting that makes a layer's colour exactly its iso-value's colour: ambient 1 from the
/// headlight's white ambient, nothing else.
fn flat_params() -> RenderParams {
    lit(1.0, 0.0, 0.0)
}

#[test]
fn nested_translucent_spheres_composite() {
    let mut r = renderer();
    let vol = radial(64, |d| d);
    r.set_volume(&vol).unwrap();
    // the skin: red, 40% opaque; the bone inside: blue, opaque
    let colors = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    let alphas = [0.4f32, 1.0];
    let mut p = iso(&[(24.0, colors[0], alphas[0]), (12.0, colors[1], alphas[1])]);
    p.environment_light = 0.0;
    r.set_isosurface(&p).unwrap();
    let mut view = View::fit(vol.bounds(), 96, 96);
    view.camera.zoom(1.5);
    let img = r.render_image(&view, &flat_params()).unwrap();
    save(&img, "iso-nested");
    let g = r.read_gbuffer().unwrap();
    let (mut sequences, mut max_err) = (std::collections::BTreeMap::new(), 0.0f32);
    for y in 0..g.height {
        for x in 0..g.width {
            let hits = g.hits(x, y);
            // the analytic front-to-back composite of this pixel's layers
            let mut want = [0.0f32; 4];
            for h in &hits {
                let w = (1.0 - want[3]) * alphas[h.iso_index];
                for k in 0..3 {
                    want[k] += w * colors[h.iso_index][k];
                }
                want[3] += w;
            }
            let got = img.pixel(x, y);
            for k in 0..4 {
                max_err = max_err.max((got[k] - want[k]).abs());
            }
            let seq: Vec<usize> = hits.iter().map(|h| h.iso_index).collect();
            *sequences.entry(seq).or_insert(0) += 1;
        }
    }
    println!("layer sequences (iso indices front to back: pixels): {sequences:?}");
    println!(
        "max |composite − analytic| = {max_err:.4} (1/255 = {:.4})",
        1.0 / 255.0
    );
    // skin then bone (the opaque bone ends the ray); skin in and out where the bone is missed
    assert!(sequences.get(&vec![0, 1]).copied().unwrap_or(0) > 500);
    assert!(sequences.get(&vec![0, 0]).copied().unwrap_or(0) > 500);
    assert!(sequences
        .keys()
        .all(|s| s.is_empty() || s == &[0, 1] || s == &[0, 0]
        // grazing rays may cross the skin twice within a step of its silhouette
        || s == &[0]));
    // RGBA8 output: half a level of rounding on each side
    assert!(
        max_err <= 1.0 / 255.0 + 1e-6,
        "compositing matches the analytic values"
    );
    // the centre pixel: 0.4 red over opaque blue
    let centre = img.pixel(48, 48);
    println!("centre pixel {centre:?}, expected [0.4, 0, 0.6, 1]");
    assert!((centre[0] - 0.4).abs() < 2.0 / 255.0 && (centre[2] - 0.6).abs() < 2.0 / 255.0);
}

#[test]
fn ambient_occlusion_of_a_plane_and_a_corner() {
    let mut r = renderer();
    // lit by the default sky (what another test left set must not light these images)
    r.set_environment(&Environment::default()).unwrap();
    let n = 48u32;
    let a = 10.5;
    // a flat floor z = a, seen from above
    let plane = volume([n; 3], |_, _, z| z - a);
    r.set_volume(&plane).unwrap();
    let mut p = iso(&[(0.0, [1.0; 3], 1.0)]);
    p.ambient_occlusion = Some(AmbientOcclusion {
        samples: 256,
        steps: 16,
        radius: Some(8.0),
    });
    r.set_isosurface(&p).unwrap();
    let view = View::fit(plane.bounds(), 64, 64);
    r.render_image(&view, &params()).unwrap();
    let g = r.read_gbuffer().unwrap();
    let ao: Vec<f32> = (0..64)
        .flat_map(|y| (0..64).map(move |x| (x, y)))
        .filter_map(|(x, y)| g.hits(x, y).first().map(|h| h.ambient_access))
        .collect();
    let min = ao.iter().cloned().fold(1.0, f32::min);
    println!("plane: {} hits, AO min {min}", ao.len());
    assert!(ao.len() > 1000);
    assert_eq!(min, 1.0, "nothing occludes a flat floor");

    // the inside of a box corner: walls x < a, y < a, z < a; looking into the corner
    let corner = volume([n; 3], |x, y, z| x.min(y).min(z) - a);
    r.set_volume(&corner).unwrap();
    let radius = 8.0;
    let mut view = View::fit(corner.bounds(), 96, 96);
    view.camera.focal_point = DVec3::splat(a + 6.0);
    view.camera.position = DVec3::splat(a + 6.0) + DVec3::new(1.0, 0.8, 1.3).normalize() * 120.0;
    view.camera.view_up = DVec3::Z;
    view.camera.orthogonalize_view_up();
    view.camera.reset_clipping_range(corner.bounds());
    view.camera.zoom(2.5);
    let img = r.render_image(&view, &params()).unwrap();
    save(&img, "iso-corner-ao");
    let g = r.read_gbuffer().unwrap();
    let exact = |dx: f64, dy: f64| corner_accessibility(dx, dy, radius, 150, 300);
    let (mut count, mut sum, mut worst, mut deepest) = (0, 0.0, 0.0f64, (f64::MAX, 0.0, 0.0));
    for y in 0..96 {
        for x in 0..96 {
            let Some(h) = g.hits(x, y).first().copied() else {
                continue;
            };
            let (dx, dy) = (h.position.x - a, h.position.y - a);

            // floor points at least half a voxel from the creases (the interpolated min()
            // is exact there)
            if h.normal.z < 0.999 || dx < 0.5 || dy < 0.5 || dx > 12.0 || dy > 12.0 {
                continue;
            }
            let want = exact(dx, dy);
            let err = (h.ambient_access as f64 - want).abs();
            sum += err;
            worst = worst.max(err);
            count += 1;
            if dx + dy < deepest.0 {
                deepest = (dx + dy, h.ambient_access as f64, want);
            }
        }
    }
    println!(
        "corner: {count} floor hits; AO vs exact: mean error {:.4}, max {worst:.4}; \
         deepest point (dx+dy = {:.2}): AO {:.3}, exact {:.3} (1/4 in the corner itself)",
        sum / count as f64,
        deepest.0,
        deepest.1,
        deepest.2
    );
    assert!(count > 100);
    assert!(deepest.1 < 0.5, "occluded in the corner");
    // 256 Hammersley directions estimate a step-edged integrand: ~1/N^(3/4) per point
    assert!(
        sum / (count as f64) < 0.02,
        "AO within 0.02 of the exact value on average"
    );
    assert!(worst < 0.06);
}

#[test]
fn bricked_equals_unbricked() {
    let mut r = renderer();
    let vol = radial(64, |d| d);
    // translucent skin and bone, so rays cross brick boundaries carrying layers
    let mut p = iso(&[(24.0, [1.0, 0.5, 0.3], 0.4), (12.0, [0.9; 3], 0.5)]);
    p.max_layers = 4;
    r.set_isosurface(&p).unwrap();
    r.set_environment(&Environment::default()).unwrap();
    let mut view = View::fit(vol.bounds(), 96, 96);
    view.camera.azimuth(30.0);
    view.camera.elevation(20.0);
    view.camera.orthogonalize_view_up();
    view.camera.zoom(1.4);
    let mut frames = Vec::new();
    for brick in [None, Some(24)] {
        r.set_volume_with(
            &vol,
            UploadOptions {
                max_brick_points: brick,
                memory_budget: None,
                ..Default::default()
            },
        )
        .unwrap();
        let img = r.render_image(&view, &params()).unwrap();
        frames.push((r.brick_count(), img, r.read_gbuffer().unwrap()));
    }
    let (b0, img0, g0) = &frames[0];
    let (b1, img1, g1) = &frames[1];
    save(img1, "iso-bricked");
    let (mut max_pos, mut max_px, mut layers) = (0.0f64, 0u8, 0);
    for y in 0..96 {
        for x in 0..96 {
            let (h0, h1) = (g0.hits(x, y), g1.hits(x, y));
            assert_eq!(h0.len(), h1.len(), "layers at ({x}, {y})");
            layers += h0.len();
            for (a, b) in h0.iter().zip(&h1) {
                assert_eq!(a.iso_index, b.iso_index);
                max_pos = max_pos.max((a.position - b.position).length());
            }
        }
    }
    for (a, b) in img0.rgba.iter().zip(&img1.rgba) {
        max_px = max_px.max(a.abs_diff(*b));
    }
    println!(
        "{b0} vs {b1} bricks: {layers} layers each, positions differ by {max_pos:.2e} voxel at \
         most, pixels by {max_px} levels"
    );
    assert!(*b1 > 8 && layers > 5000);
    assert!(max_pos < 1e-3, "the same hits, bricked or not");
    assert!(max_px <= 1, "the same image up to rounding");
}

#[test]
fn depth_input_and_clipping_end_rays() {
    let mut r = renderer();
    let vol = synth::sphere(48, 0.8);
    r.set_volume(&vol).unwrap();
    r.set_isosurface(&iso(&[(0.0, [1.0; 3], 1.0)])).unwrap();
    let view = sphere_view(&vol, 48, true);
    let img = r.render_image(&view, &params()).unwrap();
    let hits = img.depth.iter().filter(|&&d| d < 1.0).count();
    // opaque geometry just in front of the surface hides it; just behind, it does not
    let before: Vec<f32> = img
        .depth
        .iter()
        .map(|&d| if d < 1.0 { d - 1e-5 } else { 1.0 })
        .collect();
    let after: Vec<f32> = img
        .depth
        .iter()
        .map(|&d| if d < 1.0 { d + 1e-5 } else { 1.0 })
        .collect();
    r.render(&view, &params(), Some(&before)).unwrap();
    let hidden = r
        .read_image()
        .unwrap()
        .depth
        .iter()
        .filter(|&&d| d < 1.0)
        .count();
    r.render(&view, &params(), Some(&after)).unwrap();
    let shown = r.read_image().unwrap();
    let kept = shown.depth.iter().filter(|&&d| d < 1.0).count();
    println!("{hits} hits; opaque depth just in front: {hidden} remain; just behind: {kept}");
    assert_eq!(hidden, 0);
    assert_eq!(kept, hits);
    // a clipping plane through the centre keeps x ≥ 23.5: every hit on the kept side
    let p = with_clip_plane(params(), DVec3::splat(23.5), DVec3::X);
    // the frame's first hits: how many, and their smallest coordinate `axis`
    let first_hits = |r: &mut Renderer, p: &RenderParams, axis: usize| {
        r.render_image(&view, p).unwrap();
        let g = r.read_gbuffer().unwrap();
        let c: Vec<f64> = (0..48)
            .flat_map(|y| (0..48).map(move |x| (x, y)))
            .filter_map(|(x, y)| g.hits(x, y).first().map(|h| h.position[axis]))
            .collect();
        (c.len(), c.iter().cloned().fold(f64::MAX, f64::min))
    };
    let (n, min_x) = first_hits(&mut r, &p, 0);
    println!("clipped: {n} hits, smallest x {min_x:.4}");
    assert!(n > 200 && min_x >= 23.5 - 1e-3);
    // cropping to the sub-volume y ≥ 23.5 (VTK's region flags): hits only there
    let p = RenderParams {
        cropping: Some(Cropping {
            planes: [-1.0, 100.0, 23.5, 100.0, -1.0, 100.0],
            regions: Cropping::SUBVOLUME,
        }),
        ..params()
    };
    let (n, min_y) = first_hits(&mut r, &p, 1);
    println!("cropped: {n} hits, smallest y {min_y:.4}");
    // a crossing is found between a cropped-away sample and the next kept one: up to a
    // sample step outside the region
    assert!(n > 200 && min_y >= 23.5 - 1.0);
}

#[test]
fn errors_say_what_is_wrong() {
    let mut r = renderer();
    let vol = synth::sphere(16, 0.5);
    r.set_volume(&vol).unwrap();
    let check = |res: Result<()>, words: &[&str]| {
        assert_error(res, "", words);
    };
    let good = iso(&[(0.0, [1.0; 3], 1.0)]);
    let with = |f: &dyn Fn(&mut IsoParams)| {
        let mut p = good.clone();
        f(&mut p);
        p
    };
    check(
        r.set_isosurface(&with(&|p| p.values.clear())),
        &["0 iso-values", "1 to 8"],
    );
    check(
        r.set_isosurface(&with(&|p| p.values = vec![p.values[0]; 9])),
        &["9 iso-values"],
    );
    check(
        r.set_isosurface(&with(&|p| p.values[0].value = f64::NAN)),
        &["finite"],
    );
    check(
        r.set_isosurface(&with(&|p| p.values[0].opacity = 0.0)),
        &["opacity 0", "(0, 1]"],
    );
    check(
        r.set_isosurface(&with(&|p| p.values[0].color = [2.0, 0.0, 0.0])),
        &["colour"],
    );
    check(
        r.set_isosurface(&with(&|p| p.bisection_steps = 40)),
        &["40 bisection"],
    );
    check(
        r.set_isosurface(&with(&|p| p.max_layers = 0)),
        &["0 layers"],
    );
    check(
        r.set_isosurface(&with(&|p| p.specular_samples = 5000)),
        &["5000 specular samples", "1 to 1024"],
    );
    check(
        r.set_isosurface(&with(&|p| {
            p.ambient_occlusion = Some(AmbientOcclusion {
                samples: 0,
                ..Default::default()
            })
        })),
        &["0 ambient-occlusion directions"],
    );
    check(
        r.set_isosurface(&with(&|p| {
            p.ambient_occlusion = Some(AmbientOcclusion {
                radius: Some(-1.0),
                ..Default::default()
            })
        })),
        &["radius -1"],
    );
    check(
        r.set_isosurface(&with(&|p| p.fresnel = Some(1.5))),
        &["Fresnel"],
    );
    check(
        r.set_isosurface(&with(&|p| {
            p.shininess = Shininess::GradientMagnitude {
                range: Some([2.0, 1.0]),
                exponents: [1.0, 2.0],
            }
        })),
        &["low < high"],
    );
    check(
        r.set_isosurface(&with(&|p| p.environment_light = -1.0)),
        &["environment light"],
    );
    // isosurface frames need iso-values
    let mut fresh = Renderer::new(r.context().clone()).unwrap();
    fresh.set_volume(&vol).unwrap();
    let view = View::fit(vol.bounds(), 8, 8);
    check(fresh.render(&view, &params(), None), &["set_isosurface"]);
    check(fresh.read_gbuffer().map(|_| ()), &["no isosurface frame"]);
    check(fresh.read_irradiance().map(|_| ()), &["no environment"]);
}

/// Scattering between the isosurfaces (the fast path) on nested spheres under a constant
/// environment of radiance 1, the surfaces' own shading off (all material weights 0), so
/// that a pixel shows (1 − F)·(scattered light), F Schlick's term at the outer surface:
/// without absorption both versions give the inner colour (the environment seen through
/// no medium); with a constant extinction σ the preview gives the inner colour × e^(−2σL),
/// L the distance between the two surfaces along the ray.
#[test]
fn scattering_between_isosurfaces() {
    let mut r = renderer();
    let vol = radial(64, |d| d);
    r.set_volume(&vol).unwrap();
    let sigma_alpha = 0.05f32;
    let color = Piecewise::new(vec![(0.0, [1.0; 3]), (60.0, [1.0; 3])]).unwrap();
    let opacity = Piecewise::new(vec![(0.0, [sigma_alpha]), (60.0, [sigma_alpha])]).unwrap();
    r.set_transfer_function(&TransferFunction::single(ComponentTransfer::new(
        color, opacity,
    )))
    .unwrap();
    r.set_environment(&Environment::constant([1.0; 3])).unwrap();
    let inner = [0.2f32, 0.9, 0.5];
    let mut view = View::fit(vol.bounds(), 64, 64);
    view.camera.zoom(1.5);
    view.lights.clear();
    let dark = RenderParams {
        blend: BlendMode::Isosurface,
        shading: Shading {
            enabled: true,
            ambient: 0.0,
            diffuse: 0.0,
            specular: 0.0,
            ..Shading::default()
        },
        ..RenderParams::default()
    };
    let f0 = 0.04;
    let run = |r: &mut Renderer, mode, absorption| {
        let mut p = iso(&[(24.0, [1.0, 0.3, 0.3], 1.0), (12.0, inner, 1.0)]);
        p.environment_light = 1.0;
        p.scattering = Some(IsoScattering {
            mode,
            samples: 64,
            absorption,
            fresnel: f0 as f32,
        });
        r.set_isosurface(&p).unwrap();
        let img = r.render_image(&view, &dark).unwrap();
        (img, r.read_gbuffer().unwrap())
    };
    // The pixels whose ray crosses both spheres: (x, y, Schlick's F at the outer surface,
    // the distance between the surfaces).
    let both_spheres = |g: &GBuffer| {
        let mut found = Vec::new();
        for y in 0..64 {
            for x in 0..64 {
                let hits = g.hits(x, y);
                if hits.len() < 2 || hits[1].iso_index != 1 {
                    continue;
                }
                let v = (view.camera.position - hits[0].position).normalize();
                let f = f0 + (1.0 - f0) * (1.0 - hits[0].normal.dot(v).clamp(0.0, 1.0)).powi(5);
                found.push((x, y, f, (hits[1].position - hits[0].position).length()));
            }
        }
        found
    };
    let sigma = -(1.0 - sigma_alpha as f64).ln();
    let mut worst = [0.0f64; 3];
    let mut count = 0;
    let mut traced_ratio = (0.0, 0.0);
    for (k, (mode, absorption)) in [
        (IsoScatterMode::Preview, 0.0f32),
        (IsoScatterMode::Traced, 0.0),
        (IsoScatterMode::Preview, 1.0),
    ]
    .into_iter()
    .enumerate()
    {
        let (img, g) = run(&mut r, mode, absorption);
        save(&img, &format!("iso-scatter-{k}"));
        for (x, y, f, len) in both_spheres(&g) {
            let t2 = (-2.0 * sigma * absorption as f64 * len).exp();
            let got = img.pixel(x, y);
            for ch in 0..3 {
                let want = (1.0 - f) * inner[ch] as f64 * t2;
                worst[k] = worst[k].max((got[ch] as f64 - want).abs());
            }
            if k == 0 {
                count += 1;
            }
            if k == 2 {
                traced_ratio.0 += got[1] as f64;
                traced_ratio.1 += (1.0 - f) * inner[1] as f64;
            }
        }
    }
    println!(
        "{count} pixels with both spheres: max error, preview without absorption {:.4}, \
         traced without absorption {:.4}, preview with σ = {sigma:.4}/unit {:.4}; mean \
         transmittance² there {:.3}",
        worst[0],
        worst[1],
        worst[2],
        traced_ratio.0 / traced_ratio.1
    );
    assert!(count > 250);
    // 8-bit output (half a level), the irradiance cube within 0.15% of a constant
    for w in worst {
        assert!(w <= 1.5 / 255.0, "{worst:?}");
    }
    // (the absorbed case is visibly darker)
    assert!(traced_ratio.0 / traced_ratio.1 < 0.5);
    // A binary mask empties the medium it leaves out: a mask of ones changes nothing; one
    // leaving out the shell 13 < d < 23 between the surfaces (their crossings kept) leaves
    // about 2 of the L units absorbing.
    let (absorbed, _) = run(&mut r, IsoScatterMode::Preview, 1.0);
    let shell: Vec<u8> = (0..64 * 64 * 64)
        .map(|i| {
            let p = [i % 64, (i / 64) % 64, i / 4096].map(|v| v as f64 - 31.5);
            let d = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            u8::from(!(13.0..23.0).contains(&d))
        })
        .collect();
    r.set_mask(Some((&[1u8; 64 * 64 * 64][..], MaskKind::Binary)))
        .unwrap();
    let (ones, _) = run(&mut r, IsoScatterMode::Preview, 1.0);
    assert_eq!(ones.rgba, absorbed.rgba, "a mask of ones");
    r.set_mask(Some((&shell, MaskKind::Binary))).unwrap();
    let (masked, g) = run(&mut r, IsoScatterMode::Preview, 1.0);
    r.set_mask(None).unwrap();
    let (mut got, mut free) = (0.0, 0.0);
    for (x, y, f, _) in both_spheres(&g) {
        got += masked.pixel(x, y)[1] as f64;
        free += (1.0 - f) * inner[1] as f64;
    }
    println!(
        "mean transmittance² with the shell between the surfaces masked: {:.3}",
        got / free
    );
    assert!(got / free > 0.7, "the masked medium absorbs nothing");
}
