//! Rectilinear grids (per-axis coordinates, VTK's vtkRectilinearGrid): rays march the box's
//! uniform lattice and each sample is mapped to the grid's index space per axis.

use crate::common::gpu::{assert_error, renderer, trace};
use crate::common::images::save_enlarged;
use crate::common::metrics::{alpha, channel_sums, footprint, image_diff};
use crate::common::raycast::to_pixel;
use crate::common::scenes::{blended, blob_transfer, blob_volume, shaded, volume, white};
use ferrovol_core::*;
use glam::DVec3;

/// The coordinates of a uniform grid's points along each axis.
fn uniform_coordinates(v: &VolumeData) -> [Vec<f64>; 3] {
    std::array::from_fn(|a| {
        (0..v.dims[a])
            .map(|i| v.origin[a] + v.spacing[a] * i as f64)
            .collect()
    })
}

/// Coordinates that place the points where they already are draw the image of the uniform
/// grid, in every ray-casting blend mode, shaded composite included, and isosurfaces.
#[test]
fn uniform_coordinates_draw_the_plain_volume() {
    let mut r = renderer();
    let plain = blob_volume(24)
        .with_spacing([0.5, 0.75, 1.0])
        .and_then(|v| v.with_origin([-3.0, 2.0, 1.0]))
        .unwrap();
    let coords = uniform_coordinates(&plain);
    let rect = plain.clone().with_coordinates(coords).unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    r.set_isosurface(&IsoParams::with_values(vec![IsoValue::new(
        0.3,
        [0.9, 0.8, 0.6],
        1.0,
    )]))
    .unwrap();
    let mut view = View::fit(plain.bounds(), 64, 64);
    view.camera.azimuth(30.0);
    view.camera.elevation(20.0);
    for (name, p) in [
        ("composite", RenderParams::default()),
        ("shaded", shaded()),
        ("mip", blended(BlendMode::Maximum)),
        ("average", blended(BlendMode::Average)),
        ("isosurface", blended(BlendMode::Isosurface)),
    ] {
        r.set_volume(&plain).unwrap();
        let a = r.render_image(&view, &p).unwrap();
        r.set_volume(&rect).unwrap();
        let b = r.render_image(&view, &p).unwrap();
        let (mean, max) = image_diff(&a, &b);
        println!("{name}: mean {mean:.4}, max {max} levels");
        save_enlarged(&b, &format!("rectilinear_uniform_{name}"));
        assert!(a.rgba.iter().any(|&x| x > 40), "{name}: an empty image");
        // (the lookup reproduces the lattice up to f32 rounding of the index)
        assert!(max <= 2, "{name}: the images differ by {max} levels");
    }
}

/// A step between points 7 and 8 along x, on x coordinates i²: the value crosses 0.5
/// between x = 49 and x = 64, at x = 56.5 (on the uniform lattice of the same box it would
/// be at 112.5). Seen along z in perspective, the step's plane and the box's side show
/// widest on the front face (z = 225, nearest to the camera): the pixels left of the plane
/// there are empty and those right of it opaque, ray cast and path traced.
#[test]
fn a_step_sits_at_its_physical_position() {
    let mut r = renderer();
    let v = volume([16, 6, 6], |i, _, _| if i >= 8.0 { 1.0 } else { 0.0 })
        .with_coordinates([
            (0..16).map(|i| (i * i) as f64).collect(),
            (0..6).map(|j| 45.0 * j as f64).collect(),
            (0..6).map(|k| 45.0 * k as f64).collect(),
        ])
        .unwrap();
    r.set_volume(&v).unwrap();
    r.set_transfer_function(&white(
        &[(0.0, 0.0), (0.45, 0.0), (0.55, 1.0), (1.0, 1.0)],
        1.0,
    ))
    .unwrap();
    let view = View::fit(v.bounds(), 128, 128);
    let img = r.render_image(&view, &RenderParams::default()).unwrap();
    save_enlarged(&img, "rectilinear_step");
    let c = view.camera.focal_point;
    let col = |x: f64| to_pixel(&view, DVec3::new(x, c.y, 225.0)).0;
    let row = to_pixel(&view, c).1 as u32;
    let (lo, hi) = (col(55.0), col(58.0));
    let (left, right) = (col(0.0), col(225.0));
    let alphas: Vec<u8> = (0..128).map(|x| alpha(&img, x, row)).collect();
    println!("step between columns {lo:.1} and {hi:.1} (box {left:.1} to {right:.1}; the uniform lattice's step at {:.1})", col(112.5));
    println!("row {row}: {alphas:?}");
    let mut checked = 0;
    for (x, &a) in alphas.iter().enumerate() {
        let x = x as f64 + 0.5;
        if x > left.min(right) + 1.0 && x < lo.min(hi) - 1.0 {
            assert_eq!(a, 0, "column {x}: before the step");
            checked += 1;
        }
        if x > lo.max(hi) + 1.0 && x < left.max(right) - 1.0 {
            assert!(a > 200, "column {x}: past the step, alpha {a}");
            checked += 1;
        }
    }
    assert!(checked > 70, "{checked} columns checked");
    // The path tracer's medium sits there too: no path meets it before the step, every
    // path does past it (the medium is nearly opaque, the coverage per pixel).
    let traced = trace(&mut r, &view, &PathTraceParams::default(), 16);
    let mut checked = 0;
    for x in 0..128usize {
        let cov = traced[row as usize * 128 + x][3];
        let xc = x as f64 + 0.5;
        if xc > left.min(right) + 1.0 && xc < lo.min(hi) - 1.0 {
            assert_eq!(
                cov, 0.0,
                "column {x}: a path met the medium before the step"
            );
            checked += 1;
        }
        if xc > lo.max(hi) + 1.0 && xc < left.max(right) - 1.0 {
            assert!(cov > 0.9, "column {x}: coverage {cov} past the step");
            checked += 1;
        }
    }
    assert!(checked > 70, "{checked} traced columns checked");
}

/// The isosurface of the distance to a point on a grid whose points crowd toward the
/// origin (coordinates 40·(i/15)^1.5, 16 per axis) is the sphere the same field's
/// isosurface on a uniform grid of the same box draws: the same silhouette, shaded alike.
#[test]
fn isosurfaces_sit_at_their_physical_position() {
    let mut r = renderer();
    let c = DVec3::new(21.0, 19.0, 20.0);
    let coords: Vec<f64> = (0..16)
        .map(|i| 40.0 * (i as f64 / 15.0).powf(1.5))
        .collect();
    let at = |i: f64| coords[i as usize];
    let rect = volume([16, 16, 16], |i, j, k| {
        (DVec3::new(at(i), at(j), at(k)) - c).length()
    })
    .with_coordinates([coords.clone(), coords.clone(), coords.clone()])
    .unwrap();
    let uniform = volume([41, 41, 41], |x, y, z| (DVec3::new(x, y, z) - c).length());
    r.set_transfer_function(&white(&[(0.0, 1.0), (40.0, 1.0)], 1.0))
        .unwrap();
    r.set_isosurface(&IsoParams::with_values(vec![IsoValue::new(
        12.0,
        [0.9, 0.8, 0.6],
        1.0,
    )]))
    .unwrap();
    let mut view = View::fit(uniform.bounds(), 96, 96);
    view.camera.azimuth(30.0);
    view.camera.elevation(20.0);
    view.camera.zoom(2.0);
    let p = RenderParams {
        blend: BlendMode::Isosurface,
        shading: shaded().shading,
        ..Default::default()
    };
    r.set_volume(&uniform).unwrap();
    let a = r.render_image(&view, &p).unwrap();
    r.set_volume(&rect).unwrap();
    let b = r.render_image(&view, &p).unwrap();
    save_enlarged(&b, "rectilinear_sphere");
    let (fa, fb) = (footprint(&a), footprint(&b));
    let (mean, max) = image_diff(&a, &b);
    println!("sphere r = 12: footprint {fa} pixels uniform, {fb} rectilinear; mean {mean:.2}, max {max} levels");
    // (trilinear between points up to 4 units apart: the surface bends a little)
    assert!(fa > 2000, "the sphere is drawn ({fa} pixels)");
    assert!(
        (fa as f64 - fb as f64).abs() < 0.04 * fa as f64,
        "{fa} vs {fb}"
    );
    assert!(mean < 3.0, "mean difference {mean}");
}

/// The path tracer traces a rectilinear grid's medium: with coordinates that place the
/// points where they already are, the image converges to the uniform grid's (the sums over
/// the image of each channel and of the coverage within 1.5%; the tracking differs: a
/// rectilinear grid is tracked against its largest majorant, not block by block).
#[test]
fn path_tracing_traces_the_grid() {
    let mut r = renderer();
    let plain = blob_volume(24).with_spacing([0.5, 0.75, 1.0]).unwrap();
    let rect = plain
        .clone()
        .with_coordinates(uniform_coordinates(&plain))
        .unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    let view = View::fit(plain.bounds(), 32, 32);
    let p = PathTraceParams {
        samples_per_frame: 64,
        ..Default::default()
    };
    let mut sums = Vec::new();
    for v in [&plain, &rect] {
        r.set_volume(v).unwrap();
        let img = trace(&mut r, &view, &p, 1024);
        sums.push(channel_sums(&img));
    }
    let rel: Vec<f64> = (0..4).map(|c| sums[1][c] / sums[0][c] - 1.0).collect();
    println!(
        "coverage summed over the image {:.1}; rectilinear / uniform − 1 (r, g, b, coverage): \
         {rel:.4?}",
        sums[0][3]
    );
    assert!(sums[0][3] > 50.0, "the medium is met");
    for d in rel {
        assert!(d.abs() < 0.015, "{d}");
    }
}

/// What needs a uniform grid refuses a rectilinear one, naming the reason: cubic
/// isosurfaces, bricks.
#[test]
fn rectilinear_grids_are_refused_where_unsupported() {
    let mut r = renderer();
    let plain = blob_volume(24);
    let v = plain
        .clone()
        .with_coordinates(std::array::from_fn(|_| {
            (0..24).map(|i| (i as f64).powf(1.5)).collect()
        }))
        .unwrap();
    r.set_transfer_function(&TransferFunction::single(blob_transfer()))
        .unwrap();
    r.set_volume(&v).unwrap();
    r.set_isosurface(&IsoParams::with_values(vec![IsoValue::new(
        0.3,
        [0.9, 0.8, 0.6],
        1.0,
    )]))
    .unwrap();
    let view = View::fit(v.bounds(), 32, 32);
    let p = RenderParams {
        blend: BlendMode::Isosurface,
        interpolation: Interpolation::Cubic,
        ..Default::default()
    };
    assert_error(
        r.render_image(&view, &p),
        "cubic isosurfaces",
        &["rectilinear (per-axis coordinates)"],
    );
    assert_error(
        r.set_volume_with(
            &v,
            UploadOptions {
                max_brick_points: Some(16),
                ..Default::default()
            },
        ),
        "bricked",
        &["rectilinear grid", "is bricked"],
    );
}
