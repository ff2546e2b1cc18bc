//! Frames do not wait for the device: `Renderer::render` returns while lavapipe, which runs
//! submissions on threads of its own, still draws a heavy frame; with two frames in flight
//! (`wait_for_previous_frame`) the images are those of one frame at a time. Path-traced
//! frames with a time budget and preview frames past the memory budget read what they need
//! from the device (the time the paths took, the bricks the rays read) one frame late,
//! without waiting: `Context::device_waits` counts every wait.

use crate::common::gpu::{pt_params, renderer};
use crate::common::metrics::image_diff;
use crate::common::scenes::{ball, blob_transfer, blob_volume, component_transfer, shaded};
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

/// Renders a frame, and says after how many seconds `render` returned and whether the
/// device had finished it then (polled, not waited for).
fn render_and_poll(
    r: &mut Renderer,
    view: &View,
    params: &RenderParams,
) -> (f64, wgpu::PollStatus) {
    let t0 = Instant::now();
    r.render(view, params, None).unwrap();
    let returned = t0.elapsed().as_secs_f64();
    let status = r
        .context()
        .device
        .poll(wgpu::PollType::Poll)
        .expect("polling the device");
    (returned, status)
}

#[test]
fn render_returns_before_the_device_finishes_the_frame() {
    let mut r = renderer();
    let (view, params) = heavy_scene(&mut r);
    r.render_image(&view, &params).unwrap();
    let t0 = Instant::now();
    let (returned, status) = render_and_poll(&mut r, &view, &params);
    r.finish().unwrap();
    let finished = t0.elapsed().as_secs_f64();
    println!(
        "render returned after {:.1} ms, the frame finished after {:.1} ms ({status:?} when it returned)",
        returned * 1e3,
        finished * 1e3
    );
    // (the times are printed, not held to a ratio: on a loaded machine the render call's
    // own CPU time varies more than the frame's)
    assert!(
        !status.is_queue_empty(),
        "the frame was still on the device when render returned"
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

/// Budgeted path-traced frames wait for nothing: a frame traces as many sixteenths as the
/// budget holds at the rate the device's timestamps gave for an earlier frame (read without
/// waiting), and returns while the device traces them. Frames in flight trace the same paths
/// as whole passes: the accumulation is equal to the bit.
#[test]
fn budgeted_path_tracing_frames_do_not_wait() {
    let mut r = renderer();
    let ball = ball(20, 9.0);
    r.set_volume(&ball).unwrap();
    let rgb = [0.9, 0.7, 0.5];
    r.set_transfer_function(&TransferFunction::single(component_transfer(
        &[(0.0, rgb), (1.0, rgb)],
        &[(0.0, 0.0), (1.0, 0.6)],
        2.0,
    )))
    .unwrap();
    r.set_environment(&Environment::constant([1.0; 3])).unwrap();
    let view = View::fit(ball.bounds(), 48, 48);
    let whole = PathTraceParams {
        samples_per_frame: 2,
        seed: 5,
        ..Default::default()
    };
    // (these frames are timed too: the budgeted ones below start from their rate)
    let reference = crate::common::gpu::trace(&mut r, &view, &whole, 2);
    let budget = 0.4;
    r.set_path_tracing(&PathTraceParams {
        samples_per_frame: 64,
        max_samples: 0,
        time_budget: budget,
        ..whole
    })
    .unwrap();
    r.reset_accumulation();
    // (each frame traces at most twice the sixteenths its rate was measured on: a few
    // frames, each waited for by the caller, bring it to the budget)
    for _ in 0..6 {
        r.render(&view, &pt_params(), None).unwrap();
        r.finish().unwrap();
    }
    r.reset_accumulation();
    let waits = r.context().device_waits();
    let t0 = Instant::now();
    let (returned, status) = render_and_poll(&mut r, &view, &pt_params());
    assert_eq!(r.context().device_waits(), waits, "the frame waited");
    r.finish().unwrap();
    let finished = t0.elapsed().as_secs_f64();
    let traced = r.convergence().unwrap().mean_paths_per_pixel;
    println!(
        "budget {budget} s: the frame traced {traced:.2} paths per pixel, returned after \
         {:.1} ms, finished after {:.0} ms ({status:?} when it returned)",
        returned * 1e3,
        finished * 1e3,
    );
    assert!(traced > 2.0, "the rate let the frame trace several passes");
    assert!(
        !status.is_queue_empty() && returned < 0.5 * finished,
        "render did not wait for the paths"
    );
    // (the rate comes from frames of another size, and lavapipe shares the machine's cores
    // with whatever else runs: the budget holds within a factor)
    assert!(
        finished < 5.0 * budget as f64,
        "{finished} s for {budget} s"
    );
    // Frames in flight, each planned from an earlier one's rate: the same paths. (In this
    // scene subsets trace whole passes' sums to the bit, as in pathtrace/progressive.rs; in
    // others lavapipe's subset dispatches can differ by an ulp in a few pixels, however the
    // frames split them, waiting or not.)
    r.set_path_tracing(&PathTraceParams {
        time_budget: 0.001,
        max_samples: 2,
        ..whole
    })
    .unwrap();
    r.reset_accumulation();
    let waits = r.context().device_waits();
    let mut frames = 0;
    while r.accumulated_samples() < 2 {
        r.render(&view, &pt_params(), None).unwrap();
        frames += 1;
    }
    let in_frames = r.context().device_waits() - waits;
    println!("budget 1 ms: {frames} frames in flight traced 2 paths per pixel");
    let traced = r.read_accumulation().unwrap();
    let differ = traced
        .iter()
        .zip(&reference)
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(
        differ, 0,
        "pixels whose accumulation differs from whole passes"
    );
    assert_eq!(in_frames, 0, "frames waited");
}

/// Preview frames past the memory budget take the bricks their rays read through a readback
/// ring, one frame late, without waiting; frames of a still camera in flight still converge
/// to the in-core image.
#[test]
fn preview_frames_do_not_wait_and_converge() {
    let mut r = renderer();
    let n = 96u32;
    let vol = super::lod::slab_scene(&mut r, n);
    let view = View::fit(vol.bounds(), 64, 64);
    let still = RenderParams {
        sample_distance: Some(1.0),
        ..Default::default()
    };
    r.set_volume(&vol).unwrap();
    let in_core = r.render_image(&view, &still).unwrap();
    r.set_volume_with(
        &vol,
        UploadOptions {
            max_brick_points: Some(24),
            memory_budget: Some((n as u64).pow(3) * 4 * 4 / 5),
            ..Default::default()
        },
    )
    .unwrap();
    let preview = RenderParams {
        preview_level: true,
        ..still
    };
    let mut stand_ins = Vec::new();
    let mut render_waits = 0;
    for _ in 0..16 {
        let waits = r.context().device_waits();
        r.render(&view, &preview, None).unwrap();
        render_waits += r.context().device_waits() - waits;
        r.wait_for_previous_frame().unwrap();
        stand_ins.push(r.residency().stand_ins);
    }
    r.finish().unwrap();
    let last = r.residency().stand_ins;
    let (mean, max) = image_diff(&r.read_image().unwrap(), &in_core);
    println!(
        "16 preview frames in flight: bricks read from stand-ins, as known after each \
         {stand_ins:?}, {last} after the last; {mean:.4}/255 mean, {max}/255 max from in \
         core; {render_waits} waits inside the frames"
    );
    assert_eq!(render_waits, 0, "preview frames waited");
    assert!(
        stand_ins.iter().any(|&s| s > 0),
        "the previews read stand-ins"
    );
    assert_eq!(last, 0, "complete");
    assert!(max <= 2, "the complete preview equals in core");
}

/// `Renderer::prepare` does a frame's set-up without drawing: the frame after it compiles no
/// pipeline and draws what a renderer that was not prepared draws; what a frame would
/// refuse, prepare refuses with the same message.
#[test]
fn prepared_frames_compile_nothing_and_draw_the_same() {
    let mut r = crate::common::gpu::new_renderer();
    let blob = blob_volume(32);
    let tf = TransferFunction::single(blob_transfer());
    r.set_volume(&blob).unwrap();
    r.set_transfer_function(&tf).unwrap();
    let iso = IsoParams::with_values(vec![IsoValue::new(0.4, [0.9, 0.8, 0.7], 1.0)]);
    r.set_isosurface(&iso).unwrap();
    let view = View::fit(blob.bounds(), 48, 48);
    let mut other = Renderer::new(r.context().clone()).unwrap();
    other.set_volume(&blob).unwrap();
    other.set_transfer_function(&tf).unwrap();
    other.set_isosurface(&iso).unwrap();
    for (what, params) in [
        ("composite", RenderParams::default()),
        ("shaded", shaded()),
        (
            "isosurface",
            RenderParams {
                blend: BlendMode::Isosurface,
                ..Default::default()
            },
        ),
        ("path traced", pt_params()),
    ] {
        let compiled = r.context().compiled_pipelines();
        let frames = r.stats().frames;
        r.prepare(&view, &params).unwrap();
        let prepared = r.context().compiled_pipelines();
        assert_eq!(r.stats().frames, frames, "{what}: prepare drew");
        let img = r.render_image(&view, &params).unwrap();
        println!(
            "{what}: prepare compiled {} pipelines, the frame {}",
            prepared - compiled,
            r.context().compiled_pipelines() - prepared
        );
        assert!(prepared > compiled, "{what}: prepare compiled nothing");
        assert_eq!(
            r.context().compiled_pipelines(),
            prepared,
            "{what}: the prepared frame compiled"
        );
        assert!(img.rgba.chunks(4).any(|p| p[3] > 0), "{what}: empty frame");
        let unprepared = other.render_image(&view, &params).unwrap();
        assert_eq!(image_diff(&img, &unprepared).1, 0, "{what}");
    }
    let refused = RenderParams {
        sample_distance: Some(-1.0),
        ..Default::default()
    };
    let prepare = r.prepare(&view, &refused).unwrap_err().to_string();
    let render = r.render(&view, &refused, None).unwrap_err().to_string();
    assert_eq!(prepare, render);
}
