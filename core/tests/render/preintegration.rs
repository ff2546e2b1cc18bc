//! Pre-integrated classification (RenderParams::preintegration): a thin opacity peak that
//! the default step slices into rings comes out (nearly) as the converged image, and the
//! setting leaves every frame without it as it was.

use crate::common::gpu::{renderer, set_bricked};
use crate::common::images::save_enlarged;
use crate::common::metrics::{footprint, frame_diff, image_diff, psnr};
use crate::common::scenes::{component_transfer, oblique, radial};
use ferrovol_core::*;

/// PSNR (dB) of `img` against `reference` over the RGBA bytes.
fn shell_volume() -> VolumeData {
    radial(48, |d| 4.0 * d)
}

/// A radial field rising 4 scalar units per voxel under a transfer function whose opacity
/// is one peak 2 units wide (half a voxel across in space): at one sample per voxel the
/// samples fall on the peak or beside it by where each ray happens to cross the shell.
fn thin_shell(r: &mut Renderer) -> View {
    let vol = shell_volume();
    r.set_volume(&vol).unwrap();
    let tf = component_transfer(
        &[(0.0, [1.0, 0.5, 0.2]), (160.0, [0.2, 0.6, 1.0])],
        &[
            (0.0, 0.0),
            (87.0, 0.0),
            (88.0, 0.9),
            (89.0, 0.0),
            (160.0, 0.0),
        ],
        1.0,
    );
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    oblique(&vol, 96)
}

#[test]
fn a_thin_peak_converges_at_the_default_step() {
    let mut r = renderer();
    let view = thin_shell(&mut r);
    let at = |r: &mut Renderer, step: Option<f64>, pre: bool| {
        let params = RenderParams {
            sample_distance: step,
            preintegration: pre,
            ..RenderParams::default()
        };
        r.render_image(&view, &params).unwrap()
    };
    let reference = at(&mut r, Some(1.0 / 16.0), false);
    let plain = at(&mut r, None, false);
    let half = at(&mut r, Some(0.5), false);
    let pre = at(&mut r, None, true);
    let pre_reference = at(&mut r, Some(1.0 / 16.0), true);
    save_enlarged(&reference, "preintegration_reference");
    save_enlarged(&plain, "preintegration_off");
    save_enlarged(&pre, "preintegration_on");
    let covered = footprint(&reference);
    let mean_alpha =
        reference.rgba.chunks(4).map(|p| p[3] as f64).sum::<f64>() / covered.max(1) as f64;
    let (db_plain, db_half, db_pre, db_pre_ref) = (
        psnr(&plain, &reference),
        psnr(&half, &reference),
        psnr(&pre, &reference),
        psnr(&pre_reference, &reference),
    );
    let ((mean_plain, max_plain), (mean_pre, max_pre)) =
        (image_diff(&plain, &reference), image_diff(&pre, &reference));
    println!(
        "thin shell, {covered} pixels covered (mean alpha {mean_alpha:.1}): against 1/16-voxel \
         sampling, step 1 {db_plain:.2} dB (mean {mean_plain:.2}, max {max_plain}), step 1/2 \
         {db_half:.2} dB, pre-integrated step 1 {db_pre:.2} dB (mean {mean_pre:.2}, max \
         {max_pre}); pre-integrated at 1/16 {db_pre_ref:.2} dB"
    );
    // The shell covers a sixth of the frame or more and is not faint: a black frame cannot pass.
    assert!(
        covered > 96 * 96 / 6 && mean_alpha > 40.0,
        "{covered} {mean_alpha}"
    );
    assert!(db_pre > 40.0, "pre-integrated {db_pre:.2} dB");
    assert!(db_plain < 30.0, "plain sampling {db_plain:.2} dB");
    assert!(
        db_pre > db_half + 6.0,
        "{db_pre:.2} vs half step {db_half:.2}"
    );
    assert!(
        db_pre_ref > 45.0,
        "both converge to the same image: {db_pre_ref:.2} dB"
    );
}

/// Pre-integration off (the default) draws what the renderer drew before it existed, and
/// a frame with it on changes no later frame without it; blend modes it does not apply to
/// ignore it.
#[test]
fn preintegration_off_changes_nothing() {
    let mut r = renderer();
    let view = thin_shell(&mut r);
    let off = RenderParams::default();
    let on = RenderParams {
        preintegration: true,
        ..RenderParams::default()
    };
    let before = r.render_image(&view, &off).unwrap();
    let with = r.render_image(&view, &on).unwrap();
    let builds = r.stats().preintegration_builds;
    let again = r.render_image(&view, &on).unwrap();
    let after = r.render_image(&view, &off).unwrap();
    assert_eq!(frame_diff(&before, &after), (0, 0));
    assert_ne!(
        image_diff(&before, &with).1,
        0,
        "pre-integration changed nothing"
    );
    assert_eq!(frame_diff(&with, &again), (0, 0));
    // built once for this transfer function and step, again for another step
    assert_eq!(r.stats().preintegration_builds, builds);
    let other_step = RenderParams {
        sample_distance: Some(0.5),
        ..on.clone()
    };
    r.render_image(&view, &other_step).unwrap();
    assert_eq!(r.stats().preintegration_builds, builds + 1);
    for blend in [BlendMode::Maximum, BlendMode::Additive] {
        let a = r
            .render_image(
                &view,
                &RenderParams {
                    blend,
                    ..off.clone()
                },
            )
            .unwrap();
        let b = r
            .render_image(
                &view,
                &RenderParams {
                    blend,
                    ..on.clone()
                },
            )
            .unwrap();
        assert_eq!(frame_diff(&a, &b), (0, 0), "{blend:?}");
    }
}

/// Bricked, a ray's previous sample may lie in another brick: the image is the unbricked
/// one (the bricks' aprons hold every point a sample reads).
#[test]
fn preintegration_across_bricks() {
    let mut r = renderer();
    let view = thin_shell(&mut r);
    let on = RenderParams {
        preintegration: true,
        ..RenderParams::default()
    };
    let whole = r.render_image(&view, &on).unwrap();
    set_bricked(&mut r, &shell_volume(), 12);
    let bricked = r.render_image(&view, &on).unwrap();
    let (mean, max) = image_diff(&whole, &bricked);
    println!("pre-integrated, bricks of 12 points vs one texture: mean {mean:.4}, max {max}");
    // the same samples from the same data; one level for the filtering's rounding
    assert!(max <= 1, "mean {mean}, max {max}");
}
