//! Bricking is invisible in every mode: a volume forced into many small bricks (an upload
//! option, so that small test volumes exercise what large ones need) renders what it
//! renders as one brick in every ray-casting blend mode, with volumetric shadows, as
//! isosurfaces with ambient occlusion and with scattering between them, and path traced;
//! ambient-occlusion rays see occluders across a brick face.
//!
//! Every pass samples a bricked volume through the page table (shaders/lib/volume.wgsl,
//! `locate`) on the same per-ray lattice as one brick, and bricks overlap by an apron of two
//! points, so the images may differ only by f32 rounding where a sample falls on a brick
//! face (which brick serves it) and by the 8-bit output: a level or two of 255.

use crate::common::gpu::{pt_params, renderer, set_bricked, trace};
use crate::common::images::{save_enlarged, save_rgb};
use crate::common::metrics::{corner_accessibility, flip, footprint, image_diff, srgb8};
use crate::common::scenes::{
    blob_transfer, blob_volume, component_transfer, oblique, radial, shaded, volume, white,
};
use ferrovol_core::*;
use glam::DVec3;
use std::collections::HashSet;

/// Fewest bricks a bricked upload must give for these tests to mean anything: at least two
/// along each axis, so that rays cross brick faces in every direction.
const MIN_BRICKS: usize = 8;

/// Renders with `vol` uploaded as one brick, then as bricks of at most `max_points` points
/// per axis: (bricks, the one-brick result, the bricked result).
fn one_and_bricked<T>(
    r: &mut Renderer,
    vol: &VolumeData,
    max_points: u32,
    mut render: impl FnMut(&mut Renderer) -> T,
) -> (usize, T, T) {
    r.set_volume(vol).unwrap();
    assert_eq!(r.brick_count(), 1, "the test volume fits one brick");
    let one = render(r);
    set_bricked(r, vol, max_points);
    let bricks = r.brick_count();
    assert!(
        bricks >= MIN_BRICKS,
        "only {bricks} bricks of {max_points} points"
    );
    let split = render(r);
    (bricks, one, split)
}

/// Fails unless `img` shows something: a test that passes on empty frames proves nothing.
/// At least a tenth of the pixels covered, a channel of 64/255 or more, and 50 distinct
/// pixel values (not one flat colour).
pub(crate) fn assert_content(img: &Image, name: &str) {
    let pixels = (img.width * img.height) as usize;
    let covered = footprint(img);
    let brightest = img
        .rgba
        .chunks(4)
        .map(|p| p[0].max(p[1]).max(p[2]))
        .max()
        .unwrap_or(0);
    let distinct = img
        .rgba
        .chunks(4)
        .map(|p| [p[0], p[1], p[2], p[3]])
        .collect::<HashSet<_>>()
        .len();
    println!(
        "  {name}: {covered}/{pixels} pixels covered, brightest channel {brightest}/255, \
         {distinct} distinct pixel values"
    );
    assert!(
        covered * 10 >= pixels,
        "{name}: only {covered} pixels covered"
    );
    assert!(brightest >= 64, "{name}: brightest channel {brightest}/255");
    assert!(distinct >= 50, "{name}: {distinct} distinct pixel values");
}

/// Prints the difference of the one-brick and bricked frames of case `name`, saves both as
/// `bricks_NAME_{one,split}.png` and returns a failure when a channel differs by more than
/// `levels`.
fn compare(name: &str, bricks: usize, one: &Image, split: &Image, levels: u8) -> Option<String> {
    assert_content(one, &format!("{name}, one brick"));
    assert_content(split, &format!("{name}, {bricks} bricks"));
    save_enlarged(one, &format!("bricks_{name}_one"));
    save_enlarged(split, &format!("bricks_{name}_split"));
    let (mean, max) = image_diff(one, split);
    let off = one
        .rgba
        .iter()
        .zip(&split.rgba)
        .filter(|(a, b)| a.abs_diff(**b) > 1)
        .count();
    println!(
        "{name}: {bricks} bricks vs one: mean abs diff {mean:.4}/255, max {max}/255, {off} \
         channels off by more than 1"
    );
    (max > levels).then(|| format!("{name}: max {max}/255 ({off} channels > 1)"))
}

/// Every ray-casting blend mode and volumetric shadows, one brick against 125 bricks of a
/// 32³ blob (bricks of 12 points: 7 cells and a 2-point apron on each side).
#[test]
fn bricked_equals_unbricked_in_every_dvr_mode() {
    let mut r = renderer();
    let vol = blob_volume(32);
    // MinIP of the inverted volume with a mirrored opacity map shows the blob as MIP does
    // (rays through the blob find a low minimum, not the box's corners)
    let inverted = VolumeData::new(
        [32; 3],
        1,
        Scalars::F32(
            (0..32usize.pow(3))
                .map(|i| (1.0 - vol.scalars.get(i)) as f32)
                .collect(),
        ),
    )
    .unwrap();
    let view = oblique(&vol, 72);
    let centre = {
        let b = vol.bounds();
        DVec3::new(b[0] + b[1], b[2] + b[3], b[4] + b[5]) * 0.5
    };
    // volumetric shadows: a directional light from −x, a little above, shadow rays across
    // the whole volume (reach 1), so that they cross many bricks
    let mut lit_view = view.clone();
    lit_view.lights = vec![Light::directional(
        centre + DVec3::new(-100.0, 30.0, 20.0),
        centre,
        1.0,
    )];
    let volumetric = |blending: f32| {
        let mut p = shaded();
        p.shading.volumetric_blending = blending;
        p.shading.global_illumination_reach = 1.0;
        p
    };
    let blend = |mode: BlendMode| RenderParams {
        blend: mode,
        ..RenderParams::default()
    };
    let colourful = TransferFunction::single(blob_transfer());
    let ramp = TransferFunction::ramp([0.0, 1.0], 0.8);
    let cases: Vec<(&str, &VolumeData, TransferFunction, RenderParams, &View)> = vec![
        (
            "composite",
            &vol,
            colourful.clone(),
            RenderParams::default(),
            &view,
        ),
        ("composite_shaded", &vol, colourful.clone(), shaded(), &view),
        (
            "mip",
            &vol,
            white(&[(0.0, 0.0), (1.0, 1.0)], 1.0),
            blend(BlendMode::Maximum),
            &view,
        ),
        (
            "minip",
            &inverted,
            white(&[(0.0, 1.0), (1.0, 0.0)], 1.0),
            blend(BlendMode::Minimum),
            &view,
        ),
        (
            "average",
            &vol,
            ramp.clone(),
            // samples below 0.2 (most of the box) left out of the average
            RenderParams {
                average_range: Some([0.2, 1.0]),
                ..blend(BlendMode::Average)
            },
            &view,
        ),
        ("additive", &vol, ramp, blend(BlendMode::Additive), &view),
        (
            "volumetric_shadows",
            &vol,
            colourful.clone(),
            volumetric(2.0),
            &lit_view,
        ),
        (
            "volumetric_blended",
            &vol,
            colourful,
            volumetric(1.0),
            &lit_view,
        ),
    ];
    let mut failures = Vec::new();
    for (name, v, tf, params, view) in &cases {
        r.set_transfer_function(tf).unwrap();
        let (bricks, one, split) =
            one_and_bricked(&mut r, v, 12, |r| r.render_image(view, params).unwrap());
        failures.extend(compare(name, bricks, &one, &split, 2));
    }
    assert!(
        failures.is_empty(),
        "bricked rendering differs: {failures:?}"
    );
}

/// Isosurface frames with the given iso-values and extra settings.
fn iso_params(values: &[(f64, [f32; 3], f32)], f: impl FnOnce(&mut IsoParams)) -> IsoParams {
    let mut p = IsoParams::with_values(
        values
            .iter()
            .map(|&(v, c, a)| IsoValue::new(v, c, a))
            .collect(),
    );
    f(&mut p);
    p
}

/// Isosurface frames lit by the headlight, two-sided, with VTK's material.
fn iso_render_params() -> RenderParams {
    RenderParams {
        blend: BlendMode::Isosurface,
        shading: Shading {
            enabled: true,
            ..Shading::default()
        },
        ..RenderParams::default()
    }
}

/// The ambient accessibility of every hit, pixel by pixel, front to back; fails unless both
/// G-buffers hold the same number of layers at every pixel.
fn hit_ao(a: &GBuffer, b: &GBuffer) -> Vec<(f32, f32)> {
    let mut ao = Vec::new();
    for y in 0..a.height {
        for x in 0..a.width {
            let (ha, hb) = (a.hits(x, y), b.hits(x, y));
            assert_eq!(ha.len(), hb.len(), "layers at ({x}, {y})");
            ao.extend(
                ha.iter()
                    .zip(&hb)
                    .map(|(p, q)| (p.ambient_access, q.ambient_access)),
            );
        }
    }
    ao
}

/// Isosurfaces with ambient occlusion, and with scattering between two of them (preview and
/// traced), one brick against 125.
#[test]
fn bricked_isosurfaces_equal_unbricked() {
    let mut r = renderer();
    // the default sky: directional light that AO and the traced scattering both see
    r.set_environment(&Environment::default()).unwrap();
    let mut failures = Vec::new();

    // AO on the two blobs: the small one shadows the large one's flank (default radius:
    // 8 voxels, several bricks of 7 cells)
    let blob = blob_volume(32);
    let p = iso_params(
        &[(0.4, [0.9, 0.85, 0.8], 1.0), (0.2, [0.3, 0.5, 0.9], 0.4)],
        |p| {
            p.ambient_occlusion = Some(AmbientOcclusion {
                samples: 32,
                steps: 8,
                radius: None,
            })
        },
    );
    r.set_isosurface(&p).unwrap();
    let mut view = oblique(&blob, 72);
    view.camera.zoom(2.0);
    let (bricks, (one, g_one), (split, g_split)) = one_and_bricked(&mut r, &blob, 12, |r| {
        let img = r.render_image(&view, &iso_render_params()).unwrap();
        (img, r.read_gbuffer().unwrap())
    });
    failures.extend(compare("iso_ao", bricks, &one, &split, 2));
    let pairs = hit_ao(&g_one, &g_split);
    let occluded = pairs.iter().filter(|(x, _)| *x < 1.0).count();
    let max_ao = pairs.iter().map(|(x, y)| (x - y).abs()).fold(0.0, f32::max);
    let mean_ao = pairs.iter().map(|(x, y)| (x - y).abs() as f64).sum::<f64>() / pairs.len() as f64;
    println!(
        "iso_ao: {} hits, {occluded} occluded; AO {bricks} bricks vs one: mean abs diff \
         {mean_ao:.5}, max {max_ao:.4} (one direction: {:.4})",
        pairs.len(),
        1.0 / 32.0
    );
    assert!(occluded > 200, "too little occlusion to test: {occluded}");
    // a direction may flip where an AO sample lies on the iso-value within f32 rounding
    if max_ao > 1.5 / 32.0 || mean_ao > 1e-3 {
        failures.push(format!("iso_ao: AO mean {mean_ao}, max {max_ao}"));
    }

    // scattering between nested spheres (radius 15 outside, 8 inside) in a medium of
    // constant extinction: light paths from the inner surface out through the medium cross
    // bricks of 14 points (9 cells)
    let spheres = radial(40, |d| d);
    let sigma_alpha = 0.05f32;
    r.set_transfer_function(&TransferFunction::single(component_transfer(
        &[(0.0, [1.0; 3]), (40.0, [1.0; 3])],
        &[(0.0, sigma_alpha), (40.0, sigma_alpha)],
        1.0,
    )))
    .unwrap();
    let mut view = View::fit(spheres.bounds(), 64, 64);
    view.camera.azimuth(20.0);
    view.camera.elevation(15.0);
    view.camera.orthogonalize_view_up();
    view.camera.zoom(1.5);
    for (name, mode) in [
        ("iso_scatter_preview", IsoScatterMode::Preview),
        ("iso_scatter_traced", IsoScatterMode::Traced),
    ] {
        let p = iso_params(
            &[(15.0, [1.0, 0.4, 0.3], 1.0), (8.0, [0.2, 0.9, 0.5], 1.0)],
            |p| {
                p.environment_light = 1.0;
                p.scattering = Some(IsoScattering {
                    mode,
                    samples: 32,
                    absorption: 1.0,
                    fresnel: 0.04,
                });
            },
        );
        r.set_isosurface(&p).unwrap();
        let (bricks, one, split) = one_and_bricked(&mut r, &spheres, 14, |r| {
            r.render_image(&view, &iso_render_params()).unwrap()
        });
        failures.extend(compare(name, bricks, &one, &split, 2));
    }
    assert!(
        failures.is_empty(),
        "bricked isosurfaces differ: {failures:?}"
    );
}

/// The inside of a box corner seen from above: walls x < a, y < a and floor z < a, with
/// ambient occlusion of `radius` world units; bricks of 16 points put brick faces at x, y,
/// z = 11 and 22 (11 cells a brick).
///
/// A floor point with x > 11 and y > 11 lies in a brick beyond the faces x = 11 and
/// y = 11 while the walls it is occluded by (x < a or y < a, a = 8.5) lie in the bricks
/// before them, out of reach of its brick's two-point apron (which ends at 9): every AO
/// direction that is blocked there is blocked across a brick face. AO rays that stop at the
/// edge of their brick (counting as open, as when each brick was rendered on its own) give
/// these points an accessibility of exactly 1, where one brick gives down to ~0.5 next to
/// the walls; the test requires the one-brick values there, and that they are well below 1.
#[test]
fn ambient_occlusion_crosses_brick_faces() {
    let mut r = renderer();
    r.set_environment(&Environment::default()).unwrap();
    let n = 40u32;
    let a = 8.5;
    let face = 11.0;
    let radius = 6.0;
    let samples = 64u32;
    let corner = volume([n; 3], |x, y, z| x.min(y).min(z) - a);
    let p = iso_params(&[(0.0, [1.0; 3], 1.0)], |p| {
        p.ambient_occlusion = Some(AmbientOcclusion {
            samples,
            steps: 24,
            radius: Some(radius),
        })
    });
    r.set_isosurface(&p).unwrap();
    let mut view = View::fit(corner.bounds(), 80, 80);
    view.camera.focal_point = DVec3::splat(a + 5.0);
    view.camera.position = DVec3::splat(a + 5.0) + DVec3::new(1.0, 0.8, 1.3).normalize() * 120.0;
    view.camera.view_up = DVec3::Z;
    view.camera.orthogonalize_view_up();
    view.camera.reset_clipping_range(corner.bounds());
    view.camera.zoom(2.5);
    let (bricks, (one, g_one), (split, g_split)) = one_and_bricked(&mut r, &corner, 16, |r| {
        let img = r.render_image(&view, &iso_render_params()).unwrap();
        (img, r.read_gbuffer().unwrap())
    });
    assert_content(&one, "AO corner, one brick");
    save_enlarged(&one, "bricks_ao_seam_one");
    save_enlarged(&split, "bricks_ao_seam_split");

    let exact = |dx: f64, dy: f64| corner_accessibility(dx, dy, radius, 100, 200);
    let (mut all, mut all_sum, mut all_max) = (0usize, 0.0f64, 0.0f32);
    let (mut seam, mut seam_sum, mut seam_max, mut seam_ao, mut seam_min) =
        (0usize, 0.0f64, 0.0f32, 0.0f64, 1.0f32);
    let mut exact_err = 0.0;
    for y in 0..view.height {
        for x in 0..view.width {
            let (h1, h2) = (g_one.hits(x, y), g_split.hits(x, y));
            assert_eq!(h1.len(), h2.len(), "layers at ({x}, {y})");
            let (Some(h1), Some(h2)) = (h1.first(), h2.first()) else {
                continue;
            };
            let d = (h1.ambient_access - h2.ambient_access).abs();
            all += 1;
            all_sum += d as f64;
            all_max = all_max.max(d);
            // floor points beyond both faces, within reach of a wall
            let (px, py) = (h1.position.x, h1.position.y);
            if h1.normal.z > 0.999 && px > face && py > face && (px - a < radius || py - a < radius)
            {
                seam += 1;
                seam_sum += d as f64;
                seam_max = seam_max.max(d);
                seam_ao += h1.ambient_access as f64;
                seam_min = seam_min.min(h1.ambient_access);
                exact_err += (h1.ambient_access as f64 - exact(px - a, py - a)).abs();
            }
        }
    }
    let seam_mean_ao = seam_ao / seam as f64;
    println!(
        "AO across brick faces ({bricks} bricks vs one, {samples} directions of {radius} \
         voxels): all {all} first hits: mean abs diff {:.5}, max {all_max:.4}; {seam} floor \
         hits beyond the faces x, y = {face} within reach of a wall: one-brick AO mean \
         {seam_mean_ao:.3}, min {seam_min:.3} (1 where rays stop at a brick face), mean error \
         against the exact value {:.4}; bricked vs one: mean abs diff {:.5}, max {seam_max:.4}",
        all_sum / all as f64,
        exact_err / seam as f64,
        seam_sum / seam as f64,
    );
    assert!(
        all > 2000 && seam > 100,
        "{all} hits, {seam} beyond the faces"
    );
    // the occlusion these points get comes entirely from across a brick face: well below 1
    assert!(
        seam_mean_ao < 0.9 && seam_min < 0.7,
        "too little occlusion beyond the faces to test: mean {seam_mean_ao}, min {seam_min}"
    );
    // and it is the right occlusion: 64 Hammersley directions estimate a step-edged
    // integrand to a few hundredths per point
    assert!(exact_err / seam as f64 <= 0.05);
    // the same samples bricked or not: a direction may flip only where an AO sample lies on
    // the iso-value within f32 rounding (one direction is 1/64)
    assert!(
        all_max <= 1.5 / samples as f32 && all_sum / (all as f64) < 1e-3,
        "bricked AO differs: mean {}, max {all_max}",
        all_sum / all as f64
    );
    assert!(seam_max <= 1.5 / samples as f32);
}

/// Path tracing a scattering blob, one brick against 125, the same seed: the difference is
/// judged against the noise, the difference between two seeds of the one-brick image. The
/// bricked image may follow other paths once a collision decision rounds differently at a
/// brick face, so it is held to "no noisier than another seed" (mean absolute difference,
/// mean FLIP) and "no bias" (mean signed difference within 4 standard errors of the
/// two-seed difference's mean).
#[test]
fn bricked_path_tracing_equals_unbricked() {
    let mut r = renderer();
    let vol = blob_volume(32);
    r.set_transfer_function(&TransferFunction::single(component_transfer(
        &[(0.0, [0.9, 0.7, 0.5]), (1.0, [0.6, 0.8, 0.9])],
        &[(0.0, 0.0), (1.0, 0.6)],
        2.0,
    )))
    .unwrap();
    r.set_environment(&Environment::hemisphere([0.9, 0.95, 1.0], [0.3, 0.25, 0.2]))
        .unwrap();
    let size = 40u32;
    let view = oblique(&vol, size);
    let spp = 256;
    let p = |seed: u32| PathTraceParams {
        samples_per_frame: 64,
        anisotropy: 0.3,
        seed,
        ..Default::default()
    };
    r.set_volume(&vol).unwrap();
    assert_eq!(r.brick_count(), 1);
    let one = trace(&mut r, &view, &p(1), spp);
    let other_seed = trace(&mut r, &view, &p(2), spp);
    set_bricked(&mut r, &vol, 12);
    let bricks = r.brick_count();
    assert!(bricks >= MIN_BRICKS);
    let split = trace(&mut r, &view, &p(1), spp);
    r.render(&view, &pt_params(), None).unwrap();
    save_enlarged(&r.read_image().unwrap(), "bricks_pathtrace_split");

    // per channel: mean abs difference, mean signed difference, standard error of the mean
    let stats = |a: &[[f32; 4]], b: &[[f32; 4]]| {
        let n = a.len() as f64;
        [0, 1, 2].map(|c| {
            let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| (y[c] - x[c]) as f64).collect();
            let mean = d.iter().sum::<f64>() / n;
            let abs = d.iter().map(|v| v.abs()).sum::<f64>() / n;
            let var = d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (abs, mean, (var / n).sqrt())
        })
    };
    let to8 = |img: &[[f32; 4]]| -> Vec<u8> {
        img.iter()
            .flat_map(|v| [0, 1, 2].map(|c| srgb8(v[c] as f64)))
            .collect()
    };
    let (one8, other8, split8) = (to8(&one), to8(&other_seed), to8(&split));
    let (flip_seed, _) = flip(&one8, &other8, size);
    let (flip_split, flip_map) = flip(&one8, &split8, size);
    save_rgb(&one8, size, 6, "bricks_pathtrace_one");
    save_rgb(&flip_map, size, 6, "bricks_pathtrace_flip");

    let mean_radiance = one.iter().map(|v| v[1] as f64).sum::<f64>() / one.len() as f64;
    let covered = one.iter().filter(|v| v[3] > 0.05).count();
    println!(
        "path tracing, {size}² pixels, {spp} paths per pixel: mean green radiance \
         {mean_radiance:.4}, {covered} pixels with coverage > 0.05"
    );
    assert!(
        mean_radiance > 0.05 && covered * 4 > one.len(),
        "the path-traced blob is (nearly) empty"
    );
    let noise = stats(&one, &other_seed);
    let diff = stats(&one, &split);
    for (c, name) in ["red", "green", "blue"].iter().enumerate() {
        let (abs_n, bias_n, se_n) = noise[c];
        let (abs_d, bias_d, _) = diff[c];
        println!(
            "  {name}: {bricks} bricks vs one (same seed): mean abs diff {abs_d:.5}, bias \
             {bias_d:+.5}; another seed (one brick): mean abs diff {abs_n:.5}, bias \
             {bias_n:+.5}, standard error of the mean {se_n:.5}"
        );
        assert!(
            abs_d <= 1.1 * abs_n,
            "{name}: bricked is noisier than another seed"
        );
        assert!(
            bias_d.abs() <= 4.0 * se_n,
            "{name}: bias {bias_d} beyond 4 standard errors ({se_n})"
        );
    }
    println!(
        "  mean FLIP against the one-brick image: bricked (same seed) {flip_split:.4}, another \
         seed {flip_seed:.4}"
    );
    assert!(flip_split <= 1.1 * flip_seed);
}
