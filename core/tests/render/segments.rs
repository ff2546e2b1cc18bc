//! Rays limited to a per-pixel depth range ([`Renderer::render_between`]), as a host peeling
//! translucent geometry draws the volume between its layers: two ranges that meet, composited
//! front over back, give the whole ray's image, since they take the whole ray's samples and
//! share none (with the midpoint quadrature the ranges' steps end exactly at both ends: the
//! same integral, split there).

use crate::common::gpu::{assert_error, renderer};
use crate::common::images::save_enlarged;
use crate::common::metrics::{footprint, image_diff};
use crate::common::scenes::{blob_transfer, blob_volume, shaded};
use ferrovol_core::*;

/// `front` over `back` (premultiplied RGBA8).
fn over(front: &Image, back: &Image) -> Image {
    let mut out = front.clone();
    for (o, (f, b)) in out
        .rgba
        .chunks_mut(4)
        .zip(front.rgba.chunks(4).zip(back.rgba.chunks(4)))
    {
        let t = 1.0 - f[3] as f64 / 255.0;
        for c in 0..4 {
            o[c] = (f[c] as f64 + t * b[c] as f64).round().min(255.0) as u8;
        }
    }
    out
}

#[test]
fn ranges_that_meet_compose_the_whole_ray() {
    let mut r = renderer();
    let vol = blob_volume(40);
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let view = View::fit(vol.bounds(), 64, 64);
    let n = 64 * 64;
    let midpoints = RenderParams {
        quadrature: Quadrature::Midpoint,
        ..shaded()
    };
    for (name, params) in [
        ("unshaded", RenderParams::default()),
        ("shaded", shaded()),
        ("midpoints", midpoints),
    ] {
        let whole = r.render_image(&view, &params).unwrap();
        // Split each ray where its opacity passes 0.3 (the far plane where it never does).
        let split = r
            .render_image(
                &view,
                &RenderParams {
                    depth_threshold: 0.3,
                    ..params.clone()
                },
            )
            .unwrap()
            .depth;
        let (zeros, ones) = (vec![0.0f32; n], vec![1.0f32; n]);
        r.render_between(&view, &params, &zeros, &split).unwrap();
        let front = r.read_image().unwrap();
        r.render_between(&view, &params, &split, &ones).unwrap();
        let back = r.read_image().unwrap();
        let joined = over(&front, &back);
        let (mean, max) = image_diff(&joined, &whole);
        save_enlarged(&front, &format!("segments_front_{name}"));
        save_enlarged(&back, &format!("segments_back_{name}"));
        println!(
            "{name}: front {} px, back {} px, front over back vs the whole ray: mean {mean:.3}, \
             max {max}",
            footprint(&front),
            footprint(&back)
        );
        assert!(footprint(&whole) > 500 && footprint(&front) > 500 && footprint(&back) > 500);
        // Two RGBA8 roundings (each segment's), one in the compositing above (midpoints:
        // the split also ends a step there).
        assert!(
            max <= 3,
            "{name}: front over back differs from the whole ray by {max}"
        );
        // The whole range is the whole ray; an empty one draws nothing.
        r.render_between(&view, &params, &zeros, &ones).unwrap();
        let all = r.read_image().unwrap();
        assert_eq!(
            image_diff(&all, &whole).1,
            0,
            "{name}: [0, 1) is the whole ray"
        );
        r.render_between(&view, &params, &split, &split).unwrap();
        assert_eq!(
            footprint(&r.read_image().unwrap()),
            0,
            "{name}: empty ranges"
        );
    }
    assert_error(
        r.render_between(
            &view,
            &RenderParams::default(),
            &vec![0.0; n],
            &vec![1.0; n - 1],
        ),
        "a far image of the wrong size",
        &["depth image", "4095"],
    );
    for blend in [
        BlendMode::Isosurface,
        BlendMode::PathTrace,
        BlendMode::Slice,
    ] {
        let params = RenderParams {
            blend,
            ..Default::default()
        };
        assert_error(
            r.render_between(&view, &params, &vec![0.0; n], &vec![1.0; n]),
            "a depth range outside ray casting",
            &["depth range", "blend mode"],
        );
    }
}
