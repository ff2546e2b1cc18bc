//! Masks, intermixed volumes, 2D tables, isosurfaces and path tracing through the C ABI.

use super::*;

#[test]
fn masks_through_the_c_abi() {
    let lib = Lib::open();
    type SetMask = unsafe extern "C" fn(H, *const u8, usize, u32) -> FvStatus;
    let n = 8usize;
    let mut s = Session::new(&lib);
    s.set_volume([8, 8, 8], FvScalarType::U8, &vec![200u8; n * n * n]);
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 255.0, 1.0, 1.0, 1.0],
        &[0.0, 0.0, 255.0, 0.5],
    );
    s.set_camera(&camera([3.5, 3.5, 18.0], [3.5, 3.5, 3.5], [0.1, 100.0]));
    let pixel = |rgba: &[u8], x: usize, y: usize| -> [u8; 4] {
        let i = 4 * (y * 16 + x);
        [rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]]
    };
    let plain = s.frame(16, 16).to_vec();
    // points with x < 4 hold 0 (binary) / label 2 (label map)
    let left: Vec<u8> = (0..n * n * n).map(|i| u8::from(i % n >= 4)).collect();
    let labels: Vec<u8> = left.iter().map(|&v| if v == 0 { 2 } else { 0 }).collect();
    let set_mask = lib.f::<SetMask>("fv_renderer_set_mask");
    let label_color = lib.f::<SetPoints>("fv_transfer_function_set_label_color");
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        lib.expect(set_mask(s.r, left.as_ptr(), 7, 0), Invalid, "7 values");
        lib.expect(
            set_mask(s.r, left.as_ptr(), left.len(), 2),
            Invalid,
            "mask type 2",
        );
        lib.expect(set_mask(null_mut(), null(), 0, 0), Null, "renderer");
        let red = [0.0, 1.0, 0.0, 0.0, 255.0, 1.0, 0.0, 0.0];
        lib.expect(label_color(s.tf, 0, red.as_ptr(), 2), Invalid, "label 0");
        lib.expect(
            label_color(s.tf, 256, red.as_ptr(), 2),
            Invalid,
            "label 256",
        );
        lib.ok(label_color(s.tf, 2, red.as_ptr(), 2));
        lib.ok(lib.f::<SetH>("fv_renderer_set_transfer_function")(
            s.r, s.tf,
        ));

        lib.ok(set_mask(s.r, left.as_ptr(), left.len(), 0));
        let binary = s.frame(16, 16).to_vec();
        lib.ok(set_mask(s.r, labels.as_ptr(), labels.len(), 1));
        let labelled = s.frame(16, 16).to_vec();
        let mut p = FvRenderParams::defaults();
        p.mask_blend_factor = 2.0;
        lib.expect(
            lib.f::<SetParams>("fv_renderer_set_params")(s.r, &p),
            Invalid,
            "mask blend factor 2",
        );
        p.mask_blend_factor = 0.0;
        s.set_params(&p);
        let unlabelled = s.frame(16, 16).to_vec();
        lib.ok(set_mask(s.r, null(), 0, 0));
        println!(
            "centre: plain {:?}, binary {:?} / {:?}, labelled {:?} / {:?}",
            pixel(&plain, 8, 8),
            pixel(&binary, 4, 8),
            pixel(&binary, 12, 8),
            pixel(&labelled, 4, 8),
            pixel(&labelled, 12, 8)
        );
        assert_eq!(pixel(&binary, 4, 8)[3], 0, "masked side empty");
        assert_eq!(pixel(&binary, 12, 8), pixel(&plain, 12, 8));
        let [r, g, _, a] = pixel(&labelled, 4, 8);
        assert!(a > 100 && r > 100 && g == 0, "label 2 red");
        assert_eq!(pixel(&labelled, 12, 8), pixel(&plain, 12, 8));
        assert_eq!(unlabelled, plain, "blend factor 0 reads no label");
    }
}

#[test]
fn intermixed_volumes_through_the_c_abi() {
    let lib = Lib::open();
    type SetIntermixed = unsafe extern "C" fn(H, *const FvIntermixedVolume, usize) -> FvStatus;
    let n = 8usize;
    let mut s = Session::new(&lib);
    s.set_volume([8, 8, 8], FvScalarType::U8, &vec![200u8; n * n * n]);
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 255.0, 1.0, 1.0, 1.0],
        &[0.0, 0.0, 255.0, 0.2],
    );
    s.set_camera(&camera([3.5, 3.5, 18.0], [3.5, 3.5, 3.5], [0.1, 100.0]));
    let pixel = |rgba: &[u8], x: usize, y: usize| -> [u8; 4] {
        let i = 4 * (y * 16 + x);
        [rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]]
    };
    let plain = s.frame(16, 16).to_vec();
    let set = lib.f::<SetIntermixed>("fv_renderer_set_intermixed_volumes");
    let mut red_volume: H = null_mut();
    let mut red_tf: H = null_mut();
    let mut two: H = null_mut();
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        let data = vec![200u8; n * n * n];
        lib.ok(lib.f::<NewVolume>("fv_volume_new")(
            &desc([8, 8, 8], 1, FvScalarType::U8 as u32),
            data.as_ptr().cast(),
            data.len(),
            &mut red_volume,
        ));
        lib.ok(lib.f::<NewTf>("fv_transfer_function_new")(
            1,
            true,
            &mut red_tf,
        ));
        let red = [0.0, 1.0, 0.0, 0.0, 255.0, 1.0, 0.0, 0.0];
        let opacity = [0.0, 0.0, 255.0, 0.2];
        lib.ok(lib.f::<SetPoints>("fv_transfer_function_set_color")(
            red_tf,
            0,
            red.as_ptr(),
            2,
        ));
        lib.ok(lib.f::<SetPoints>("fv_transfer_function_set_opacity")(
            red_tf,
            0,
            opacity.as_ptr(),
            2,
        ));
        // the red volume moved half its width to +x: it covers the image's right half
        let mut matrix = [0.0; 16];
        for i in 0..4 {
            matrix[5 * i] = 1.0;
        }
        matrix[12] = 4.0;
        let one = FvIntermixedVolume {
            volume: red_volume.cast_const().cast(),
            transfer_function: red_tf.cast_const().cast(),
            matrix,
            interpolation: 1,
        };
        let cubic = FvIntermixedVolume {
            interpolation: 2,
            ..one
        };
        lib.expect(set(s.r, &cubic, 1), Invalid, "volumes[0].interpolation 2");
        lib.expect(
            set(s.r, [one; 4].as_ptr(), 4),
            FvStatus::Unsupported,
            "at most 3",
        );
        lib.expect(set(s.r, null(), 1), Null, "volumes");
        lib.expect(set(null_mut(), null(), 0), Null, "renderer");
        let no_volume = FvIntermixedVolume {
            volume: null(),
            ..one
        };
        lib.expect(set(s.r, &no_volume, 1), Null, "volumes[0].volume");
        let no_tf = FvIntermixedVolume {
            transfer_function: null(),
            ..one
        };
        lib.expect(set(s.r, &no_tf, 1), Null, "volumes[0].transfer_function");
        let data2 = [0u8; 2 * 4 * 4 * 4];
        lib.ok(lib.f::<NewVolume>("fv_volume_new")(
            &desc([4, 4, 4], 2, FvScalarType::U8 as u32),
            data2.as_ptr().cast(),
            data2.len(),
            &mut two,
        ));
        let two_comp = FvIntermixedVolume {
            volume: two.cast_const().cast(),
            ..one
        };
        lib.expect(
            set(s.r, &two_comp, 1),
            FvStatus::Unsupported,
            "2 components",
        );
        lib.ok(set(s.r, &one, 1));
        // the renderer keeps what it needs: the handles may go
        lib.f::<Free>("fv_volume_free")(red_volume);
        lib.f::<Free>("fv_transfer_function_free")(red_tf);
        lib.f::<Free>("fv_volume_free")(two);
        let mixed = s.frame(16, 16).to_vec();
        let mut p = FvRenderParams::defaults();
        p.blend_mode = FvBlendMode::Maximum as u32;
        s.set_params(&p);
        lib.expect(
            lib.f::<Render>("fv_renderer_render")(s.r, 16, 16, null(), 0),
            FvStatus::Unsupported,
            "composite",
        );
        s.set_params(&FvRenderParams::defaults());
        lib.ok(set(s.r, null(), 0));
        let cleared = s.frame(16, 16).to_vec();
        println!(
            "intermixed: plain {:?} / {:?}, mixed {:?} / {:?}",
            pixel(&plain, 5, 8),
            pixel(&plain, 10, 8),
            pixel(&mixed, 5, 8),
            pixel(&mixed, 10, 8),
        );
        let [r, g, b, a] = pixel(&mixed, 10, 8);
        assert!(
            r > g && r > b && a > pixel(&plain, 10, 8)[3],
            "red over white: {r} {g} {b} {a}"
        );
        let [r, g, b, _] = pixel(&mixed, 5, 8);
        assert!(r == g && g == b, "the left half stays white");
        assert_eq!(cleared, plain, "cleared: the main volume alone");
    }
}

#[test]
fn table_2d_through_the_c_abi() {
    let lib = Lib::open();
    type SetTable = unsafe extern "C" fn(H, u32, u32, u32, *const f32, f64, f64, f64) -> FvStatus;
    let mut s = Session::new(&lib);
    s.set_volume([8, 8, 8], FvScalarType::U8, &vec![200u8; 512]);
    s.set_transfer_function(
        &[0.0, 1.0, 1.0, 1.0, 255.0, 1.0, 1.0, 1.0],
        &[0.0, 0.0, 255.0, 0.5],
    );
    s.set_camera(&camera([3.5, 3.5, 18.0], [3.5, 3.5, 3.5], [0.1, 100.0]));
    let white = s.frame(16, 16).to_vec();
    let set_table = lib.f::<SetTable>("fv_transfer_function_set_table_2d");
    // 4 x 2 entries: green and half as opaque as the 1D function over [0, 255]
    let rgba: Vec<f32> = (0..8)
        .flat_map(|_| [0.0, 1.0, 0.0, 0.5 * 200.0 / 255.0])
        .collect();
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        lib.expect(
            set_table(s.tf, 0, 0, 2, rgba.as_ptr(), 0.0, 255.0, 0.0),
            Invalid,
            "0x2",
        );
        lib.expect(
            set_table(s.tf, 1, 4, 2, rgba.as_ptr(), 0.0, 255.0, 0.0),
            Invalid,
            "component 1",
        );
        lib.expect(
            set_table(s.tf, 0, 4, 2, rgba.as_ptr(), 5.0, 5.0, 0.0),
            Invalid,
            "scalar range",
        );
        lib.expect(
            set_table(s.tf, 0, 4, 2, rgba.as_ptr(), 0.0, 255.0, -1.0),
            Invalid,
            "gradient magnitude -1",
        );
        lib.ok(set_table(s.tf, 0, 4, 2, rgba.as_ptr(), 0.0, 255.0, 0.0));
        lib.ok(lib.f::<SetH>("fv_renderer_set_transfer_function")(
            s.r, s.tf,
        ));
        let green = s.frame(16, 16).to_vec();
        let i = 4 * (8 * 16 + 8);
        println!(
            "centre: 1D {:?}, 2D {:?}",
            &white[i..i + 4],
            &green[i..i + 4]
        );
        assert!(
            green[i + 1] > 100 && green[i] == 0 && green[i + 2] == 0,
            "green"
        );
        assert_eq!(green[i + 3], white[i + 3], "the same opacity");
        lib.ok(set_table(s.tf, 0, 0, 0, null(), 0.0, 0.0, 0.0));
        lib.ok(lib.f::<SetH>("fv_renderer_set_transfer_function")(
            s.r, s.tf,
        ));
        assert_eq!(s.frame(16, 16), &white[..], "removed: the 1D image again");
    }
}

/// The isosurface mode through the C ABI: every refusal names its problem, then a sphere
/// renders opaque at the centre and empty in the corner.
#[test]
fn isosurface_errors_and_a_frame() {
    let lib = Lib::open();
    let n = 16usize;
    // Distance from the volume's centre: the iso-value 5 is a sphere of radius 5 voxels.
    let data: Vec<f32> = (0..n * n * n)
        .map(|i| {
            let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
            let c = (n - 1) as f32 / 2.0;
            ((x as f32 - c).powi(2) + (y as f32 - c).powi(2) + (z as f32 - c).powi(2)).sqrt()
        })
        .collect();
    let set_iso = lib.f::<SetIso>("fv_renderer_set_isosurface");
    let set_env = lib.f::<SetEnv>("fv_renderer_set_environment");
    let mut s = Session::new(&lib);
    s.set_volume([16, 16, 16], FvScalarType::F32, &data);
    s.set_camera(&camera([7.5, 7.5, 60.0], [7.5; 3], [1.0, 200.0]));
    let mut p = FvRenderParams::defaults();
    p.blend_mode = FvBlendMode::Isosurface as u32;
    s.set_params(&p);
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        let render = lib.f::<Render>("fv_renderer_render");
        lib.expect(render(s.r, 32, 32, null(), 0), Invalid, "iso-values");

        let mut iso: FvIsoParams = std::mem::zeroed();
        let defaults = lib.f::<unsafe extern "C" fn(*mut FvIsoParams, usize) -> FvStatus>(
            "fv_iso_params_default",
        );
        lib.expect(
            defaults(null_mut(), size_of_val(&iso)),
            Null,
            "params is NULL",
        );
        lib.ok(defaults(&mut iso, size_of_val(&iso)));
        assert_eq!(iso.bisection_steps, 8);
        lib.expect(set_iso(s.r, &iso), Invalid, "value_count 0");
        iso.value_count = 1;
        iso.values[0] = ferrovol::FvIsoValue {
            value: 5.0,
            color: [0.9, 0.8, 0.7],
            opacity: 1.0,
        };
        type Edit = fn(&mut FvIsoParams);
        let cases: [(Edit, &str); 7] = [
            (|i| i.value_count = 9, "value_count 9"),
            (|i| i.values[0].opacity = 0.0, "opacity 0"),
            (|i| i.values[0].color[0] = 2.0, "colour"),
            (|i| i.specular_mode = 7, "specular_mode 7"),
            (|i| i.specular_samples = 0, "0 specular samples"),
            (|i| i.ao_radius = -1.0, "ao_radius -1"),
            (|i| i.bisection_steps = 40, "40 bisection steps"),
        ];
        for (edit, needle) in cases {
            let mut bad = iso;
            edit(&mut bad);
            lib.expect(set_iso(s.r, &bad), Invalid, needle);
        }
        lib.expect(set_iso(null_mut(), &iso), Null, "renderer");
        let missing = c"/nonexistent/sky.hdr";
        lib.expect(
            set_env(s.r, missing.as_ptr(), 1.0, null(), 0.0),
            Invalid,
            "cannot be opened",
        );
        let text = c"/etc/hostname.txt";
        lib.expect(
            set_env(s.r, text.as_ptr(), 1.0, null(), 0.0),
            Invalid,
            "unsupported file type",
        );
        let up = [0.0, 0.0, 1.0];
        lib.ok(set_env(s.r, null(), 1.0, up.as_ptr(), 30.0));
        iso.ao_samples = 8;
        lib.ok(set_iso(s.r, &iso));
    }
    let rgba = s.frame(32, 32);
    let px = |x: usize, y: usize| &rgba[4 * (y * 32 + x)..][..4];
    println!("sphere centre {:?}, corner {:?}", px(16, 16), px(0, 0));
    assert_eq!(px(16, 16)[3], 255, "the opaque sphere covers the centre");
    assert!(px(16, 16)[0] > 100, "and it is lit");
    assert_eq!(px(0, 0), [0, 0, 0, 0], "the corner misses it");
}

/// Path tracing through the C ABI: refusals name their problem, frames accumulate and a
/// camera change starts over.
#[test]
fn path_tracing_accumulates_and_refuses_bad_settings() {
    let lib = Lib::open();
    let data: Vec<f32> = (0..8 * 8 * 8).map(|i| (i % 8) as f32 / 7.0).collect();
    let mut s = Session::new(&lib);
    s.set_volume([8, 8, 8], FvScalarType::F32, &data);
    s.set_transfer_function(
        &[0.0, 0.9, 0.8, 0.7, 1.0, 0.9, 0.8, 0.7],
        &[0.0, 0.0, 1.0, 0.6],
    );
    let mut cam = camera([3.5, 3.5, 40.0], [3.5; 3], [1.0, 100.0]);
    s.set_camera(&cam);
    let mut p = FvRenderParams::defaults();
    p.blend_mode = FvBlendMode::PathTrace as u32;
    s.set_params(&p);
    let set_pt = lib.f::<SetPt>("fv_renderer_set_path_tracing");
    let defaults = lib.f::<unsafe extern "C" fn(*mut FvPathTraceParams, usize) -> FvStatus>(
        "fv_path_trace_params_default",
    );
    // SAFETY: arguments follow the header; invalid ones are the test.
    unsafe {
        let mut pt: FvPathTraceParams = std::mem::zeroed();
        lib.ok(defaults(&mut pt, size_of_val(&pt)));
        type Edit = fn(&mut FvPathTraceParams);
        let cases: [(Edit, &str); 9] = [
            (|p| p.anisotropy = 1.0, "anisotropy 1"),
            (|p| p.time_budget = -1.0, "time budget -1"),
            (|p| p.samples_per_frame = 0, "0 paths per pixel"),
            (|p| p.scatter_regions = 7, "not an FvScatterRegions"),
            (|p| p.roughness = 0.0, "roughness 0"),
            (|p| p.cone_angle = 90.0, "cone angle 90"),
            (|p| p.gradient_threshold = -1.0, "gradient threshold"),
            (|p| p.stochastic_blend = f32::NAN, "stochastic blend"),
            (|p| p.secondary_rays = 0, "secondary rays"),
        ];
        for (edit, needle) in cases {
            let mut bad = pt;
            edit(&mut bad);
            lib.expect(set_pt(s.r, &bad), Invalid, needle);
        }
        lib.expect(set_pt(s.r, null()), Null, "params is NULL");
        // the hybrid model with a 2×2 budget renders
        let mut hybrid = pt;
        hybrid.gradient_threshold = 0.5;
        hybrid.secondary_rays = 2;
        hybrid.scatter_regions = ferrovol::FvScatterRegions::Surfaces as u32;
        lib.ok(set_pt(s.r, &hybrid));
        s.render(16, 16);
        pt.samples_per_frame = 2;
        lib.ok(set_pt(s.r, &pt));
    }
    let accumulated = lib.f::<Accumulated>("fv_renderer_accumulated_samples");
    let mut counts = vec![];
    for i in 0..4 {
        if i == 3 {
            cam.position = [3.5, 10.0, 40.0];
            s.set_camera(&cam);
        }
        s.render(16, 16);
        let mut n = 0u32;
        // SAFETY: a valid handle and out-pointer.
        lib.ok(unsafe { accumulated(s.r, &mut n) });
        counts.push(n);
    }
    println!("accumulated paths per pixel: {counts:?} (camera moved before the last)");
    assert_eq!(counts, vec![2, 4, 6, 2]);
    let convergence = lib.f::<unsafe extern "C" fn(H, *mut ferrovol::FvConvergence) -> FvStatus>(
        "fv_renderer_convergence",
    );
    let mut c = ferrovol::FvConvergence::default();
    // SAFETY: a valid handle; the out-pointer is checked for NULL.
    unsafe {
        lib.ok(convergence(s.r, &mut c));
        lib.expect(convergence(s.r, null_mut()), Null, "convergence is NULL");
    }
    println!("convergence after 2 paths per pixel: {c:?}");
    assert_eq!(c.paths_per_pixel, 2);
    assert_eq!(c.mean_paths_per_pixel, 2.0);
    assert!(c.relative_error > 0.0 && c.relative_error.is_finite());
}
