//! Frames do not wait for the device: `Renderer::render` returns while lavapipe, which runs
//! submissions on threads of its own, still draws a heavy frame; with two frames in flight
//! (`wait_for_previous_frame`) the images are those of one frame at a time.

use crate::common::gpu::renderer;
use crate::common::metrics::image_diff;
use crate::common::scenes::{blob_transfer, blob_volume, shaded};
use ferrovol_core::*;
use std::time::Instant;

/// A shaded blob at 256×256 with a fine step: a frame lavapipe takes a while to draw.
fn heavy_scene(r: &mut Renderer) -> (View, RenderParams) {
    let blob = blob_volume(96);
    r.set_volume(&blob).unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let mut view = View::fit(blob.bounds(), 256, 256);
    view.camera.azimuth(30.0);
    view.camera.reset_clipping_range(blob.bounds());
    let params = RenderParams {
        sample_distance: Some(0.1),
        ..shaded()
    };
    (view, params)
}

#[test]
fn render_returns_before_the_device_finishes_the_frame() {
    let mut r = renderer();
    let (view, params) = heavy_scene(&mut r);
    r.render_image(&view, &params).unwrap();
    let t0 = Instant::now();
    r.render(&view, &params, None).unwrap();
    let returned = t0.elapsed().as_secs_f64();
    let status = r
        .context()
        .device
        .poll(wgpu::PollType::Poll)
        .expect("polling the device");
    r.finish().unwrap();
    let finished = t0.elapsed().as_secs_f64();
    println!(
        "render returned after {:.1} ms, the frame finished after {:.1} ms ({status:?} when it returned)",
        returned * 1e3,
        finished * 1e3
    );
    assert!(
        !status.is_queue_empty(),
        "the frame was still on the device when render returned"
    );
    assert!(
        returned < 0.5 * finished,
        "render did not wait for the frame"
    );
}

#[test]
fn two_frames_in_flight_draw_what_one_at_a_time_draws() {
    let mut r = renderer();
    let (mut view, params) = heavy_scene(&mut r);
    view.width = 128;
    view.height = 128;
    let mut one_at_a_time = Vec::new();
    for k in 0..3 {
        view.camera.azimuth(10.0 * k as f64);
        one_at_a_time.push(r.render_image(&view, &params).unwrap());
    }
    view.camera.azimuth(-30.0);
    for (k, expected) in one_at_a_time.iter().enumerate() {
        view.camera.azimuth(10.0 * k as f64);
        r.render(&view, &params, None).unwrap();
        r.wait_for_previous_frame().unwrap();
        let (_, most) = image_diff(&r.read_image().unwrap(), expected);
        assert_eq!(most, 0, "frame {k}");
    }
}
