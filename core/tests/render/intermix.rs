//! Volumes intermixed per sample (Renderer::set_intermixed_volumes): a volume cut in two
//! halves, drawn as the main volume and an intermixed one, is the whole volume; an
//! intermixed volume placed by its own matrix is the main volume placed by the same matrix;
//! and what intermixing does not take is refused with an error naming it.

use crate::common::gpu::{assert_error, new_renderer};
use crate::common::images::save_enlarged;
use crate::common::metrics::{footprint, image_diff};
use crate::common::scenes::{blob_transfer, blob_volume, oblique, shaded, volume};
use ferrovol_core::*;
use glam::{DMat4, DVec3};
use std::sync::Arc;

/// Points `x0 ..= x1` (along x) of `v`, placed where they are in `v`.
fn slab_x(v: &VolumeData, x0: u32, x1: u32) -> VolumeData {
    let [_, ny, nz] = v.dims;
    let mut out = volume([x1 - x0 + 1, ny, nz], |i, j, k| {
        v.value(x0 + i as u32, j as u32, k as u32, 0)
    });
    out.origin = [
        v.origin[0] + x0 as f64 * v.spacing[0],
        v.origin[1],
        v.origin[2],
    ];
    out.spacing = v.spacing;
    out
}

fn tf(c: ComponentTransfer) -> TransferFunction {
    TransferFunction::single(c)
}

#[test]
fn halves_intermixed_equal_the_whole() {
    // A volume that changes along y and z only, cut between x = 20 and x = 21 into two
    // halves without a shared point: each half is read half a point beyond its outer
    // points (VTK's texture-coordinate test, the outer points' values there), so the halves
    // tile the whole, and with no change along x they read what the whole reads there,
    // gradients included.
    let mut r = new_renderer();
    let whole = volume([41, 41, 41], |_, y, z| {
        let g = |c: [f64; 2], s: f64| {
            (-((y - c[0]).powi(2) + (z - c[1]).powi(2)) / (2.0 * s * s)).exp()
        };
        (0.95 * g([20.0, 22.0], 9.0) + 0.7 * g([14.0, 16.0], 4.0)).min(1.0)
    });
    let view = oblique(&whole, 96);
    let transfer = tf(blob_transfer());
    let nearest = RenderParams {
        interpolation: Interpolation::Nearest,
        ..RenderParams::default()
    };
    for (name, params) in [
        ("unshaded", RenderParams::default()),
        ("shaded", shaded()),
        ("nearest", nearest),
    ] {
        r.set_intermixed_volumes(&[]).unwrap();
        r.set_volume(&whole).unwrap();
        r.set_transfer_function(&transfer).unwrap();
        let reference = r.render_image(&view, &params).unwrap();
        r.set_volume(&slab_x(&whole, 0, 20)).unwrap();
        r.set_intermixed_volumes(&[IntermixedVolume {
            volume: Arc::new(slab_x(&whole, 21, 40)),
            matrix: DMat4::IDENTITY,
            transfer: transfer.clone(),
            interpolation: params.interpolation,
        }])
        .unwrap();
        let img = r.render_image(&view, &params).unwrap();
        save_enlarged(&img, &format!("intermix_halves_{name}"));
        let (mean, max) = image_diff(&img, &reference);
        println!(
            "intermix halves ({name}): mean {mean:.4} max {max} levels, footprint {}",
            footprint(&img)
        );
        assert!(footprint(&reference) > 2000, "the whole volume shows");
        // The same samples and values (f32 trilinear weights against the sampler's), but
        // for a sample that f32 rounding puts on both sides of the cut or neither: a few
        // pixels by a few levels.
        assert!(
            mean < 0.01 && max <= 8,
            "{name}: halves differ from the whole by mean {mean:.4} max {max}"
        );
    }
}

#[test]
fn intermixed_matrix_places_the_volume() {
    let mut r = new_renderer();
    let vol = blob_volume(33);
    let transfer = tf(blob_transfer());
    // Scaled unevenly and moved: a world box of another size and place than the data's.
    let m = DMat4::from_translation(DVec3::new(5.0, -3.0, 2.0))
        * DMat4::from_scale(DVec3::new(1.5, 0.75, 1.0));
    let b = vol.bounds();
    let lo = m.transform_point3(DVec3::new(b[0], b[2], b[4]));
    let hi = m.transform_point3(DVec3::new(b[1], b[3], b[5]));
    let mut view = View::fit([lo.x, hi.x, lo.y, hi.y, lo.z, hi.z], 96, 96);
    view.camera.azimuth(25.0);
    view.camera.elevation(15.0);
    view.camera.orthogonalize_view_up();
    view.camera
        .reset_clipping_range([lo.x, hi.x, lo.y, hi.y, lo.z, hi.z]);
    for (name, base) in [("unshaded", RenderParams::default()), ("shaded", shaded())] {
        let params = RenderParams {
            volume_matrix: m,
            ..base.clone()
        };
        r.set_intermixed_volumes(&[]).unwrap();
        r.set_volume(&vol).unwrap();
        r.set_transfer_function(&transfer).unwrap();
        let reference = r.render_image(&view, &params).unwrap();
        // The main volume the same, but transparent: what shows is the intermixed one.
        let mut clear = blob_transfer();
        clear.opacity = Piecewise::new(vec![(0.0, [0.0]), (1.0, [0.0])]).unwrap();
        r.set_transfer_function(&tf(clear)).unwrap();
        r.set_intermixed_volumes(&[IntermixedVolume {
            volume: Arc::new(vol.clone()),
            matrix: m,
            transfer: transfer.clone(),
            interpolation: params.interpolation,
        }])
        .unwrap();
        let img = r.render_image(&view, &params).unwrap();
        save_enlarged(&img, &format!("intermix_matrix_{name}"));
        let (mean, max) = image_diff(&img, &reference);
        println!("intermix matrix ({name}): mean {mean:.4} max {max} levels");
        assert!(footprint(&reference) > 2000, "the volume shows");
        // The same samples (an axis-aligned matrix: the union box is the volume's), the
        // same normals (the gradient taken to world by the inverse transpose).
        assert!(
            mean < 0.05 && max <= 4,
            "{name}: intermixed differs from main by mean {mean:.4} max {max}"
        );
    }
    r.set_intermixed_volumes(&[]).unwrap();
}

#[test]
fn intermixed_volumes_composite_in_order_per_sample() {
    // Two coincident uniform slabs: red first (main), then blue. Per sample the red one is
    // composited in front of the blue one, so the pixel carries more red than blue.
    let mut r = new_renderer();
    let vol = volume([9, 9, 17], |_, _, _| 0.5);
    let colour = |c: [f32; 3]| {
        let mut t = ComponentTransfer::new(
            Piecewise::new(vec![(0.0, c), (1.0, c)]).unwrap(),
            Piecewise::new(vec![(0.0, [0.3]), (1.0, [0.3])]).unwrap(),
        );
        t.unit_distance = 1.0;
        tf(t)
    };
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&colour([1.0, 0.0, 0.0])).unwrap();
    r.set_intermixed_volumes(&[IntermixedVolume {
        volume: Arc::new(vol.clone()),
        matrix: DMat4::IDENTITY,
        transfer: colour([0.0, 0.0, 1.0]),
        interpolation: Interpolation::Linear,
    }])
    .unwrap();
    let mut view = View::fit(vol.bounds(), 17, 17);
    view.camera.parallel = true;
    view.camera.reset_clipping_range(vol.bounds());
    let img = r.render_image(&view, &RenderParams::default()).unwrap();
    let i = 4 * (8 * 17 + 8) as usize;
    let p = &img.rgba[i..i + 4];
    // Per sample: red adds 0.3 of what remains, blue 0.3 of what then remains (0.7 × 0.3):
    // red / blue = 1 / 0.7 in every sample, so in the sum.
    let ratio = p[0] as f64 / p[2] as f64;
    println!(
        "intermix order: pixel {p:?}, red / blue {ratio:.3} (expected {:.3})",
        1.0 / 0.7
    );
    assert!(
        p[3] > 200,
        "16 samples at opacity 0.3 and 0.3 are nearly opaque: {p:?}"
    );
    assert!((ratio - 1.0 / 0.7).abs() < 0.03, "red / blue {ratio:.3}");
}

#[test]
fn intermixing_refuses_what_it_does_not_take() {
    let mut r = new_renderer();
    let vol = blob_volume(17);
    let transfer = tf(blob_transfer());
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&transfer).unwrap();
    let one = IntermixedVolume {
        volume: Arc::new(vol.clone()),
        matrix: DMat4::IDENTITY,
        transfer: transfer.clone(),
        interpolation: Interpolation::Linear,
    };
    assert_error(
        r.set_intermixed_volumes(&vec![one.clone(); MAX_INTERMIXED_VOLUMES + 1]),
        "too many",
        &["intermixed volumes", "at most 3"],
    );
    let two = VolumeData::new([4, 4, 4], 2, Scalars::F32(vec![0.0; 128])).unwrap();
    assert_error(
        r.set_intermixed_volumes(&[IntermixedVolume {
            volume: Arc::new(two),
            ..one.clone()
        }]),
        "two components",
        &["intermixed volume 0", "2 components"],
    );
    assert_error(
        r.set_intermixed_volumes(&[IntermixedVolume {
            matrix: DMat4::ZERO,
            ..one.clone()
        }]),
        "singular matrix",
        &["intermixed volume 0", "singular"],
    );
    assert_error(
        r.set_intermixed_volumes(&[IntermixedVolume {
            interpolation: Interpolation::Cubic,
            ..one.clone()
        }]),
        "cubic",
        &["intermixed volume 0", "cubic"],
    );
    r.set_intermixed_volumes(&[one]).unwrap();
    let view = oblique(&vol, 32);
    for blend in [BlendMode::Maximum, BlendMode::Isosurface] {
        let params = RenderParams {
            blend,
            ..RenderParams::default()
        };
        assert_error(
            r.render_image(&view, &params),
            &format!("{blend:?}"),
            &["intermixed volumes", "composite"],
        );
    }
    let cropped = RenderParams {
        cropping: Some(Cropping {
            planes: [2.0, 10.0, 2.0, 10.0, 2.0, 10.0],
            regions: Cropping::SUBVOLUME,
        }),
        ..RenderParams::default()
    };
    assert_error(
        r.render_image(&view, &cropped),
        "cropping",
        &["cropping is on"],
    );
    let traced = RenderParams {
        blend: BlendMode::PathTrace,
        ..cropped
    };
    assert_error(
        r.render_image(&view, &traced),
        "path tracing with cropping",
        &["intermixed volumes", "path traced", "cropping"],
    );
    r.set_intermixed_volumes(&[]).unwrap();
    assert!(r.render_image(&view, &RenderParams::default()).is_ok());
}
