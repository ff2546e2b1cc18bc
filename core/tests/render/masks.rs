//! Masks (VTK's MaskInput): binary masks leave samples out in every ray-casting blend mode,
//! label maps classify labelled samples with their labels' functions; blanking leaves
//! samples out of isosurfaces and the path tracer's medium too.

use crate::common::gpu::{assert_error, renderer, set_bricked, trace};
use crate::common::images::save_enlarged;
use crate::common::metrics::{image_diff, rgba};
use crate::common::raycast::to_pixel;
use crate::common::scenes::{blob_transfer, blob_volume, piecewise1, piecewise3, shaded, volume};
use ferrovol_core::*;
use glam::DVec3;

const N: usize = 24;

/// One byte per point of the N³ grid, `f` of the point's x index.
fn by_x(f: impl Fn(usize) -> u8) -> Vec<u8> {
    (0..N * N * N).map(|i| f(i % N)).collect()
}

/// The blob volume, its transfer function (shaded with gradient opacity where `shade`) and
/// a view along z of 64² pixels.
fn scene(r: &mut Renderer, labels: Vec<LabelTransfer>) -> View {
    let vol = blob_volume(N as u32);
    r.set_volume(&vol).unwrap();
    let mut tf = TransferFunction::single(blob_transfer());
    tf.labels = labels;
    r.set_transfer_function(&tf).unwrap();
    View::fit(vol.bounds(), 64, 64)
}

/// One opaque isosurface of the blob at 0.3.
fn set_isosurface(r: &mut Renderer) {
    r.set_isosurface(&IsoParams::with_values(vec![IsoValue::new(
        0.3,
        [0.9, 0.8, 0.6],
        1.0,
    )]))
    .unwrap();
}

/// Pixel column where the world plane x = `x` projects on the volume's centre line.
fn column(view: &View, x: f64) -> f64 {
    let c = view.camera.focal_point;
    to_pixel(view, DVec3::new(x, c.y, c.z)).0
}

fn params(blend: BlendMode) -> RenderParams {
    RenderParams {
        blend,
        ..RenderParams::default()
    }
}

/// A binary mask of zeros on the points x < 12 leaves out every sample nearer to them: the
/// pixels whose rays see only that side are background, in every ray-casting blend mode and
/// for isosurfaces, bricked or not; a mask of ones changes nothing.
#[test]
fn binary_mask_leaves_out_samples() {
    let mut r = renderer();
    let view = scene(&mut r, Vec::new());
    set_isosurface(&mut r);
    let ones = by_x(|_| 1);
    let half = by_x(|x| u8::from(x >= 12));
    // samples with x < 11.5 (index = world here) are left out
    let edge = column(&view, 11.5);
    for blend in BlendMode::ALL {
        if matches!(blend, BlendMode::PathTrace | BlendMode::Slice) {
            continue;
        }
        let p = params(blend);
        r.set_mask(None).unwrap();
        let plain = r.render_image(&view, &p).unwrap();
        r.set_mask(Some((&ones, MaskKind::Binary))).unwrap();
        let all = r.render_image(&view, &p).unwrap();
        assert_eq!(image_diff(&plain, &all).1, 0, "{blend:?}: a mask of ones");
        r.set_mask(Some((&half, MaskKind::Binary))).unwrap();
        let masked = r.render_image(&view, &p).unwrap();
        save_enlarged(&masked, &format!("mask_binary_{blend:?}"));
        let (mut left, mut right) = (0, 0);
        for y in 0..64 {
            for x in 0..64 {
                let a = rgba(&masked, x, y)[3];
                if (x as f64) < edge - 1.0 {
                    left += u32::from(a > 0);
                } else if (x as f64) > edge + 1.0 && rgba(&plain, x, y)[3] > 0 {
                    right += u32::from(a > 0);
                }
            }
        }
        println!("{blend:?}: edge at column {edge:.1}; {left} pixels left of it, {right} right");
        assert_eq!(
            left, 0,
            "{blend:?}: nothing drawn where every sample is masked"
        );
        // (the blob's minimum along every ray is transparent: MinIP draws nothing here)
        if blend != BlendMode::Minimum {
            assert!(right > 150, "{blend:?}: the unmasked side is drawn");
        }
        let vol = blob_volume(N as u32);
        set_bricked(&mut r, &vol, 10);
        r.set_mask(Some((&half, MaskKind::Binary))).unwrap();
        let bricked = r.render_image(&view, &p).unwrap();
        let (mean, max) = image_diff(&masked, &bricked);
        println!("{blend:?}: bricked vs one brick, mean {mean:.3}, max {max}");
        assert!(max <= 1, "{blend:?}: bricking changes the masked image");
        r.set_volume(&vol).unwrap();
    }
}

/// VTK's blanking leaves samples out of isosurfaces and of the path tracer's medium as ray
/// casting does: with the points x < 12 hidden, the samples x < 12 are blanked (a sample is
/// when its nearest point or a point around it along an axis is hidden), so the pixels
/// whose rays see only that side are background; blanking nothing changes nothing.
#[test]
fn blanking_leaves_samples_out_of_isosurfaces_and_the_medium() {
    let mut r = renderer();
    let view = scene(&mut r, Vec::new());
    set_isosurface(&mut r);
    let edge = column(&view, 12.0);
    let traced = |r: &mut Renderer| -> Vec<f32> {
        let p = PathTraceParams {
            samples_per_frame: 8,
            ..Default::default()
        };
        trace(r, &view, &p, 8).iter().map(|v| v[3]).collect()
    };
    let iso = |r: &mut Renderer| -> Vec<f32> {
        let img = r
            .render_image(&view, &params(BlendMode::Isosurface))
            .unwrap();
        (0..64 * 64)
            .map(|i| f32::from(rgba(&img, i % 64, i / 64)[3]))
            .collect()
    };
    for (name, draw) in [
        ("isosurfaces", &iso as &dyn Fn(&mut Renderer) -> Vec<f32>),
        ("path tracing", &traced),
    ] {
        r.set_blanking(None).unwrap();
        let plain = draw(&mut r);
        r.set_blanking(Some(&by_x(|_| 0))).unwrap();
        assert_eq!(draw(&mut r), plain, "{name}: blanking nothing");
        r.set_blanking(Some(&by_x(|x| u8::from(x < 12)))).unwrap();
        let blanked = draw(&mut r);
        let (mut left, mut right) = (0, 0);
        for (i, (&a, &b)) in blanked.iter().zip(&plain).enumerate() {
            let x = (i % 64) as f64;
            if x < edge - 1.0 {
                left += u32::from(a > 0.0);
            } else if x > edge + 1.0 && b > 0.0 {
                right += u32::from(a > 0.0);
            }
        }
        println!("{name}: edge at column {edge:.1}; {left} pixels left of it, {right} right");
        assert_eq!(
            left, 0,
            "{name}: nothing drawn where every sample is blanked"
        );
        assert!(right > 150, "{name}: the other side is drawn");
    }
    r.set_blanking(None).unwrap();
}

/// Ambient-occlusion rays leave masked samples out, as the surfaces do: a floor facing the
/// camera with a pillar standing on it at x < 10, the mask leaving out x < 12. The floor's
/// hits the mask leaves where they were are at least as open as without it, and those
/// beside the (masked) pillar more open.
#[test]
fn ambient_occlusion_rays_leave_masked_samples_out() {
    let mut r = renderer();
    let vol = volume([N as u32; 3], |x, _, z| {
        f64::from(u8::from(z < 8.0 || (x < 10.0 && z < 20.0)))
    });
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let view = View::fit(vol.bounds(), 64, 64);
    r.set_isosurface(&IsoParams {
        ambient_occlusion: Some(AmbientOcclusion::default()),
        ..IsoParams::with_values(vec![IsoValue::new(0.5, [0.9, 0.8, 0.6], 1.0)])
    })
    .unwrap();
    let p = params(BlendMode::Isosurface);
    r.render_image(&view, &p).unwrap();
    let plain = r.read_gbuffer().unwrap();
    r.set_mask(Some((&by_x(|x| u8::from(x >= 12)), MaskKind::Binary)))
        .unwrap();
    r.render_image(&view, &p).unwrap();
    let masked = r.read_gbuffer().unwrap();
    let (mut same, mut opener, mut closer) = (0, 0, 0);
    for y in 0..64 {
        for x in 0..64 {
            let (a, b) = (plain.hits(x, y), masked.hits(x, y));
            let (Some(a), Some(b)) = (a.first(), b.first()) else {
                continue;
            };
            if (a.distance - b.distance).abs() > 1e-4 || a.iso_index != b.iso_index {
                continue;
            }
            same += 1;
            if b.ambient_access > a.ambient_access + 1e-6 {
                opener += 1;
            } else if b.ambient_access < a.ambient_access - 1e-6 {
                closer += 1;
            }
        }
    }
    println!("{same} hits the mask left in place: {opener} more open, {closer} less");
    assert!(same > 200, "the unmasked side's hits");
    assert_eq!(closer, 0, "a masked region occludes nothing");
    assert!(opener > 20, "rays into the masked half see it empty");
}

/// A label map: labels classify with their own functions (one left out is the first
/// component's), blended by the blend factor; label 0 and labels above the highest with
/// functions are the background's; a label of zero opacity equals a binary mask of it.
#[test]
fn label_map_classifies_by_label() {
    let mut r = renderer();
    let red = LabelTransfer {
        label: 2,
        color: Some(piecewise3(&[
            (0.0, [1.0, 0.0, 0.0]),
            (1.0, [1.0, 0.0, 0.0]),
        ])),
        opacity: None,
        gradient_opacity: None,
    };
    let hidden = LabelTransfer {
        label: 3,
        color: None,
        opacity: Some(piecewise1(&[(0.0, 0.0), (1.0, 0.0)])),
        gradient_opacity: None,
    };
    let view = scene(&mut r, vec![red, hidden]);
    let p = RenderParams {
        mask_blend: 1.0,
        ..RenderParams::default()
    };
    let plain = r.render_image(&view, &p).unwrap();
    // label 1 (no functions: the first component's), 0 and 9 (above the highest) draw as
    // without a mask
    for label in [0u8, 1, 9] {
        r.set_mask(Some((&by_x(|_| label), MaskKind::LabelMap)))
            .unwrap();
        let same = r.render_image(&view, &p).unwrap();
        assert_eq!(image_diff(&plain, &same).1, 0, "label {label}");
    }
    // label 2 on the right half: red there, unchanged on the left
    let right_red = by_x(|x| if x >= 12 { 2 } else { 0 });
    r.set_mask(Some((&right_red, MaskKind::LabelMap))).unwrap();
    let labelled = r.render_image(&view, &p).unwrap();
    save_enlarged(&labelled, "mask_label_red");
    let edge = column(&view, 11.5);
    let (mut red_px, mut other) = (0, 0);
    for y in 0..64 {
        for x in 0..64 {
            let [cr, cg, cb, a] = rgba(&labelled, x, y);
            if (x as f64) > edge + 1.0 && a > 64 {
                red_px += 1;
                assert!(
                    cr > 2 * cg.max(cb),
                    "({x}, {y}) = {cr} {cg} {cb}: labelled red"
                );
            } else if (x as f64) < edge - 1.0 {
                other = other.max(rgba(&plain, x, y)[0].abs_diff(cr));
            }
        }
    }
    println!("{red_px} red pixels; the unlabelled side within {other} levels");
    assert!(red_px > 100);
    assert!(other <= 1, "the unlabelled side changed by {other} levels");
    // blend 0 reads no mask; 0.5 lies between
    let none = r
        .render_image(
            &view,
            &RenderParams {
                mask_blend: 0.0,
                ..p.clone()
            },
        )
        .unwrap();
    assert_eq!(image_diff(&plain, &none).1, 0, "blend factor 0");
    let half = r
        .render_image(
            &view,
            &RenderParams {
                mask_blend: 0.5,
                ..p.clone()
            },
        )
        .unwrap();
    let (d_plain, _) = image_diff(&plain, &half);
    let (d_label, _) = image_diff(&labelled, &half);
    println!("blend 0.5: {d_plain:.2} from the unmasked image, {d_label:.2} from the labelled");
    assert!(d_plain > 0.5 && d_label > 0.5);
    // a label of zero opacity leaves its samples out as a binary mask does
    r.set_mask(Some((
        &by_x(|x| if x < 12 { 3 } else { 0 }),
        MaskKind::LabelMap,
    )))
    .unwrap();
    let hidden_left = r.render_image(&view, &p).unwrap();
    r.set_mask(Some((&by_x(|x| u8::from(x >= 12)), MaskKind::Binary)))
        .unwrap();
    let binary = r.render_image(&view, &p).unwrap();
    assert_eq!(
        image_diff(&binary, &hidden_left).1,
        0,
        "label 3 = binary mask"
    );
}

/// A label's gradient opacity applies to its samples; the components' does not.
#[test]
fn label_gradient_opacity() {
    let mut r = renderer();
    let flat = LabelTransfer {
        label: 1,
        color: None,
        opacity: None,
        gradient_opacity: Some(piecewise1(&[(0.0, 0.0), (1e-3, 0.0)])),
    };
    let view = scene(&mut r, vec![flat]);
    let p = shaded();
    let plain = r.render_image(&view, &p).unwrap();
    r.set_mask(Some((&by_x(|_| 1), MaskKind::LabelMap)))
        .unwrap();
    let gone = r.render_image(&view, &p).unwrap();
    let lit = (0..64 * 64)
        .filter(|i| rgba(&gone, i % 64, i / 64)[3] > 0)
        .count();
    println!("label gradient opacity 0: {lit} pixels drawn");
    assert_eq!(lit, 0);
    assert!(image_diff(&plain, &gone).0 > 1.0);
}

/// Bad masks are refused, naming why; a new volume clears the mask.
#[test]
fn mask_errors() {
    let mut r = renderer();
    let view = scene(&mut r, Vec::new());
    assert_error(
        r.set_mask(Some((&[1; 7], MaskKind::Binary))),
        "mask of the wrong length",
        &["7 values", "24x24x24"],
    );
    let dup = |label| LabelTransfer {
        label,
        color: None,
        opacity: None,
        gradient_opacity: None,
    };
    let mut tf = TransferFunction::single(blob_transfer());
    tf.labels = vec![dup(0)];
    assert_error(r.set_transfer_function(&tf), "label 0", &["label 0"]);
    tf.labels = vec![dup(4), dup(4)];
    assert_error(r.set_transfer_function(&tf), "two label 4", &["label 4"]);
    assert_error(
        r.render_image(
            &view,
            &RenderParams {
                mask_blend: 1.5,
                ..RenderParams::default()
            },
        ),
        "blend factor",
        &["mask blend factor 1.5"],
    );
    r.set_mask(Some((&by_x(|_| 1), MaskKind::Binary))).unwrap();
    let p = params(BlendMode::Composite);
    r.set_mask(None).unwrap();
    let plain = r.render_image(&view, &p).unwrap();
    r.set_mask(Some((&by_x(|x| u8::from(x >= 12)), MaskKind::Binary)))
        .unwrap();
    r.set_volume(&blob_volume(N as u32)).unwrap();
    let fresh = r.render_image(&view, &p).unwrap();
    assert_eq!(
        image_diff(&plain, &fresh).1,
        0,
        "a new volume clears the mask"
    );
}
