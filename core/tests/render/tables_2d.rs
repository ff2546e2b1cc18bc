//! 2D transfer functions (vtkVolumeProperty's TF_2D): a table whose rows all hold the 1D
//! function draws the 1D image, ray cast and path traced; the gradient axis selects what is
//! drawn; bad tables and the modes that do not read them are refused.

use crate::common::gpu::{assert_error, renderer, trace};
use crate::common::images::save_enlarged;
use crate::common::metrics::{channel_sums, footprint, image_diff};
use crate::common::scenes::{blob_transfer, blob_volume, shaded};
use ferrovol_core::*;

const W: u32 = 256;
const H: u32 = 64;

/// blob_transfer's colour and opacity as a 2D table over [0, 1], every row alike, or the
/// opacity where the row's gradient magnitude (up to `gmax`) passes `edge` only. A table's
/// opacity is per sample (as VTK reads it): the 1D function's, corrected from its unit
/// distance to the default step (one voxel spacing).
fn table(gmax: Option<f64>, edge: Option<f64>) -> Table2D {
    let c = blob_transfer();
    let mut rgba = Vec::new();
    for y in 0..H {
        let g = (y as f64 + 0.5) / H as f64 * gmax.unwrap_or(1.0);
        for x in 0..W {
            let s = (x as f64 + 0.5) / W as f64;
            let [r, gr, b] = c.color.eval(s);
            let a = 1.0 - (1.0 - c.opacity.eval(s)[0]).powf((1.0 / c.unit_distance) as f32);
            let keep = edge.is_none_or(|e| g > e);
            rgba.push([r, gr, b, if keep { a } else { 0.0 }]);
        }
    }
    Table2D {
        width: W,
        height: H,
        rgba,
        scalar_range: [0.0, 1.0],
        gradient_max: gmax,
    }
}

fn with_table(t: Table2D) -> TransferFunction {
    let mut c = blob_transfer();
    c.table_2d = Some(t);
    TransferFunction::single(c)
}

#[test]
fn table_2d_equals_1d_and_reads_the_gradient() {
    let mut r = renderer();
    let vol = blob_volume(32);
    r.set_volume(&vol).unwrap();
    let view = View::fit(vol.bounds(), 96, 96);
    for p in [RenderParams::default(), shaded()] {
        r.set_transfer_function(&TransferFunction::single(blob_transfer()))
            .unwrap();
        let one = r.render_image(&view, &p).unwrap();
        r.set_transfer_function(&with_table(table(None, None)))
            .unwrap();
        let two = r.render_image(&view, &p).unwrap();
        save_enlarged(&two, &format!("table_2d_flat_{}", p.shading.enabled));
        let (mean, max) = image_diff(&one, &two);
        println!(
            "shade {}: 2D table of the 1D function vs 1D: mean {mean:.3}, max {max} levels",
            p.shading.enabled
        );
        assert!(mean < 0.5 && max <= 6, "{mean} {max}");
    }
    // only steep gradients opaque: less drawn; the same table read at the first row only
    // (no gradient range): nothing
    let p = RenderParams::default();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let all = r.render_image(&view, &p).unwrap();
    r.set_transfer_function(&with_table(table(Some(0.1), Some(0.05))))
        .unwrap();
    let steep = r.render_image(&view, &p).unwrap();
    save_enlarged(&steep, "table_2d_steep");
    r.set_transfer_function(&with_table(table(None, Some(0.05))))
        .unwrap();
    let first_row = r.render_image(&view, &p).unwrap();
    let (mean, _) = image_diff(&all, &steep);
    println!(
        "steep gradients only: {mean:.2} levels from the 1D image; footprint {} vs {}; \
         first row only: {} pixels",
        footprint(&steep),
        footprint(&all),
        footprint(&first_row)
    );
    assert!(mean > 1.0);
    assert!(footprint(&steep) > 100 && footprint(&steep) < footprint(&all));
    assert_eq!(footprint(&first_row), 0);
}

#[test]
fn table_2d_errors() {
    let mut r = renderer();
    let vol = blob_volume(16);
    r.set_volume(&vol).unwrap();
    let view = View::fit(vol.bounds(), 32, 32);
    let mut t = table(None, None);
    t.rgba.pop();
    assert_error(
        r.set_transfer_function(&with_table(t)),
        "short table",
        &["component 0", "2D table", "16383 RGBA values", "256x64"],
    );
    let mut t = table(None, None);
    t.scalar_range = [1.0, 1.0];
    assert_error(
        r.set_transfer_function(&with_table(t)),
        "empty range",
        &["scalar range [1, 1]"],
    );
    let mut t = table(Some(0.0), None);
    t.rgba[3][1] = f32::NAN;
    assert_error(r.set_transfer_function(&with_table(t)), "NaN", &["entry 3"]);
    r.set_transfer_function(&with_table(table(None, None)))
        .unwrap();
    assert_error(
        r.render_image(
            &view,
            &RenderParams {
                blend: BlendMode::Maximum,
                ..RenderParams::default()
            },
        ),
        "MIP",
        &["2D"],
    );
}

/// The path tracer reads the 2D table as the medium (its opacity as the 1D functions' is
/// read, per unit distance): a table whose rows all hold the 1D functions converges to the
/// 1D image (sums over the image within 1% per channel and coverage); one opaque at steep
/// gradients only meets the medium less.
#[test]
fn path_tracing_reads_the_table() {
    let mut r = renderer();
    let vol = blob_volume(24);
    r.set_volume(&vol).unwrap();
    let view = View::fit(vol.bounds(), 32, 32);
    let c = blob_transfer();
    let raw = |gmax: Option<f64>, edge: Option<f64>| {
        let mut t = table(gmax, edge);
        for (i, v) in t.rgba.iter_mut().enumerate() {
            let s = ((i % W as usize) as f64 + 0.5) / W as f64;
            let g = ((i / W as usize) as f64 + 0.5) / H as f64 * gmax.unwrap_or(1.0);
            let keep = edge.is_none_or(|e| g > e);
            v[3] = if keep { c.opacity.eval(s)[0] } else { 0.0 };
        }
        t
    };
    let p = PathTraceParams {
        samples_per_frame: 64,
        ..Default::default()
    };
    let mut sums = Vec::new();
    for tf in [
        TransferFunction::single(c.clone()),
        with_table(raw(None, None)),
        with_table(raw(Some(0.1), Some(0.05))),
    ] {
        r.set_transfer_function(&tf).unwrap();
        let img = trace(&mut r, &view, &p, 1024);
        sums.push(channel_sums(&img));
    }
    let rel: Vec<f64> = (0..4).map(|k| sums[1][k] / sums[0][k] - 1.0).collect();
    println!(
        "2D table of the 1D functions / 1D − 1 (r, g, b, coverage): {rel:.4?}; coverage \
         summed: 1D {:.1}, steep gradients only {:.1}",
        sums[0][3], sums[2][3]
    );
    assert!(sums[0][3] > 50.0, "the medium is met");
    for d in rel {
        assert!(d.abs() < 0.01, "{d}");
    }
    // (the blob's edge is steep: most paths still meet it there; 0.926 measured)
    assert!(sums[2][3] < 0.97 * sums[0][3]);
}
