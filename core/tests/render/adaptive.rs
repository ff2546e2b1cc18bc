//! Adaptive steps ([`Quadrature::Adaptive`]): midpoints with 1, 2 or 4 sample distances per
//! step by how much the classified function changes per step in each block. Smooth data
//! under a smooth transfer function takes coarse steps and stays closer to the converged
//! image than VTK's lattice at every step; rough data (noise) takes every step, the
//! midpoint image; a flat transfer function takes coarse steps without error; bricked and
//! streamed frames are the in-core one; jittering is refused.

use crate::common::gpu::{assert_error, renderer, set_bricked};
use crate::common::images::save_enlarged;
use crate::common::metrics::{image_diff, psnr};
use crate::common::scenes::{component_transfer, shaded, volume};
use ferrovol_core::*;

const TOP: f32 = 0.15;

fn at(q: Quadrature, dt: f64, base: &RenderParams) -> RenderParams {
    RenderParams {
        quadrature: q,
        sample_distance: Some(dt),
        ..base.clone()
    }
}

fn ramp(lo: f64, hi: f64, top: f32) -> TransferFunction {
    TransferFunction::single(component_transfer(
        &[
            (lo, [0.2, 0.29, 1.0]),
            (0.5 * (lo + hi), [0.87, 0.87, 0.87]),
            (hi, [0.7, 0.015, 0.15]),
        ],
        &[(lo, 0.0), (hi, top)],
        1.0,
    ))
}

/// The wavelet (64³, VTK's benchmark colours, opacity up to 0.3): unshaded, coarse steps
/// (the image differs from the midpoint one) and closer to the converged image than VTK's
/// lattice at the same step; shaded, every step (the midpoint image).
#[test]
fn adaptive_steps_stay_closer_than_vtks_lattice_on_the_wavelet() {
    let mut r = renderer();
    let vol = synth::wavelet(synth::wavelet_extent(64));
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&ramp(37.3531, 276.829, TOP))
        .unwrap();
    let view = View::fit(vol.bounds(), 128, 128);
    for (name, base) in [("unshaded", RenderParams::default()), ("shaded", shaded())] {
        let mut img = |q, dt| r.render_image(&view, &at(q, dt, &base)).unwrap();
        let converged = img(Quadrature::Midpoint, 1.0 / 16.0);
        let vtk_converged = img(Quadrature::Vtk, 1.0 / 16.0);
        let vtk = psnr(&img(Quadrature::Vtk, 1.0), &vtk_converged);
        let mid = img(Quadrature::Midpoint, 1.0);
        let adaptive = img(Quadrature::Adaptive, 1.0);
        save_enlarged(&adaptive, &format!("adaptive_wavelet_{name}"));
        let (a, m) = (psnr(&adaptive, &converged), psnr(&mid, &converged));
        let (_, max) = image_diff(&adaptive, &mid);
        println!(
            "wavelet {name}, step 1: VTK's lattice {vtk:.1} dB, midpoints {m:.1} dB, adaptive \
             {a:.1} dB (at most {max} from the midpoint image)"
        );
        if name == "unshaded" {
            assert!(a > vtk + 3.0, "{a} vs {vtk}");
            assert!(max > 0, "no step was coarse");
        } else {
            assert_eq!(max, 0, "a shaded ray took a coarse step");
        }
    }
}

/// Noise of the full range between neighbouring voxels: every block's classified function
/// can change by the whole table per voxel, so every step is one sample distance and the
/// image is the midpoint one; under a flat transfer function (one colour, one opacity) the
/// steps are coarse (four sample distances) and exact all the same.
#[test]
fn rough_data_takes_every_step_and_flat_functions_any() {
    let mut r = renderer();
    let hash = |i: u64| ((i.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40) % 1000) as f64 / 1000.0;
    let vol = volume([40; 3], |x, y, z| {
        let smooth = 0.5 + 0.2 * ((x + 2.0 * y) / 17.0).sin() * (z / 11.0).cos();
        let n = hash((x as u64) | (y as u64) << 16 | (z as u64) << 32);
        smooth + 0.6 * (n - 0.5)
    });
    r.set_volume(&vol).unwrap();
    let view = View::fit(vol.bounds(), 96, 96);
    // the adaptive image's largest difference from the midpoint one
    let from_midpoints = |r: &mut Renderer, what: &str| {
        let base = RenderParams::default();
        let mut img = |q| r.render_image(&view, &at(q, 1.0, &base)).unwrap();
        let (mid, adaptive) = (img(Quadrature::Midpoint), img(Quadrature::Adaptive));
        let (mean, max) = image_diff(&adaptive, &mid);
        println!("{what}: adaptive vs midpoints mean {mean:.4}, max {max}");
        max
    };
    r.set_transfer_function(&ramp(0.0, 1.0, 1.0)).unwrap();
    assert_eq!(
        from_midpoints(&mut r, "noise"),
        0,
        "rough data took a coarse step"
    );
    r.set_transfer_function(&TransferFunction::single(component_transfer(
        &[(0.0, [0.9, 0.6, 0.3]), (1.0, [0.9, 0.6, 0.3])],
        &[(0.0, 0.02), (1.0, 0.02)],
        1.0,
    )))
    .unwrap();
    let max = from_midpoints(&mut r, "flat function");
    assert!(max <= 1, "{max}");
}

#[test]
fn adaptive_steps_are_the_same_bricked_and_streamed() {
    let mut r = renderer();
    let vol = synth::wavelet(synth::wavelet_extent(40));
    r.set_transfer_function(&ramp(37.3531, 276.829, TOP))
        .unwrap();
    let view = View::fit(vol.bounds(), 64, 64);
    let params = at(Quadrature::Adaptive, 1.0, &RenderParams::default());
    r.set_volume(&vol).unwrap();
    let whole = r.render_image(&view, &params).unwrap();
    let mid = at(Quadrature::Midpoint, 1.0, &RenderParams::default());
    let (_, coarse) = image_diff(&whole, &r.render_image(&view, &mid).unwrap());
    assert!(coarse > 0, "no step was coarse");
    set_bricked(&mut r, &vol, 12);
    let bricked = r.render_image(&view, &params).unwrap();
    let (mean, max) = image_diff(&bricked, &whole);
    println!("adaptive bricked vs one brick: mean {mean:.4}, max {max}");
    assert!(max <= 1, "{max}");
    let budget = UploadOptions {
        max_brick_points: Some(12),
        memory_budget: Some(41u64.pow(3) * 4 / 4),
        ..Default::default()
    };
    r.set_volume_with(&vol, budget).unwrap();
    let streamed = r.render_image(&view, &params).unwrap();
    let res = r.residency();
    assert!(res.pool_bytes < res.dense_bytes / 2, "{res:?}");
    let (mean, max) = image_diff(&streamed, &whole);
    println!("adaptive streamed vs in core: mean {mean:.4}, max {max}");
    assert!(max <= 1, "{max}");
    r.set_volume(&vol).unwrap();
    let jittered = RenderParams {
        jitter: true,
        ..params
    };
    assert_error(
        r.render_image(&view, &jittered),
        "adaptive steps with jittering",
        &["adaptive", "jittering"],
    );
}
