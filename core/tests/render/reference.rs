//! The GPU image against the f64 CPU reference of the ray caster (common/raycast.rs):
//! shaded compositing with linear and nearest interpolation, and depth in and out.

use crate::common::gpu::renderer;
use crate::common::images::save_enlarged;
use crate::common::metrics::{
    alpha, compare_to_reference, footprint, image_diff, pixels_off_by_more, reference_image,
};
use crate::common::raycast::{self, pixel_ray};
use crate::common::scenes::{blob_transfer, blob_volume, shaded, volume, with_clip_plane};
use ferrovol_core::*;
use glam::DVec3;

// ---------------------------------------------------------------------------------------
// The GPU image against an f64 CPU reference
// ---------------------------------------------------------------------------------------

/// The blob on an anisotropic grid away from the origin.
fn aniso_blob() -> VolumeData {
    blob_volume(24)
        .with_spacing([1.0, 0.8, 1.2])
        .unwrap()
        .with_origin([-5.0, 3.0, 0.5])
        .unwrap()
}

#[test]
fn cpu_reference_composite_shaded() {
    let mut r = renderer();
    let aniso = aniso_blob();
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
        let (refc, _) = raycast::render(vol, tf, &view, &params, dt);
        save_enlarged(&img, name);
        save_enlarged(&reference_image(&refc, 64, 64), &format!("{name}_cpu"));
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
            let (refc_central, _) = raycast::render(vol, tf, &view, &other, dt);
            let (_, psnr_central, _) = compare_to_reference(&img, &refc_central);
            println!("{name}: against central differences PSNR {psnr_central:.1} dB");
            assert!(
                psnr > psnr_central + 6.0,
                "{name}: forward differences not told from central ({psnr:.1} against {psnr_central:.1} dB)"
            );
        }
    }
}

/// Cubic B-spline interpolation against the CPU reference's B-spline (and clearly apart from
/// the trilinear reference), shaded, on a field that changes within a few voxels; its cost is
/// printed (frame time against trilinear).
#[test]
fn cpu_reference_cubic() {
    let mut r = renderer();
    let vol = volume([20; 3], |x, y, z| {
        0.5 + 0.45 * (0.9 * x).sin() * (0.7 * y).cos() * (0.8 * z + 0.3).sin()
    })
    .with_spacing([1.0, 0.8, 1.2])
    .unwrap();
    let tf = blob_transfer();
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(tf.clone()))
        .unwrap();
    let mut view = View::fit(vol.bounds(), 64, 64);
    view.camera.azimuth(35.0);
    view.camera.elevation(-25.0);
    view.camera.orthogonalize_view_up();
    view.camera.reset_clipping_range(vol.bounds());
    let cubic = RenderParams {
        interpolation: Interpolation::Cubic,
        ..shaded()
    };
    let dt = r.sample_distance(&cubic).unwrap();
    let img = r.render_image(&view, &cubic).unwrap();
    let (refc, _) = raycast::render(&vol, &tf, &view, &cubic, dt);
    let linear = RenderParams {
        interpolation: Interpolation::Linear,
        ..cubic.clone()
    };
    let (refl, _) = raycast::render(&vol, &tf, &view, &linear, dt);
    save_enlarged(&img, "cpu_reference_cubic");
    save_enlarged(&reference_image(&refc, 64, 64), "cpu_reference_cubic_cpu");
    let (mae, psnr, max) = compare_to_reference(&img, &refc);
    let (_, psnr_linear, _) = compare_to_reference(&img, &refl);
    let time = |p: &RenderParams, r: &mut Renderer| {
        r.render_image(&view, p).unwrap();
        let t = std::time::Instant::now();
        for _ in 0..5 {
            r.render_image(&view, p).unwrap();
        }
        t.elapsed().as_secs_f64()
    };
    let (tc, tl) = (time(&cubic, &mut r), time(&linear, &mut r));
    println!(
        "cubic: mean abs error {mae:.3}/255, max {max:.1}/255, PSNR {psnr:.1} dB against the \
         B-spline reference, {psnr_linear:.1} dB against the trilinear one; frame time {:.2}x \
         trilinear",
        tc / tl
    );
    assert!(footprint(&img) > 400);
    assert!(psnr >= 35.0 && mae < 1.5, "{psnr} {mae}");
    assert!(psnr > psnr_linear + 6.0, "cubic not told from trilinear");
}

// ---------------------------------------------------------------------------------------
// Depth in, depth out
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
    let clip = with_clip_plane(shaded(), DVec3::new(0.0, 0.0, zc), DVec3::Z);
    let clipped = r.render_image(&view, &clip).unwrap();
    save_enlarged(&full, "depth_full");
    save_enlarged(&cut, "depth_cut");
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
    let (_, ref_depth) = raycast::render(&vol, &tf, &view, &params, dt);
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
// Nearest-neighbour interpolation against the f64 reference
// ---------------------------------------------------------------------------------------

#[test]
fn cpu_reference_nearest() {
    let mut r = renderer();
    // small enough that a voxel covers ~2 pixels, so nearest's blocks show
    let vol = aniso_blob();
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
            let (refc, _) = raycast::render(&vol, &tf, &view, &params, dt);
            save_enlarged(&img, &name);
            save_enlarged(&reference_image(&refc, w, h), &format!("{name}_cpu"));
            let (mae, psnr, max) = compare_to_reference(&img, &refc);
            let big = pixels_off_by_more(&img, &refc, 8.0);
            // What the test tells apart: the same GPU image against the linear reference,
            // and the renderer's own linear image against the nearest reference.
            let linear = RenderParams {
                interpolation: Interpolation::Linear,
                ..params.clone()
            };
            let (ref_lin, _) = raycast::render(&vol, &tf, &view, &linear, dt);
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

/// Isosurfaces of the cubic B-spline: on a linear field they are the trilinear ones (the
/// B-spline keeps linear fields); on a field that changes within a few voxels they move.
#[test]
fn cubic_isosurfaces() {
    let mut r = renderer();
    let mut moved = Vec::new();
    for (name, vol, value) in [
        (
            "ramp",
            volume([20; 3], |x, _, z| 0.3 + 0.02 * z + 0.005 * x),
            0.5,
        ),
        (
            "waves",
            volume([20; 3], |x, y, z| {
                0.5 + 0.45 * (0.9 * x).sin() * (0.7 * y).cos() * (0.8 * z + 0.3).sin()
            }),
            0.7,
        ),
    ] {
        r.set_volume(&vol).unwrap();
        r.set_isosurface(&IsoParams::with_values(vec![IsoValue::new(
            value,
            [0.9, 0.8, 0.6],
            1.0,
        )]))
        .unwrap();
        let view = View::fit(vol.bounds(), 64, 64);
        let p = |interpolation| RenderParams {
            blend: BlendMode::Isosurface,
            interpolation,
            ..shaded()
        };
        let linear = r.render_image(&view, &p(Interpolation::Linear)).unwrap();
        let cubic = r.render_image(&view, &p(Interpolation::Cubic)).unwrap();
        save_enlarged(&cubic, &format!("cubic_isosurface_{name}"));
        let (mean, max) = image_diff(&linear, &cubic);
        println!("{name}: cubic vs trilinear isosurface: mean {mean:.3}, max {max} levels");
        assert!(footprint(&cubic) > 400, "{name}: drawn");
        moved.push(mean);
    }
    assert!(
        moved[0] < 0.5,
        "a linear field's surface moved by {}",
        moved[0]
    );
    assert!(
        moved[1] > 2.0,
        "the waves' surfaces did not move ({})",
        moved[1]
    );
}
