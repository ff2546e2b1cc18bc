//! Renderer state: bricking is invisible, only what changed is uploaded, errors name the
//! problem; volumetric shadows and precomputed gradients.

use crate::common::gpu::{assert_error, new_renderer, renderer, set_bricked};
use crate::common::images::save_enlarged;
use crate::common::metrics::{footprint, image_diff, rgba};
use crate::common::scenes::{blob_transfer, blob_volume, piecewise1, shaded};
use ferrovol_core::*;
use glam::DVec3;

// ---------------------------------------------------------------------------------------
// Bricking is invisible
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
    set_bricked(&mut r, &vol, 12);
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
        save_enlarged(one, &format!("bricked_{name}_one"));
        save_enlarged(&split, &format!("bricked_{name}_split"));
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
// Only what changed is uploaded
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
// Errors name the problem
// ---------------------------------------------------------------------------------------

#[test]
fn errors() {
    let mut r = renderer();
    let good = blob_volume(8);

    let mut nan = good.clone();
    if let Scalars::F32(v) = &mut nan.scalars {
        v[3 + 8 * (2 + 8 * 5)] = f32::NAN;
    }
    assert_error(r.set_volume(&nan), "NaN volume", &["NaN", "(3, 2, 5)"]);

    let mut flat = good.clone();
    flat.spacing = [1.0, 0.0, 1.0];
    assert_error(r.set_volume(&flat), "zero spacing", &["spacing along y"]);

    assert_error(
        VolumeData::new([4, 4, 4], 1, Scalars::F32(vec![0.0; 10])),
        "wrong length",
        &["expected 64"],
    );

    r.set_volume(&good).unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let view = View::fit(good.bounds(), 16, 16);
    let plane = ClipPlane {
        origin: DVec3::ZERO,
        normal: DVec3::X,
    };
    for (label, p, words) in [
        (
            "sample distance 0",
            RenderParams {
                sample_distance: Some(0.0),
                ..Default::default()
            },
            "sample distance",
        ),
        (
            "9 clip planes",
            RenderParams {
                clip_planes: vec![plane; 9],
                ..Default::default()
            },
            "9 clipping planes",
        ),
        (
            "clipped voxel value NaN",
            RenderParams {
                clipped_voxel_value: Some([f64::NAN, 0.0, 0.0, 0.0]),
                ..Default::default()
            },
            "clipped voxel value",
        ),
        (
            "termination threshold 0",
            RenderParams {
                termination_threshold: 0.0,
                ..Default::default()
            },
            "termination threshold",
        ),
    ] {
        assert_error(r.render(&view, &p, None), label, &[words]);
    }
    let narrow = View {
        width: 0,
        ..view.clone()
    };
    assert_error(
        r.render(&narrow, &RenderParams::default(), None),
        "0-wide image",
        &["image size"],
    );
    assert_error(
        r.render(&view, &RenderParams::default(), Some(&[0.5; 3])),
        "short depth image",
        &["depth image"],
    );
    let mut bad_tf = blob_transfer();
    bad_tf.unit_distance = 0.0;
    assert_error(
        r.set_transfer_function(&TransferFunction::single(bad_tf)),
        "unit distance 0",
        &["unit distance"],
    );
    // the renderer still works after all that
    r.render_image(&view, &RenderParams::default()).unwrap();
    drop(r);

    // a fresh renderer: no volume, then no transfer function
    let mut fresh = new_renderer();
    let e = assert_error(
        fresh.render(&view, &RenderParams::default(), None),
        "no volume",
        &[],
    );
    assert!(
        e.contains("no volume") || e.contains("no transfer function"),
        "{e}"
    );
    fresh.set_volume(&good).unwrap();
    assert_error(
        fresh.render(&view, &RenderParams::default(), None),
        "no transfer function",
        &["no transfer function"],
    );
    assert_error(
        fresh.read_image(),
        "read before render",
        &["nothing has been rendered"],
    );
}

/// Volumetric shadows (VTK's VolumetricScatteringBlending): a shadow ray toward a light
/// from the side darkens the far half of the blob; blending 0 changes nothing; blending
/// out of range is refused. (Their agreement with VTK 9.2 is the regression suite's:
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
    save_enlarged(&plain, "volumetric_off");
    save_enlarged(&shadowed, "volumetric_on");
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
    assert_error(
        r.render_image(&view, &p),
        "blending 2.5",
        &["volumetric scattering blending"],
    );
}

/// Uploads `vol` in bricks of at most `bricks` points (None: as few as fit), with or without
/// precomputed gradients.
fn upload(r: &mut Renderer, vol: &VolumeData, bricks: Option<u32>, precompute: bool) {
    r.set_volume_with(
        vol,
        UploadOptions {
            max_brick_points: bricks,
            precompute_gradients: Some(precompute),
            ..Default::default()
        },
    )
    .unwrap();
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
            upload(&mut r, &vol, bricks, pre);
            images.push(r.render_image(&view, &shaded()).unwrap());
        }
        let (mean, max) = image_diff(&images[0], &images[1]);
        println!(
            "{} brick(s): precomputed against on-the-fly gradients: mean {mean:.4}/255, max {max}/255",
            r.brick_count()
        );
        save_enlarged(
            &images[1],
            &format!("precomputed_gradients_{}", r.brick_count()),
        );
        assert!(footprint(&images[0]) > 1000);
        assert!(max <= 1, "precomputed gradients differ by {max} levels");
    }
}

/// Shading normals from the opacity's gradient (VTK's ComputeNormalFromOpacity): with an
/// opacity peak the normals turn over past it, so the image changes; precomputed scalar
/// gradients (which gradient opacity at the neighbours reads) give the on-the-fly image;
/// a bricked volume draws the one-brick image, and refuses gradient opacity with it (the
/// neighbours' gradients reach beyond a brick's apron).
#[test]
fn normals_from_opacity() {
    let mut r = renderer();
    let vol = blob_volume(40);
    let peak = crate::common::scenes::component_transfer(
        &[(0.0, [0.9, 0.6, 0.2]), (1.0, [1.0, 1.0, 0.9])],
        &[(0.0, 0.0), (0.2, 0.0), (0.3, 0.3), (0.4, 0.0), (1.0, 0.0)],
        1.0,
    );
    let view = View::fit(vol.bounds(), 80, 80);
    let from_opacity = |on: bool| {
        let mut p = shaded();
        p.shading.normal_from_opacity = on;
        p
    };
    let render = |r: &mut Renderer, tf: &ComponentTransfer, pre: bool, bricks: Option<u32>| {
        upload(r, &vol, bricks, pre);
        r.set_transfer_function(&TransferFunction::single(tf.clone()))
            .unwrap();
        [false, true].map(|on| r.render_image(&view, &from_opacity(on)).unwrap())
    };
    let [scalar, opacity] = render(&mut r, &peak, false, None);
    save_enlarged(&opacity, "normals_from_opacity");
    let (mean, max) = image_diff(&scalar, &opacity);
    println!(
        "normals from opacity vs scalar: mean {mean:.3}/255, max {max}/255; {} pixels covered",
        footprint(&opacity)
    );
    assert!(footprint(&opacity) > 1000);
    // (means over the whole frame, a sixth of it covered)
    assert!(
        mean > 0.5 && max > 30,
        "normals from the opacity change the image"
    );

    let [_, split] = render(&mut r, &peak, false, Some(16));
    let (mean, max) = image_diff(&opacity, &split);
    println!(
        "{} bricks vs one: mean {mean:.4}/255, max {max}/255",
        r.brick_count()
    );
    assert!(
        max <= 2,
        "bricked normals from opacity differ by {max} levels"
    );

    let mut graded = peak.clone();
    graded.gradient_opacity = Some(piecewise1(&[(0.0, 0.2), (0.05, 1.0)]));
    let [plain, fly] = render(&mut r, &graded, false, None);
    let [_, pre] = render(&mut r, &graded, true, None);
    let (mean_go, _) = image_diff(&plain, &fly);
    let (mean, max) = image_diff(&fly, &pre);
    println!(
        "with gradient opacity: vs scalar normals mean {mean_go:.3}/255; precomputed vs \
         on-the-fly mean {mean:.4}/255, max {max}/255"
    );
    assert!(mean_go > 0.5, "normals from the opacity change the image");
    assert!(max <= 1, "precomputed gradients differ by {max} levels");

    set_bricked(&mut r, &vol, 16);
    assert_error(
        r.render(&view, &from_opacity(true), None),
        "normals from opacity, gradient opacity, bricked",
        &["gradient opacity", "bricked"],
    );
}

/// A clipped voxel value (VTK's UseClippedVoxelIntensity): gradients next to a clipping
/// plane read it beyond the plane, so a cut through a shaded blob is lit as a wall; without
/// clipping planes it changes nothing.
#[test]
fn clipped_voxel_value_lights_the_cut() {
    let mut r = renderer();
    let vol = blob_volume(40);
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let view = View::fit(vol.bounds(), 80, 80);
    let b = vol.bounds();
    let centre = DVec3::new(b[0] + b[1], b[2] + b[3], b[4] + b[5]) * 0.5;
    let eye = view.camera.position;
    let cut = |value: Option<[f64; 4]>, planes: bool| RenderParams {
        clip_planes: if planes {
            vec![ClipPlane {
                origin: centre,
                normal: centre - eye,
            }]
        } else {
            vec![]
        },
        clipped_voxel_value: value,
        sample_distance: Some(0.25 * vol.spacing[0]),
        ..shaded()
    };
    let wall = Some([0.0; 4]);
    let data = r.render_image(&view, &cut(None, true)).unwrap();
    let walled = r.render_image(&view, &cut(wall, true)).unwrap();
    save_enlarged(&walled, "clipped_voxel_value");
    let (mean, max) = image_diff(&data, &walled);
    println!("clipped voxel value 0 vs the data beyond the cut: mean {mean:.3}/255, max {max}/255");
    assert!(footprint(&walled) > 1000);
    assert!(mean > 0.5 && max > 30, "the value beyond the cut lights it");
    let whole = r.render_image(&view, &cut(None, false)).unwrap();
    let whole_walled = r.render_image(&view, &cut(wall, false)).unwrap();
    assert_eq!(
        image_diff(&whole, &whole_walled).1,
        0,
        "no plane, no change"
    );
}

/// Blanking (VTK's ghost arrays): a mask hiding half the points leaves those samples out in
/// every ray-casting mode; an all-zero mask changes nothing; a new volume clears the mask;
/// a mask of the wrong length and a bricked volume are refused.
#[test]
fn blanking_leaves_hidden_points_out() {
    let mut r = renderer();
    let vol = blob_volume(24);
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let view = View::fit(vol.bounds(), 64, 64);
    let n = 24usize;
    let half: Vec<u8> = (0..n * n * n).map(|i| u8::from(i % n < n / 2)).collect();
    for blend in [
        BlendMode::Composite,
        BlendMode::Maximum,
        BlendMode::Additive,
    ] {
        let p = RenderParams {
            blend,
            ..RenderParams::default()
        };
        r.set_blanking(None).unwrap();
        let plain = r.render_image(&view, &p).unwrap();
        r.set_blanking(Some(&vec![0; n * n * n])).unwrap();
        let clear = r.render_image(&view, &p).unwrap();
        r.set_blanking(Some(&half)).unwrap();
        let blanked = r.render_image(&view, &p).unwrap();
        save_enlarged(&blanked, &format!("blanking_{blend:?}"));
        let (mean, _) = image_diff(&plain, &blanked);
        println!("{blend:?}: half the points blanked moves the image {mean:.2}/255");
        assert_eq!(
            image_diff(&plain, &clear).1,
            0,
            "{blend:?}: an all-zero mask"
        );
        assert!(mean > 1.0, "{blend:?}: blanking leaves samples out");
    }
    r.set_volume(&vol).unwrap();
    let p = RenderParams::default();
    let fresh = r.render_image(&view, &p).unwrap();
    r.set_blanking(None).unwrap();
    assert_eq!(
        image_diff(&fresh, &r.render_image(&view, &p).unwrap()).1,
        0,
        "a new volume clears the mask"
    );
    assert_error(
        r.set_blanking(Some(&[0; 7])),
        "blanking of the wrong length",
        &["7 values", "24x24x24"],
    );
    set_bricked(&mut r, &vol, 12);
    assert_error(
        r.set_blanking(Some(&half)),
        "blanking a bricked volume",
        &["bricked"],
    );
}

/// The per-pixel ray state (48 bytes a pixel, the largest of a frame's images) is allocated
/// only by frames that keep one: a ray-cast frame that does not stream holds none, an
/// isosurface frame allocates it.
#[test]
fn ray_state_only_where_a_frame_keeps_one() {
    let mut r = new_renderer();
    let vol = blob_volume(24);
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let (w, h) = (512, 384);
    let view = View::fit(vol.bounds(), w, h);
    let state_bytes = 48 * w as u64 * h as u64;
    let mut img = r.render_image(&view, &shaded()).unwrap();
    assert!(img.rgba.chunks(4).any(|p| p[3] > 0), "empty frame");
    let ray_cast = r.context().device_memory().buffer_bytes;
    r.set_isosurface(&IsoParams::with_values(vec![IsoValue::new(
        0.4,
        [0.9, 0.8, 0.7],
        1.0,
    )]))
    .unwrap();
    let iso = RenderParams {
        blend: BlendMode::Isosurface,
        ..Default::default()
    };
    img = r.render_image(&view, &iso).unwrap();
    assert!(
        img.rgba.chunks(4).any(|p| p[3] > 0),
        "empty isosurface frame"
    );
    let with_state = r.context().device_memory().buffer_bytes;
    println!(
        "buffers after a ray-cast frame {ray_cast} bytes, after an isosurface frame \
         {with_state} (the ray state of {w}x{h}: {state_bytes})"
    );
    assert!(
        ray_cast < state_bytes,
        "the ray-cast frame holds a ray state"
    );
    assert!(with_state >= ray_cast + state_bytes);
}
