//! Level of detail per brick in interactive frames ([`RenderParams::preview_level`]) of ray
//! casting past the memory budget: one pass, fine bricks where resident and a coarser
//! level's bricks standing in elsewhere; the bricks the rays read from a stand-in come in
//! the next frames, so frames of a still camera converge to the in-core image, and bricks no
//! ray reaches are never brought.

use crate::common::gpu::renderer;
use crate::common::images::save_enlarged;
use crate::common::metrics::{footprint, image_diff, psnr};
use crate::common::scenes::{blob_transfer, blob_volume, component_transfer, volume};
use ferrovol_core::*;

/// The still and the preview parameters of `blend`, and the in-core image of `vol` (set
/// without a budget) at `view`.
fn in_core(
    r: &mut Renderer,
    vol: &VolumeData,
    view: &View,
    blend: BlendMode,
) -> (RenderParams, RenderParams, Image) {
    let still = RenderParams {
        blend,
        sample_distance: Some(1.0),
        ..Default::default()
    };
    let preview = RenderParams {
        preview_level: true,
        ..still.clone()
    };
    r.set_volume(vol).unwrap();
    let image = r.render_image(view, &still).unwrap();
    (still, preview, image)
}

/// The first preview frame past the budget draws in one pass (ray casting and the
/// isosurfaces' first hit), from the stand-ins where fine bricks are missing, close to the
/// in-core image; the still frame streams and equals it. A masked preview streams (masks
/// have no coarser levels).
#[test]
fn previews_draw_coarser_bricks_where_fine_ones_are_missing() {
    let mut r = renderer();
    let vol = blob_volume(40);
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    r.set_isosurface(&IsoParams {
        shininess: Shininess::Constant(32.0),
        ..IsoParams::with_values(vec![IsoValue::new(0.3, [0.4, 0.6, 1.0], 1.0)])
    })
    .unwrap();
    let view = View::fit(vol.bounds(), 64, 64);
    let dense = 40u64.pow(3) * 4;
    let budget = UploadOptions {
        max_brick_points: Some(12),
        memory_budget: Some(dense / 4),
        ..Default::default()
    };
    for blend in [
        BlendMode::Composite,
        BlendMode::Maximum,
        BlendMode::Isosurface,
    ] {
        let (still, preview, in_core) = in_core(&mut r, &vol, &view, blend);
        let fits = r.render_image(&view, &preview).unwrap();
        assert_eq!(image_diff(&in_core, &fits).1, 0, "{blend:?}: fits");
        assert_eq!(r.residency().stand_ins, 0);
        r.set_volume_with(&vol, budget).unwrap();
        let passes = r.stats().streamed_passes;
        let first = r.render_image(&view, &preview).unwrap();
        let res = r.residency();
        assert_eq!(r.stats().streamed_passes, passes, "{blend:?}: one pass");
        save_enlarged(&first, &format!("lod_first_{blend:?}"));
        let (mean, max) = image_diff(&first, &in_core);
        println!(
            "{blend:?}: first preview {:.1} dB from in core (mean {mean:.3}/255, max \
             {max}/255), {} bricks read from stand-ins, {} of {} fine bricks resident, pool \
             {} of {} bytes",
            psnr(&first, &in_core),
            res.stand_ins,
            res.resident,
            res.bricks,
            res.pool_bytes,
            dense / 4
        );
        assert!(footprint(&first) * 2 > footprint(&in_core));
        assert!(res.stand_ins > 0 && res.pool_bytes <= dense / 4, "{res:?}");
        assert!(psnr(&first, &in_core) > 20.0, "{blend:?}: close to in core");
        let streamed = r.render_image(&view, &still).unwrap();
        assert!(
            r.stats().streamed_passes >= passes + 2,
            "the still frame streams"
        );
        assert!(
            image_diff(&streamed, &in_core).1 <= 2,
            "{blend:?}: and equals in core"
        );
        assert_eq!(
            r.residency().stand_ins,
            0,
            "no stand-in after a still frame"
        );
    }
    r.set_volume_with(&vol, budget).unwrap();
    r.set_mask(Some((&vec![1u8; 40 * 40 * 40], MaskKind::Binary)))
        .unwrap();
    let passes = r.stats().streamed_passes;
    let preview = RenderParams {
        preview_level: true,
        ..Default::default()
    };
    let masked = r.render_image(&view, &preview).unwrap();
    assert!(footprint(&masked) > 0, "masked preview drawn");
    assert!(
        r.stats().streamed_passes > passes,
        "a masked preview streams"
    );
    assert_eq!(r.residency().stand_ins, 0);
}

/// An n³ volume whose opaque slab in its top 7 layers holds a pattern finer than the
/// stand-ins' points, over a faint body, and its transfer function set on `r`.
pub(crate) fn slab_scene(r: &mut Renderer, n: u32) -> VolumeData {
    let vol = volume([n; 3], |x, y, z| match z >= (n - 7) as f64 {
        true => 0.8 + 0.2 * (x / 1.5).sin() * (y / 2.0).sin(),
        false => 0.3,
    });
    r.set_transfer_function(&TransferFunction::single(component_transfer(
        &[
            (0.0, [0.2, 0.3, 0.9]),
            (0.6, [0.2, 0.3, 0.9]),
            (1.0, [1.0, 0.8, 0.3]),
        ],
        &[(0.0, 0.0), (0.3, 0.05), (0.55, 1.0), (1.0, 1.0)],
        1.0,
    )))
    .unwrap();
    vol
}

/// A box whose top slab (toward the camera) is opaque over a translucent inside: every brick
/// is visible and in view, too many for the budget, but the rays stop in the top layer of
/// bricks. Preview frames of a still camera bring the bricks the rays read, a share of the
/// pool per frame, until none is read from a stand-in: then the frame equals the in-core
/// image, and the bricks below the slab were never brought.
#[test]
fn previews_converge_to_the_fine_image_and_bring_only_what_rays_read() {
    let mut r = renderer();
    let n = 96u32;
    let vol = slab_scene(&mut r, n);
    let view = View::fit(vol.bounds(), 64, 64);
    let (_, preview, in_core) = in_core(&mut r, &vol, &view, BlendMode::Composite);
    let dense = (n as u64).pow(3) * 4;
    // 50 slots: stand-ins from the level twice as coarse; 36: four times, so that the bricks
    // the rays read fit beside them
    for budget in [dense * 4 / 5, dense * 9 / 16] {
        r.set_volume_with(
            &vol,
            UploadOptions {
                max_brick_points: Some(24),
                memory_budget: Some(budget),
                ..Default::default()
            },
        )
        .unwrap();
        let uploads = r.stats().brick_uploads;
        let mut frames = Vec::new();
        let complete = loop {
            let img = r.render_image(&view, &preview).unwrap();
            let res = r.residency();
            frames.push((res.stand_ins, res.resident, psnr(&img, &in_core)));
            if res.stand_ins == 0 || frames.len() == 12 {
                break (res.stand_ins == 0).then_some((img, res));
            }
        };
        let Some((img, res)) = complete else {
            panic!("never complete: (stand-ins read, resident, PSNR) per frame {frames:?}");
        };
        let (mean, max) = image_diff(&img, &in_core);
        println!(
            "budget {budget}: complete after {} frames {frames:?}: {mean:.4}/255 mean, \
             {max}/255 max from in core; {} of {} bricks resident, {} uploads",
            frames.len(),
            res.resident,
            res.bricks,
            r.stats().brick_uploads - uploads
        );
        assert!(max <= 2, "the complete preview equals in core");
        assert!(
            res.resident * 3 < res.bricks,
            "the bricks under the slab never came: {res:?}"
        );
        assert!(frames[0].0 > 0 && frames[0].2 < frames[frames.len() - 1].2);
    }
}

/// Lines one point thin, bright in a dim volume (MIP) or dark in a bright one (MinIP): the
/// stand-ins of a preview keep the largest (smallest) value their points reach, so the
/// first preview draws the lines at least as bright (dark) as in core, where a mean would
/// have lowered (raised) them by most of their contrast.
#[test]
fn mip_and_minip_previews_keep_thin_lines() {
    let mut r = renderer();
    let n = 40u32;
    let line = |x: f64, y: f64, z: f64| (y == 21.0 && z == 19.0) || (x == 13.0 && z == 25.0);
    r.set_transfer_function(&TransferFunction::single(component_transfer(
        &[(0.0, [1.0; 3]), (1.0, [1.0; 3])],
        &[(0.0, 0.0), (1.0, 1.0)],
        1.0,
    )))
    .unwrap();
    let view = View::fit(blob_volume(n).bounds(), 64, 64);
    for (blend, inside, on_line) in [
        (BlendMode::Maximum, 0.1, 1.0),
        (BlendMode::Minimum, 0.9, 0.0),
    ] {
        let vol = volume(
            [n; 3],
            |x, y, z| if line(x, y, z) { on_line } else { inside },
        );
        let (_, preview, in_core) = in_core(&mut r, &vol, &view, blend);
        r.set_volume_with(
            &vol,
            UploadOptions {
                max_brick_points: Some(12),
                memory_budget: Some((n as u64).pow(3)),
                ..Default::default()
            },
        )
        .unwrap();
        let first = r.render_image(&view, &preview).unwrap();
        let res = r.residency();
        save_enlarged(&first, &format!("lod_lines_{blend:?}"));
        // per image row and column across the middle of the image, the extreme grey inside
        // the volume's box: the vertical line's and the horizontal line's peaks (the lines
        // grow wider in the coarser stand-ins, and their ends follow the level's points)
        let grey = |img: &Image, x: u32, y: u32| img.rgba[((y * img.width + x) * 4) as usize];
        let middle = 22..42u32;
        // (the pixels well inside the volume's box, which covers 11–53 of 64)
        let inside_box = 15..50u32;
        let extreme = |img: &Image| {
            let pick = |a: u8, b: u8| {
                if blend == BlendMode::Maximum {
                    a.max(b)
                } else {
                    a.min(b)
                }
            };
            // (a row y is the pixels (x, y) across the box, a column x those (x, y))
            let across = |i: u32, row: bool| {
                let at = |j: u32| {
                    if row {
                        grey(img, j, i)
                    } else {
                        grey(img, i, j)
                    }
                };
                f64::from(inside_box.clone().map(at).reduce(pick).unwrap())
            };
            let rows = middle.clone().map(|y| across(y, true));
            rows.chain(middle.clone().map(|x| across(x, false)))
                .collect::<Vec<f64>>()
        };
        let (a, b) = (extreme(&first), extreme(&in_core));
        // the lines' contrast: in core, against the grey beside them in the image's centre
        let beside = f64::from(grey(&in_core, 32, 38));
        let contrast = b.iter().map(|x| (x - beside).abs()).fold(255.0, f64::min);
        // how much fainter than in core the preview draws the lines (the stand-ins' lines
        // are wider: their samples meet the peak where in core a sample between points
        // meets less of it, so they may be stronger)
        let fainter = a
            .iter()
            .zip(&b)
            .map(|(x, y)| {
                if blend == BlendMode::Maximum {
                    y - x
                } else {
                    x - y
                }
            })
            .fold(f64::MIN, f64::max);
        println!(
            "{blend:?}: first preview {} stand-ins read, {} of {} fine bricks resident; the \
             lines' peak per row and column {:.0}–{:.0}/255, in core {:.0}–{:.0}/255 \
             (contrast at least {contrast:.0}/255)",
            res.stand_ins,
            res.resident,
            res.bricks,
            a.iter().copied().fold(255.0, f64::min),
            a.iter().copied().fold(0.0, f64::max),
            b.iter().copied().fold(255.0, f64::min),
            b.iter().copied().fold(0.0, f64::max),
        );
        assert!(res.stand_ins > 0, "{blend:?}: the preview reads stand-ins");
        assert!(contrast > 100.0, "{blend:?}: the lines show in core");
        assert!(
            fainter <= 2.0,
            "{blend:?}: the preview draws the lines up to {fainter}/255 fainter than in core"
        );
    }
}
