//! Which bricks are resident: only the visible ones, streamed frames equal in-core ones,
//! resident bricks carry over between frames, and the pool shrinks with hysteresis.

use super::bricks::assert_content;
use crate::common::gpu::{renderer, set_bricked};
use crate::common::metrics::{footprint, image_diff};
use crate::common::scenes::{blended, blob_transfer, blob_volume, component_transfer, shaded};
use ferrovol_core::*;

/// The blob's colours, transparent below `from` and rising to 0.8 at 1.
fn opacity_from(from: f64) -> TransferFunction {
    TransferFunction::single(component_transfer(
        &[(0.0, [0.9, 0.6, 0.2]), (1.0, [1.0, 1.0, 0.9])],
        &[(0.0, 0.0), (from, 0.0), (1.0, 0.8)],
        3.0,
    ))
}

/// Sparse residency: a bricked volume keeps only the bricks something visible lies in, so a
/// transfer function that shows a small part of the volume takes a matching part of the
/// memory; widening it uploads only the bricks it adds; the projection modes make every
/// brick resident; every image equals the one-brick image.
#[test]
fn only_visible_bricks_are_resident() {
    let mut r = renderer();
    let vol = blob_volume(40);
    let view = View::fit(vol.bounds(), 64, 64);
    let params = RenderParams::default();
    let mut frames = Vec::new();
    for from in [0.55, 0.1] {
        r.set_transfer_function(&opacity_from(from)).unwrap();
        r.set_volume(&vol).unwrap();
        let one = r.render_image(&view, &params).unwrap();
        set_bricked(&mut r, &vol, 12);
        let uploads = r.stats().brick_uploads;
        let split = r.render_image(&view, &params).unwrap();
        // (a small blob core with the narrow transfer function: no assert_content)
        assert!(footprint(&split) > 150, "the blob is drawn");
        let (mean, max) = image_diff(&one, &split);
        let res = r.residency();
        println!(
            "opacity from {from}: {} of {} bricks resident, pool {} of {} bytes dense \
             ({:.0}%), {} bricks uploaded; image against one brick: mean {mean:.4}/255, \
             max {max}/255",
            res.resident,
            res.bricks,
            res.pool_bytes,
            res.dense_bytes,
            100.0 * res.pool_bytes as f64 / res.dense_bytes as f64,
            r.stats().brick_uploads - uploads
        );
        assert!(max <= 2, "sparse bricks draw what one brick draws");
        assert_eq!(res.bricks, 216);
        assert_eq!(r.stats().brick_uploads - uploads, res.resident);
        frames.push(res);
    }
    let [narrow, wide] = [frames[0], frames[1]];
    assert!(narrow.resident * 3 < narrow.bricks, "{narrow:?}");
    assert!(wide.resident > narrow.resident);
    // Widening the transfer function on the same upload: only the added bricks come in.
    r.set_transfer_function(&opacity_from(0.55)).unwrap();
    r.render_image(&view, &params).unwrap();
    let before = r.stats().brick_uploads;
    let narrow_resident = r.residency().resident;
    r.set_transfer_function(&opacity_from(0.1)).unwrap();
    r.render_image(&view, &params).unwrap();
    assert_eq!(
        r.stats().brick_uploads - before,
        r.residency().resident - narrow_resident,
        "a wider transfer function uploads only the bricks it adds"
    );
    // Maximum intensity reads every value: every brick comes in.
    let mip = blended(BlendMode::Maximum);
    r.render_image(&view, &mip).unwrap();
    let all = r.residency();
    println!(
        "every brick resident: pool {} bytes; the narrow transfer function's pool is {:.0}% \
         of it",
        all.pool_bytes,
        100.0 * narrow.pool_bytes as f64 / all.pool_bytes as f64
    );
    assert_eq!(all.resident, 216);
    assert!(
        narrow.pool_bytes * 2 < all.pool_bytes,
        "{narrow:?} against {all:?}"
    );
}

/// Streaming: with a memory budget of a quarter of the volume, a frame whose visible bricks
/// exceed it is drawn in several passes, front to back, each with a group of bricks in the
/// pool; the image equals the in-core one in every ray-casting mode and for isosurfaces.
/// Ambient occlusion and volumetric shadows, whose rays leave the pixels' lines, draw a
/// coarser level instead.
#[test]
fn streamed_frames_equal_in_core_ones() {
    let mut r = renderer();
    let vol = blob_volume(40);
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let view = View::fit(vol.bounds(), 64, 64);
    let dense = vol.dims.iter().map(|&d| d as u64).product::<u64>() * 4;
    let budget = UploadOptions {
        max_brick_points: Some(12),
        memory_budget: Some(dense / 4),
        ..Default::default()
    };
    let modes = [
        ("composite", RenderParams::default()),
        ("shaded", shaded()),
        ("maximum", blended(BlendMode::Maximum)),
        ("average", blended(BlendMode::Average)),
        ("additive", blended(BlendMode::Additive)),
    ];
    let told = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let log = told.clone();
    r.set_progress(Some(Box::new(move |done, total| {
        log.lock().unwrap().push((done, total))
    })));
    for (name, params) in modes {
        r.set_volume(&vol).unwrap();
        let in_core = r.render_image(&view, &params).unwrap();
        r.set_volume_with(&vol, budget).unwrap();
        let passes = r.stats().streamed_passes;
        let streamed = r.render_image(&view, &params).unwrap();
        let passes = r.stats().streamed_passes - passes;
        let (mean, max) = image_diff(&in_core, &streamed);
        println!(
            "{name}: budget {} of {dense} bytes, {passes} passes, {} bricks in the pool at \
             the end; against in core: mean {mean:.4}/255, max {max}/255",
            dense / 4,
            r.residency().resident
        );
        // (average and additive are dim grey levels: covered is enough)
        if matches!(params.blend, BlendMode::Average | BlendMode::Additive) {
            assert!(footprint(&streamed) > 400, "{name}: drawn");
        } else {
            assert_content(&streamed, name);
        }
        assert!(passes >= 2, "{name}: the frame was streamed");
        let calls = std::mem::take(&mut *told.lock().unwrap());
        assert_eq!(
            calls,
            (1..=passes).map(|d| (d, passes)).collect::<Vec<_>>(),
            "{name}: progress after each pass"
        );
        assert!(
            r.residency().pool_bytes <= dense / 4,
            "{name}: the pool stays within the budget"
        );
        assert!(max <= 2, "{name}: streamed {max}/255 off");
    }
    // Isosurfaces stream too (the first hit's state carried between passes) and give the
    // in-core hits; with ambient occlusion, whose rays reach around the surfaces' bricks,
    // the budget is reported.
    let iso_params = blended(BlendMode::Isosurface);
    let surfaces = |ao: Option<AmbientOcclusion>| IsoParams {
        values: vec![
            IsoValue::new(0.3, [0.4, 0.6, 1.0], 0.4),
            IsoValue::new(0.6, [1.0; 3], 1.0),
        ],
        ambient_occlusion: ao,
        ..Default::default()
    };
    r.set_isosurface(&surfaces(None)).unwrap();
    r.set_volume(&vol).unwrap();
    let in_core = r.render_image(&view, &iso_params).unwrap();
    let g_in_core = r.read_gbuffer().unwrap();
    r.set_volume_with(&vol, budget).unwrap();
    let passes = r.stats().streamed_passes;
    let streamed = r.render_image(&view, &iso_params).unwrap();
    let passes = r.stats().streamed_passes - passes;
    let g_streamed = r.read_gbuffer().unwrap();
    let (mean, max) = image_diff(&in_core, &streamed);
    let layers = |g: &GBuffer| g.counts.iter().map(|&n| n as usize).sum::<usize>();
    println!(
        "isosurfaces: {passes} passes, {} layers streamed against {} in core; image mean \
         {mean:.4}/255, max {max}/255",
        layers(&g_streamed),
        layers(&g_in_core)
    );
    assert_content(&streamed, "isosurfaces");
    assert!(passes >= 2, "isosurfaces: the frame was streamed");
    assert_eq!(g_streamed.counts, g_in_core.counts, "the same layers");
    assert!(max <= 2, "isosurfaces: streamed {max}/255 off");
    r.set_progress(None);
    // Rays that go anywhere cannot stream: ambient occlusion around the surfaces and
    // volumetric shadows draw the finest coarser level whose needed bricks fit, exactly as
    // that level uploaded as the volume draws at the volume's sample distance and AO radius
    // (one voxel and eight: the level's own defaults would be in its coarser voxels).
    let mut shadows = shaded();
    shadows.shading.volumetric_blending = 1.0;
    let ao = AmbientOcclusion {
        radius: Some(8.0),
        ..Default::default()
    };
    let cases = [
        ("isosurfaces with AO", Some(ao), iso_params.clone()),
        ("volumetric shadows", None, shadows),
    ];
    for (name, ao, params) in cases {
        let params = RenderParams {
            sample_distance: Some(1.0),
            ..params
        };
        // (the gradient-magnitude range of the shininess given too: its default is a
        // voxel's)
        r.set_isosurface(&IsoParams {
            shininess: Shininess::GradientMagnitude {
                range: Some([0.0, 0.25]),
                exponents: [8.0, 64.0],
            },
            ..surfaces(ao)
        })
        .unwrap();
        r.set_volume_with(&vol, budget).unwrap();
        let coarse = r.render_image(&view, &params).unwrap();
        let res = r.residency();
        r.set_volume_with(&vol.downsampled(res.level).unwrap(), budget)
            .unwrap();
        let direct = r.render_image(&view, &params).unwrap();
        let (mean, max) = image_diff(&coarse, &direct);
        println!(
            "{name} over the budget: level {} ({:?}), pool {} of {} bytes; against that level \
             as the volume: mean {mean:.4}/255, max {max}/255",
            res.level,
            res.level_dims,
            res.pool_bytes,
            dense / 4
        );
        assert_content(&coarse, name);
        let points = 39u32.div_ceil(res.level.max(1)) + 1;
        assert!(res.level >= 2, "{name}: a coarser level");
        assert_eq!(res.level_dims, [points; 3], "{name}");
        assert!(res.pool_bytes <= dense / 4, "{name}: within the budget");
        assert_eq!(
            r.residency().level,
            1,
            "{name}: the level drawn as a volume"
        );
        assert_eq!(max, 0, "{name}: the level drawn as uploaded");
    }
}

/// Residency across frames: a zoomed-in camera path of a volume that exceeds the memory
/// budget. Only the bricks in view are needed (rays never leave the view) and they stay
/// resident between frames. Where they fit the budget no frame streams, and a frame a
/// camera move away uploads only the bricks that came into view, evicting the least
/// recently used. Where they do not, frames stream, and the next frame a small move away
/// starts with the bricks the last one left resident where front-to-back order allows:
/// fewer uploads. Every frame equals the in-core one.
#[test]
fn resident_bricks_carry_over_between_frames() {
    let mut r = renderer();
    let vol = blob_volume(40);
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    // budgets in slots of 12³ float32 points; 132 of the 216 bricks are in view
    let fits = camera_path(&mut r, &vol, 150, 20.0);
    assert!(fits.iter().all(|&(_, passes)| passes == 0), "{fits:?}");
    let first = fits[0].0;
    assert!(first < 216, "{fits:?}: only the bricks in view");
    for &(n, _) in &fits[1..] {
        assert!(
            n > 0 && 4 * n < first,
            "{fits:?}: a camera move uploads the bricks that came into view"
        );
    }
    let streamed = camera_path(&mut r, &vol, 60, 3.0);
    assert!(
        streamed.iter().all(|&(_, passes)| passes >= 2),
        "{streamed:?}"
    );
    assert!(
        streamed[1].0 < streamed[0].0,
        "{streamed:?}: the second frame starts with bricks the first left resident"
    );
}

/// Four frames of `vol` at zoom 3, turned by `step` degrees each, with a memory budget of
/// `slots` bricks of 12³ points: each equals the in-core frame (within 1/255) and shows the
/// volume; per frame (bricks uploaded, streamed passes).
fn camera_path(r: &mut Renderer, vol: &VolumeData, slots: u64, step: f64) -> Vec<(u32, u32)> {
    let params = shaded();
    let mut view = View::fit(vol.bounds(), 64, 64);
    view.camera.zoom(3.0);
    let views: Vec<View> = (0..4)
        .map(|_| {
            let v = view.clone();
            view.camera.azimuth(step);
            v
        })
        .collect();
    r.set_volume(vol).unwrap();
    let in_core: Vec<Image> = views
        .iter()
        .map(|v| r.render_image(v, &params).unwrap())
        .collect();
    let slot = 12u64.pow(3) * 4;
    let budget = UploadOptions {
        max_brick_points: Some(12),
        memory_budget: Some(slots * slot),
        ..Default::default()
    };
    r.set_volume_with(vol, budget).unwrap();
    let mut out = Vec::new();
    for (i, (v, in_core)) in views.iter().zip(&in_core).enumerate() {
        let before = r.stats();
        let frame = r.render_image(v, &params).unwrap();
        let after = r.stats();
        let (mean, max) = image_diff(in_core, &frame);
        let res = r.residency();
        let n = after.brick_uploads - before.brick_uploads;
        let passes = after.streamed_passes - before.streamed_passes;
        println!(
            "budget {slots} bricks, frame {i} ({step}° apart): {n} bricks uploaded, {passes} \
             streamed passes, {} of {} bricks resident; against in core: mean {mean:.4}/255, \
             max {max}/255",
            res.resident, res.bricks
        );
        assert_content(&frame, "zoomed frame");
        assert!(max <= 1, "frame {i}: {max}/255 off");
        assert!(res.pool_bytes <= slots * slot);
        out.push((n, passes));
    }
    out
}

/// The pool shrinks when a frame needs much less of it (a transfer function that hides most
/// of the volume) and not for small changes: it shrinks only when it holds twice the layers
/// of slots the frame needs, to one and a half times them, keeping the needed bricks
/// (copied on the device, not uploaded again).
#[test]
fn the_pool_shrinks_with_hysteresis() {
    let mut r = renderer();
    let vol = blob_volume(40);
    let view = View::fit(vol.bounds(), 64, 64);
    let params = RenderParams::default();
    let steps = [0.1, 0.7, 0.65, 0.1];
    r.set_volume(&vol).unwrap();
    let one: Vec<Image> = steps
        .iter()
        .map(|&from| {
            r.set_transfer_function(&opacity_from(from)).unwrap();
            r.render_image(&view, &params).unwrap()
        })
        .collect();
    set_bricked(&mut r, &vol, 12);
    let mut seen = Vec::new();
    for (&from, one) in steps.iter().zip(&one) {
        r.set_transfer_function(&opacity_from(from)).unwrap();
        let uploads = r.stats().brick_uploads;
        let split = r.render_image(&view, &params).unwrap();
        let (_, max) = image_diff(one, &split);
        let res = r.residency();
        println!(
            "opacity from {from}: {} of {} bricks resident, pool {} bytes, {} uploaded; \
             against one brick max {max}/255",
            res.resident,
            res.bricks,
            res.pool_bytes,
            r.stats().brick_uploads - uploads
        );
        assert!(max <= 2, "{max}/255 off");
        assert!(footprint(&split) > 50, "drawn");
        seen.push((res, r.stats().brick_uploads - uploads));
    }
    let [(wide, _), (narrow, narrow_uploads), (wider, _), (again, _)] = seen[..] else {
        unreachable!()
    };
    assert!(
        2 * narrow.pool_bytes <= wide.pool_bytes,
        "a transfer function showing little shrinks the pool: {narrow:?} after {wide:?}"
    );
    assert_eq!(narrow_uploads, 0, "the needed bricks were resident: copied");
    assert_eq!(
        wider.pool_bytes, narrow.pool_bytes,
        "a little more shown: the pool neither grows nor shrinks"
    );
    assert_eq!(again.pool_bytes, wide.pool_bytes, "and grows back");
}
