//! Empty-space skipping changes no pixel: additive and average counting the skipped
//! samples, composite and isosurface rays leaping empty space, MIP and MinIP skipping by
//! block range.

use crate::common::gpu::{renderer, set_bricked};
use crate::common::images::save_enlarged;
use crate::common::metrics::{footprint, image_diff};
use crate::common::scenes::{blob_volume, blobs, component_transfer, oblique, shaded, white};
use ferrovol_core::*;

// ---------------------------------------------------------------------------------------
// Additive and average skip empty blocks and count their samples: the same image
// ---------------------------------------------------------------------------------------

/// The blob under a transfer function transparent below 0.3 (most blocks empty): additive
/// and average, with and without skipping, give the same pixels (the skipped samples are
/// counted, so the average divides by as many and a ray through empty space alone still
/// draws its opaque zero), also across bricks of 16 points.
#[test]
fn additive_average_skipping_changes_no_pixel() {
    let mut r = renderer();
    let blob = blob_volume(40);
    let mut view = View::fit(blob.bounds(), 64, 64);
    view.camera.azimuth(27.0);
    view.camera.elevation(18.0);
    view.camera.orthogonalize_view_up();
    view.camera.reset_clipping_range(blob.bounds());
    r.set_transfer_function(&white(&[(0.0, 0.0), (0.3, 0.0), (1.0, 0.8)], 1.0))
        .unwrap();
    for bricked in [false, true] {
        if bricked {
            set_bricked(&mut r, &blob, 16);
        } else {
            r.set_volume(&blob).unwrap();
        }
        for blend in [BlendMode::Additive, BlendMode::Average] {
            let [skipped, marched] = [true, false].map(|empty_space_skipping| {
                let p = RenderParams {
                    blend,
                    empty_space_skipping,
                    ..RenderParams::default()
                };
                r.render_image(&view, &p).unwrap()
            });
            let (_, most) = image_diff(&skipped, &marched);
            let opaque = footprint(&marched);
            println!("{blend:?} (bricked {bricked}): {opaque} opaque pixels, skipping changes at most {most} levels");
            assert!(opaque > 1000, "{blend:?}: the volume's box is drawn");
            assert_eq!(most, 0, "{blend:?} (bricked {bricked})");
        }
    }
}

/// `on` (skipping on) and `off` (off) have the same pixels and depths, and more than
/// `min_lit` pixels drawn.
fn assert_skipping_changes_nothing(on: &Image, off: &Image, label: &str, min_lit: usize) {
    let differ = on.rgba.chunks(4).zip(off.rgba.chunks(4));
    let differ = differ.filter(|(a, b)| a != b).count();
    let lit = footprint(off);
    println!("{label}: {lit} pixels lit, {differ} differ with skipping on");
    assert!(lit > min_lit, "{label}: only {lit} pixels lit");
    assert_eq!(differ, 0, "{label}: skipping changed {differ} pixels");
    assert!(on.depth == off.depth, "{label}: skipping changed the depth");
}

// ---------------------------------------------------------------------------------------
// Composite and isosurface rays leap the empty space around them: the same image
// ---------------------------------------------------------------------------------------

/// Two small blobs in a large, mostly empty volume (rays leap cubes of many empty blocks,
/// and a ray through nothing leaps the whole volume): composite (lattice, midpoints,
/// adaptive, pre-integrated; unshaded and shaded) and the isosurface's first hit, with and
/// without skipping, give the same pixels and depths, in one brick and across bricks of 16
/// points.
#[test]
fn leaping_empty_space_changes_no_pixel() {
    let mut r = renderer();
    let vol = blobs(
        72,
        &[(0.95, [0.3, 0.6, 0.55], 0.1), (0.8, [0.72, 0.3, 0.4], 0.08)],
    );
    let view = oblique(&vol, 80);
    r.set_transfer_function(&white(&[(0.0, 0.0), (0.25, 0.0), (1.0, 0.9)], 1.0))
        .unwrap();
    r.set_isosurface(&IsoParams::with_values(vec![IsoValue::new(
        0.5,
        [0.9, 0.8, 0.7],
        1.0,
    )]))
    .unwrap();
    let mut compared = 0;
    for bricked in [false, true] {
        if bricked {
            set_bricked(&mut r, &vol, 16);
        } else {
            r.set_volume(&vol).unwrap();
        }
        let cases = [
            ("lattice", RenderParams::default()),
            ("shaded", shaded()),
            (
                "midpoints",
                RenderParams {
                    quadrature: Quadrature::Midpoint,
                    ..RenderParams::default()
                },
            ),
            (
                "adaptive",
                RenderParams {
                    quadrature: Quadrature::Adaptive,
                    ..RenderParams::default()
                },
            ),
            (
                "pre-integrated",
                RenderParams {
                    preintegration: true,
                    ..RenderParams::default()
                },
            ),
            (
                "isosurface",
                RenderParams {
                    blend: BlendMode::Isosurface,
                    ..RenderParams::default()
                },
            ),
        ];
        for (name, base) in cases {
            let [on, off] = [true, false].map(|empty_space_skipping| {
                let p = RenderParams {
                    empty_space_skipping,
                    ..base.clone()
                };
                r.render_image(&view, &p).unwrap()
            });
            assert_skipping_changes_nothing(&on, &off, &format!("{name} (bricked {bricked})"), 100);
            compared += 1;
        }
    }
    assert_eq!(compared, 12);
}

// ---------------------------------------------------------------------------------------
// MIP / MinIP skipping by block range leaves the image as it is
// ---------------------------------------------------------------------------------------

#[test]
fn mip_minip_skipping_changes_no_pixel() {
    let mut r = renderer();
    let n = 40u32;
    let blob = blob_volume(n);
    let f32_values = match &blob.scalars {
        Scalars::F32(v) => v.clone(),
        _ => unreachable!("blob_volume is float32"),
    };
    // The same field as float32 in [0, 1] and as int16 in [-1000, 2000] (CT-like, 16-bit
    // normalised storage); MinIP reads the inverted field, so that its minimum has the
    // structure MIP's maximum has. Far from the blobs the field is ~0: blocks to skip.
    let as_i16 = |v: &[f32], invert: bool| {
        let q = v
            .iter()
            .map(|&x| {
                let x = if invert { 1.0 - x } else { x };
                (3000.0 * x - 1000.0).round() as i16
            })
            .collect();
        VolumeData::new([n; 3], 1, Scalars::I16(q)).unwrap()
    };
    let inverted: Vec<f32> = f32_values.iter().map(|&x| 1.0 - x).collect();
    let cases = [
        ("f32", blob.clone(), [0.0, 1.0], BlendMode::Maximum),
        (
            "f32",
            VolumeData::new([n; 3], 1, Scalars::F32(inverted)).unwrap(),
            [0.0, 1.0],
            BlendMode::Minimum,
        ),
        (
            "i16",
            as_i16(&f32_values, false),
            [-1000.0, 2000.0],
            BlendMode::Maximum,
        ),
        (
            "i16",
            as_i16(&f32_values, true),
            [-1000.0, 2000.0],
            BlendMode::Minimum,
        ),
    ];
    let mut view = View::fit(blob.bounds(), 72, 72);
    view.camera.azimuth(33.0);
    view.camera.elevation(21.0);
    view.camera.orthogonalize_view_up();
    view.camera.reset_clipping_range(blob.bounds());
    let mut compared = 0;
    for (name, vol, [lo, hi], blend) in cases {
        // grey = the extremum found, over the data range
        let opacity = match blend {
            BlendMode::Maximum => [(lo, 0.0), (hi, 1.0)],
            _ => [(lo, 1.0), (hi, 0.0)],
        };
        r.set_transfer_function(&TransferFunction::single(component_transfer(
            &[(lo, [1.0; 3]), (hi, [1.0; 3])],
            &opacity,
            1.0,
        )))
        .unwrap();
        // one brick, and bricks of 16 points (blocks and bricks do not align)
        for bricked in [false, true] {
            if bricked {
                crate::common::gpu::set_bricked(&mut r, &vol, 16);
            } else {
                r.set_volume(&vol).unwrap();
            }
            for interpolation in [Interpolation::Linear, Interpolation::Nearest] {
                for jitter in [false, true] {
                    let render = |r: &mut Renderer, skip: bool| {
                        let params = RenderParams {
                            blend,
                            interpolation,
                            jitter,
                            empty_space_skipping: skip,
                            ..RenderParams::default()
                        };
                        r.render_image(&view, &params).unwrap()
                    };
                    let on = render(&mut r, true);
                    let off = render(&mut r, false);
                    let label = format!(
                        "{blend:?} {name} bricked={bricked} {interpolation:?} jitter={jitter}"
                    );
                    assert_skipping_changes_nothing(&on, &off, &label, 500);
                    if !bricked && !jitter && interpolation == Interpolation::Linear {
                        save_enlarged(&on, &format!("skip_{blend:?}_{name}").to_lowercase());
                    }
                    compared += 1;
                }
            }
        }
    }
    assert_eq!(compared, 32);
}
