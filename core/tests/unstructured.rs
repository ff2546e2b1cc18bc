//! Unstructured volumes on a real wgpu device against the f64 CPU reference
//! (common/mesh.rs): every generated mesh, every blend mode drawn, point and cell scalars;
//! a ray that leaves the hollow cylinder and enters it again; isosurfaces' G-buffers against
//! the exact crossings; the errors bad meshes get.
//! Images go to `target/test-images/unstructured_*.png` for inspection.

use ferrovol_core::*;

#[path = "common/mod.rs"]
mod common;

use common::gpu::{assert_error, renderer};
use common::images::save_enlarged;
use common::mesh;
use common::metrics::{
    compare_to_reference, footprint, image_diff, pixels_off_by_more, reference_image,
};

/// A colourful transfer function over [lo, hi], opacity rising to `max` per unit.
fn tf(lo: f64, hi: f64, max: f32) -> TransferFunction {
    let m = |f: f64| lo + f * (hi - lo);
    let color = Piecewise::new(vec![
        (m(0.0), [0.1, 0.2, 0.9]),
        (m(0.5), [0.2, 0.9, 0.3]),
        (m(1.0), [1.0, 0.3, 0.1]),
    ])
    .unwrap();
    let opacity = Piecewise::new(vec![
        (m(0.0), [0.0]),
        (m(0.3), [0.2 * max]),
        (m(1.0), [max]),
    ])
    .unwrap();
    TransferFunction::single(ComponentTransfer::new(color, opacity))
}

/// Draws `v` on the GPU and on the CPU; prints and returns (mean error, PSNR, max error).
/// `v` drawn through `tf` on the shared renderer (set here: tests take turns on it).
fn draw(
    v: &UnstructuredVolume,
    tf: &TransferFunction,
    view: &View,
    params: &RenderParams,
) -> Image {
    let mut r = renderer();
    r.set_unstructured(v).unwrap();
    r.set_transfer_function(tf).unwrap();
    r.render_image(view, params).unwrap()
}

fn compare(
    name: &str,
    v: &UnstructuredVolume,
    tf: &TransferFunction,
    view: &View,
    params: &RenderParams,
) -> (f64, f64, f64) {
    let img = draw(v, tf, view, params);
    let reference = mesh::render(v, tf, view, params);
    save_enlarged(&img, &format!("unstructured_{name}"));
    save_enlarged(
        &reference_image(&reference, view.width, view.height),
        &format!("unstructured_{name}_reference"),
    );
    let (mean, psnr, max) = compare_to_reference(&img, &reference);
    let covered = footprint(&img);
    let brightness = brightness(&img);
    println!(
        "{name}: {covered} pixels drawn (mean colour {brightness:.1} of 255), mean error \
         {mean:.4}, PSNR {psnr:.1} dB, max error {max:.0} (of 255)"
    );
    assert!(brightness > 4.0, "{name}: a nearly black image");
    assert!(
        covered > (view.width * view.height / 8) as usize,
        "{name}: nearly nothing drawn"
    );
    (mean, psnr, max)
}

fn params(blend: BlendMode) -> RenderParams {
    RenderParams {
        blend,
        ..Default::default()
    }
}

/// The scalar range of a one-component mesh.
fn range(v: &UnstructuredVolume) -> (f64, f64) {
    (0..v.scalars.len())
        .map(|i| v.scalars.get(i))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        })
}

/// A view of `v` from an angle, `size` pixels square. The clipping range is left as it was
/// before turning, so that the near plane cuts through the mesh: rays start inside it.
fn view_of(v: &UnstructuredVolume, size: u32) -> View {
    let mut view = View::fit(v.bounds(), size, size);
    view.camera.azimuth(30.0);
    view.camera.elevation(20.0);
    view
}

/// GPU against CPU: composite within a level or two of 255 (the f32 closed forms against
/// f64 quadrature, the 1024-entry tables against the functions), the projections too.
#[track_caller]
fn agrees(name: &str, v: &UnstructuredVolume, blend: BlendMode, max_opacity: f32) {
    let (lo, hi) = range(v);
    let (mean, psnr, max) = compare(
        name,
        v,
        &tf(lo, hi, max_opacity),
        &view_of(v, 64),
        &params(blend),
    );
    assert!(mean < 0.5 && psnr > 45.0 && max <= 3.0, "{name}");
}

#[test]
fn house_composite_matches_the_reference() {
    // (opacity past 1 is clamped: the reference splits its pieces there too)
    agrees("house", &synth::house(), BlendMode::Composite, 1.5);
}

#[test]
fn tetrahedral_wavelet_matches_the_reference_in_every_blend_mode() {
    let v = synth::tet_wavelet(12);
    for (blend, name) in [
        (BlendMode::Composite, "wavelet_composite"),
        (BlendMode::Maximum, "wavelet_mip"),
        (BlendMode::Minimum, "wavelet_minip"),
        (BlendMode::Average, "wavelet_average"),
        (BlendMode::Additive, "wavelet_additive"),
    ] {
        agrees(name, &v, blend, 0.3);
    }
}

#[test]
fn mixed_distorted_cells_match_the_reference_with_point_and_cell_scalars() {
    let points = synth::mixed_cells(4, ScalarLocation::Points);
    agrees("mixed_points_composite", &points, BlendMode::Composite, 0.8);
    agrees("mixed_points_mip", &points, BlendMode::Maximum, 0.8);
    let cells = synth::mixed_cells(4, ScalarLocation::Cells);
    agrees("mixed_cells_composite", &cells, BlendMode::Composite, 0.8);
    agrees("mixed_cells_minip", &cells, BlendMode::Minimum, 0.8);
    agrees("mixed_cells_additive", &cells, BlendMode::Additive, 0.8);
}

/// Gradient opacity on composite, point and cell scalars, against the reference (each
/// segment's opacity scaled by the function at its middle's gradient magnitude); and it
/// shows: the image differs from the one without it by more than the comparison's error.
#[test]
fn gradient_opacity_matches_the_reference_with_point_and_cell_scalars() {
    for (name, v, max_opacity) in [
        ("wavelet_gradient_opacity", synth::tet_wavelet(12), 0.3),
        (
            "mixed_cells_gradient_opacity",
            synth::mixed_cells(4, ScalarLocation::Cells),
            0.8,
        ),
    ] {
        let (lo, hi) = range(&v);
        let plain = tf(lo, hi, max_opacity);
        // the gradient magnitudes the mesh has (scalar units per world unit), from the
        // reference's points: the function rises over the lower half of them
        let steepest = mesh::Tets::of(&v)
            .point_gradients
            .iter()
            .map(|g| g.length())
            .fold(0.0, f64::max);
        let mut graded = plain.clone();
        graded.components[0].gradient_opacity =
            Some(Piecewise::new(vec![(0.0, [0.1]), (0.5 * steepest, [1.0])]).unwrap());
        let view = view_of(&v, 64);
        let p = params(BlendMode::Composite);
        let (mean, psnr, max) = compare(name, &v, &graded, &view, &p);
        assert!(mean < 0.5 && psnr > 45.0 && max <= 3.0, "{name}");
        let without = draw(&v, &plain, &view, &p);
        let with = draw(&v, &graded, &view, &p);
        let changed = pixels_off_by_more(&with, &mesh::render(&v, &plain, &view, &p), 3.0);
        println!("{name}: {changed} pixels differ from the image without it by over 3 levels");
        assert!(
            changed > footprint(&without) / 4,
            "{name}: gradient opacity changes {changed} pixels"
        );
    }
}

/// Shaded composite (VTK's default material, the headlight) against the reference, which
/// lights a segment by the gradient interpolated from the points' (at its middle as the
/// shader does, and at every point); and the shading shows:
/// the image differs from the unshaded one by more than the comparison's error.
#[test]
fn shaded_composite_matches_the_reference_with_point_and_cell_scalars() {
    let shaded = RenderParams {
        shading: Shading {
            enabled: true,
            ..Default::default()
        },
        ..params(BlendMode::Composite)
    };
    for (name, v, max_opacity) in [
        ("wavelet_shaded", synth::tet_wavelet(12), 0.3),
        (
            "mixed_points_shaded",
            synth::mixed_cells(4, ScalarLocation::Points),
            0.8,
        ),
        (
            "mixed_cells_shaded",
            synth::mixed_cells(4, ScalarLocation::Cells),
            0.8,
        ),
    ] {
        let (lo, hi) = range(&v);
        let t = tf(lo, hi, max_opacity);
        let view = view_of(&v, 64);
        // Against the reference lit as the shader lights (each segment as at its middle),
        // within the unshaded comparisons' few levels; against lighting at every point (the
        // exact model), the figures of the approximation.
        let lit = draw(&v, &t, &view, &shaded);
        let middle = mesh::render_lit(&v, &t, &view, &shaded, mesh::LightAt::Middle);
        let (mean, psnr, max) = compare_to_reference(&lit, &middle);
        println!(
            "{name}: against the reference lit at each segment's middle: mean error \
                  {mean:.4}, PSNR {psnr:.1} dB, max error {max:.1}"
        );
        assert!(mean < 0.5 && psnr > 45.0 && max <= 3.0, "{name}");
        let (exact_mean, exact_psnr, _) = compare(name, &v, &t, &view, &shaded);
        let off = pixels_off_by_more(&lit, &mesh::render(&v, &t, &view, &shaded), 3.0);
        println!(
            "{name}: against lighting at every point, {off} of {} drawn pixels off by \
                  more than 3 levels",
            footprint(&lit)
        );
        assert!(exact_mean < 1.0 && exact_psnr > 45.0, "{name}");
        let flat = draw(&v, &t, &view, &params(BlendMode::Composite));
        let (diff, most) = image_diff(&lit, &flat);
        println!("{name}: mean difference from the unshaded image {diff:.2} levels, most {most}");
        assert!(
            diff > 5.0 * exact_mean && most > 20,
            "{name}: shading shows"
        );
    }
}

#[test]
fn rays_leave_the_hollow_cylinder_and_enter_it_again() {
    let v = synth::hollow_cylinder(2, 24, 4);
    // looking along x through the hole, the axis vertical: the centre ray crosses the
    // wall, the hole, the wall
    let mut view = View::fit(v.bounds(), 64, 64);
    view.camera.position = glam::DVec3::new(8.0, 0.0, 0.0);
    view.camera.focal_point = glam::DVec3::ZERO;
    view.camera.view_up = glam::DVec3::Z;
    view.camera.reset_clipping_range(v.bounds());
    let (lo, hi) = range(&v);
    let t = tf(lo, hi, 0.6);
    let segs = mesh::Tets::of(&v).segments(&view);
    let centre = &segs[(32 * 64 + 32) as usize];
    let gap = centre
        .windows(2)
        .map(|w| w[1].t0 - w[0].t1)
        .fold(0.0, f64::max);
    println!("centre ray: {} segments, widest gap {gap:.3}", centre.len());
    assert!(gap > 1.5, "the centre ray crosses the hole (2 wide)");
    let (mean, psnr, max) = compare("cylinder", &v, &t, &view, &params(BlendMode::Composite));
    assert!(mean < 0.5 && psnr > 45.0 && max <= 3.0);
    // the far wall shows through the hole: the centre is more opaque than one wall alone
    let img = draw(&v, &t, &view, &params(BlendMode::Composite));
    let near_wall_only = mesh::integrate(
        &centre
            .iter()
            .copied()
            .filter(|s| s.t1 < centre[0].t1 + 1.0)
            .collect::<Vec<_>>(),
        &mesh::Table::of(&t),
        BlendMode::Composite,
        1.0,
    );
    let a = img.rgba[4 * (32 * 64 + 32) + 3] as f64 / 255.0;
    println!(
        "centre alpha {a:.3}, the near wall's alone {:.3}",
        near_wall_only[3]
    );
    assert!(a > near_wall_only[3] + 0.05);
}

#[test]
fn bad_meshes_get_errors_naming_the_cell() {
    let mut r = renderer();
    let mut flat = synth::house();
    flat.points[8] = [0.5, 0.5, 1.0];
    assert_error(
        r.set_unstructured(&flat),
        "a flat pyramid",
        &["cell 1", "no volume"],
    );
    let three = UnstructuredVolume {
        points: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [0.3, 0.3, 1.0],
        ],
        connectivity: vec![0, 1, 2, 3, 0, 1, 2, 4, 0, 1, 2, 5],
        offsets: vec![0, 4, 8, 12],
        cell_types: vec![10; 3],
        location: ScalarLocation::Points,
        components: 1,
        scalars: Scalars::F32(vec![0.0; 6]),
    };
    assert_error(
        r.set_unstructured(&three),
        "a face of three cells",
        &["more than two", "not manifold"],
    );
}

#[test]
fn what_is_not_drawn_is_refused_and_images_come_back() {
    let mut r = renderer();
    let v = synth::house();
    r.set_unstructured(&v).unwrap();
    r.set_transfer_function(&tf(0.0, 2.0, 1.0)).unwrap();
    let view = view_of(&v, 32);
    let p = RenderParams {
        slice_plane: Some(ClipPlane {
            origin: glam::DVec3::ZERO,
            normal: glam::DVec3::Z,
        }),
        ..params(BlendMode::Slice)
    };
    assert_error(r.render_image(&view, &p), "a sliced mesh", &["not Slice"]);
    // isosurfaces are shaded as layers: no scattering between them
    let mut iso = IsoParams::with_values(vec![IsoValue::new(1.0, [1.0; 3], 1.0)]);
    iso.scattering = Some(IsoScattering::default());
    r.set_isosurface(&iso).unwrap();
    assert_error(
        r.render_image(&view, &params(BlendMode::Isosurface)),
        "scattering between a mesh's isosurfaces",
        &["without scattering between isosurfaces"],
    );
    // path tracing scatters a mesh by Henyey–Greenstein alone
    r.set_path_tracing(&PathTraceParams {
        gradient_threshold: 0.5,
        ..Default::default()
    })
    .unwrap();
    assert_error(
        r.render_image(&view, &params(BlendMode::PathTrace)),
        "a hybrid path-traced mesh",
        &["surface scattering", "Henyey–Greenstein"],
    );
    r.set_path_tracing(&PathTraceParams::default()).unwrap();
    let mut cropped = params(BlendMode::Composite);
    cropped.cropping = Some(Cropping {
        planes: [-1.0, 1.0, -1.0, 1.0, -1.0, 1.0],
        regions: Cropping::SUBVOLUME,
    });
    assert_error(
        r.render_image(&view, &cropped),
        "cropping",
        &["without cropping"],
    );
    let several = UnstructuredVolume {
        components: 2,
        scalars: Scalars::F32(vec![0.0; 18]),
        ..v.clone()
    };
    r.set_unstructured(&several).unwrap();
    assert_error(
        r.render_image(&view, &params(BlendMode::Composite)),
        "2 components",
        &["one scalar component"],
    );
    // back to an image volume
    let img_vol = synth::marschner_lobb(16);
    r.set_volume(&img_vol).unwrap();
    r.set_transfer_function(&TransferFunction::ramp([0.0, 1.0], 0.5))
        .unwrap();
    let img = r
        .render_image(
            &View::fit(img_vol.bounds(), 32, 32),
            &RenderParams::default(),
        )
        .unwrap();
    assert!(footprint(&img) > 100);
}

#[test]
fn opaque_depth_and_clipping_planes_end_rays() {
    let mut r = renderer();
    let v = synth::tet_wavelet(8);
    let (lo, hi) = range(&v);
    r.set_unstructured(&v).unwrap();
    r.set_transfer_function(&tf(lo, hi, 0.5)).unwrap();
    let view = view_of(&v, 32);
    let p = params(BlendMode::Composite);
    let full = r.render_image(&view, &p).unwrap();
    let alpha = |img: &Image| img.rgba.chunks(4).map(|c| c[3] as u64).sum::<u64>();
    // opaque geometry at the near plane hides everything
    r.render(&view, &p, Some(&vec![0.0; 32 * 32])).unwrap();
    assert_eq!(alpha(&r.read_image().unwrap()), 0);
    // geometry at the depth of the mesh's centre cuts rays in the middle
    let b = v.bounds();
    let centre = glam::DVec3::new(b[0] + b[1], b[2] + b[3], b[4] + b[5]) * 0.5;
    let c = view.camera.view_projection(view.aspect()) * centre.extend(1.0);
    let mid = (0.5 * c.z / c.w + 0.5) as f32;
    r.render(&view, &p, Some(&vec![mid; 32 * 32])).unwrap();
    let cut = r.read_image().unwrap();
    let (a_full, a_cut) = (alpha(&full), alpha(&cut));
    println!("alpha sums: full {a_full}, cut at the centre's depth {a_cut}");
    assert!(a_cut > a_full / 10 && a_cut < a_full * 9 / 10);
    // a clipping plane through the centre keeps about half
    let clipped = RenderParams {
        clip_planes: vec![ClipPlane {
            origin: glam::DVec3::ZERO,
            normal: glam::DVec3::X,
        }],
        ..p
    };
    let half = r.render_image(&view, &clipped).unwrap();
    let (f, h) = (footprint(&full), footprint(&half));
    println!("pixels drawn: full {f}, clipped {h}");
    assert!(h < f * 3 / 4 && h > f / 4);
}

#[test]
fn a_transfer_function_of_many_points_splits_segments_at_every_table_entry() {
    // more points than the knots the pass holds (64): the pieces end at every entry
    let v = synth::tet_wavelet(8);
    let (lo, hi) = range(&v);
    let n = 100;
    let at = |i: usize| lo + (hi - lo) * i as f64 / (n - 1) as f64;
    let opacity = Piecewise::new(
        (0..n)
            .map(|i| (at(i), [if i % 2 == 0 { 0.1 } else { 0.6 }]))
            .collect(),
    )
    .unwrap();
    let color = Piecewise::new(vec![(lo, [0.2, 0.4, 1.0]), (hi, [1.0, 0.6, 0.2])]).unwrap();
    let t = TransferFunction::single(ComponentTransfer::new(color, opacity));
    let (mean, psnr, max) = compare(
        "many_points",
        &v,
        &t,
        &view_of(&v, 48),
        &params(BlendMode::Composite),
    );
    assert!(mean < 0.5 && psnr > 45.0 && max <= 3.0);
}

#[test]
fn a_non_conforming_face_is_crossed_without_a_gap() {
    // the house's cube on two tetrahedra that split its bottom quad along the other
    // diagonal (1–3, where the cube splits it along 0–2): the triangles do not match, so
    // both sides are boundary, and rays leave the cube and enter the tetrahedra there
    let mut points = synth::HOUSE_POINTS[..8].to_vec();
    points.push([0.5, 0.5, -1.0]);
    let v = UnstructuredVolume {
        points,
        connectivity: vec![0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 3, 8, 1, 2, 3, 8],
        offsets: vec![0, 8, 12, 16],
        cell_types: vec![12, 10, 10],
        location: ScalarLocation::Points,
        components: 1,
        scalars: Scalars::F32(vec![0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 2.0]),
    };
    let mut view = View::fit(v.bounds(), 48, 48);
    view.camera.elevation(70.0);
    view.camera.reset_clipping_range(v.bounds());
    let (mean, psnr, max) = compare(
        "non_conforming",
        &v,
        &tf(0.0, 2.0, 1.0),
        &view,
        &params(BlendMode::Composite),
    );
    assert!(mean < 0.5 && psnr > 45.0 && max <= 3.0);
}

#[test]
fn composite_depth_is_where_the_ray_first_gathers_opacity() {
    // the depth threshold 0: where the opacity first exceeds 0, the entry into the mesh
    // wherever the entry's scalar has opacity
    let v = synth::tet_wavelet(8);
    let (lo, hi) = range(&v);
    let t = tf(lo, hi, 0.5);
    let mut view = view_of(&v, 32);
    view.camera.reset_clipping_range(v.bounds());
    let img = draw(&v, &t, &view, &params(BlendMode::Composite));
    let segs = mesh::Tets::of(&v).segments(&view);
    let table = mesh::Table::of(&t);
    let vp = view.camera.view_projection(view.aspect());
    let (mut checked, mut worst) = (0, 0.0f64);
    for (i, s) in segs.iter().enumerate() {
        let Some(first) = s.first() else {
            assert_eq!(img.depth[i], 1.0, "pixel {i}: no mesh, far depth");
            continue;
        };
        if table.at(first.s0)[3] < 0.01 {
            continue;
        }
        let ray = common::raycast::pixel_ray(&view, i as u32 % 32, i as u32 / 32);
        let c = vp * (ray.origin + first.t0 * ray.dir).extend(1.0);
        let expected = 0.5 * c.z / c.w + 0.5;
        worst = worst.max((img.depth[i] as f64 - expected).abs());
        checked += 1;
    }
    println!("{checked} pixels: depth off by {worst:.2e} at most");
    assert!(checked > 300 && worst < 1e-4);
}

/// The first hit of two isosurfaces (one translucent) against the exact crossings of the
/// f64 reference, pixel by pixel and layer by layer: on the tetrahedral wavelet, the hollow
/// cylinder (rays leave and enter it again) and mixed cells with cell scalars (surfaces on
/// the faces between cells). A pixel may differ in its layers where a ray grazes an edge.
#[test]
fn isosurfaces_are_the_exact_crossings_with_point_and_cell_scalars() {
    let meshes = [
        ("wavelet", synth::tet_wavelet(8)),
        ("cylinder", synth::hollow_cylinder(2, 24, 4)),
        ("cells", synth::mixed_cells(4, ScalarLocation::Cells)),
    ];
    for (name, v) in meshes {
        let (lo, hi) = range(&v);
        let values = [(lo + 0.35 * (hi - lo), 0.5), (lo + 0.7 * (hi - lo), 1.0)];
        let iso = IsoParams::with_values(vec![
            IsoValue::new(values[0].0, [0.9, 0.6, 0.2], values[0].1 as f32),
            IsoValue::new(values[1].0, [0.2, 0.5, 0.9], values[1].1 as f32),
        ]);
        let view = view_of(&v, 64);
        let p = params(BlendMode::Isosurface);
        let mut r = renderer();
        r.set_unstructured(&v).unwrap();
        r.set_isosurface(&iso).unwrap();
        let img = r.render_image(&view, &p).unwrap();
        save_enlarged(&img, &format!("unstructured_iso_{name}"));
        let gb = r.read_gbuffer().unwrap();
        let segs = mesh::Tets::of(&v).segments(&view);
        let b = v.bounds();
        let diagonal =
            ((b[1] - b[0]).powi(2) + (b[3] - b[2]).powi(2) + (b[5] - b[4]).powi(2)).sqrt();
        let (mut differ, mut hits, mut worst_t, mut worst_n) = (0, 0, 0.0f64, 1.0f64);
        for y in 0..view.height {
            for x in 0..view.width {
                let want = mesh::crossings(
                    &segs[(y * view.width + x) as usize],
                    &values,
                    iso.max_layers as usize,
                    p.termination_threshold as f64,
                );
                let got = gb.hits(x, y);
                if got.len() != want.len()
                    || got.iter().zip(&want).any(|(g, w)| g.iso_index != w.which)
                {
                    differ += 1;
                    continue;
                }
                for (g, w) in got.iter().zip(&want) {
                    hits += 1;
                    worst_t = worst_t.max((g.distance - w.t).abs() / diagonal);
                    let n = if w.below { -w.gradient } else { w.gradient };
                    if n.length() > 0.0 {
                        worst_n = worst_n.min(g.normal.dot(n.normalize()));
                    }
                }
            }
        }
        let covered = footprint(&img);
        println!(
            "iso {name}: {hits} hits in {covered} pixels; {differ} pixels' layers differ; \
             distance off by at most {worst_t:.2e} of the diagonal; normals within \
             {:.3} degrees",
            worst_n.clamp(-1.0, 1.0).acos().to_degrees()
        );
        assert!(
            covered > (view.width * view.height / 16) as usize,
            "{name}: nearly nothing drawn"
        );
        assert!(
            hits > covered,
            "{name}: the translucent surface shows another behind it"
        );
        assert!(differ * 100 <= covered, "{name}: {differ} pixels differ");
        assert!(worst_t < 1e-4 && worst_n > 0.9995, "{name}");
    }
}

/// Ambient occlusion of a mesh's isosurfaces walks the mesh, against the accessibility of
/// a slab: s = |x| on a box, the surfaces x = ±2 seen along +x. The first (from outside,
/// its hemisphere toward rising s) is open; the second, from inside the slab, faces the
/// first 4 units away, so a direction at θ from its normal reaches it within the radius R
/// where 4 / cos θ ≤ R: open with probability 4 / R over the hemisphere (0.5 for R = 8).
/// The centre pixels' rays lie in the planes of the grid's faces, the centre one along an
/// edge: the walk crosses them too.
#[test]
fn isosurface_ambient_occlusion_walks_the_mesh() {
    let mut v = synth::tet_wavelet(17);
    v.scalars = Scalars::F32(v.points.iter().map(|p| p[0].abs() as f32).collect());
    let mut iso = IsoParams::with_values(vec![IsoValue::new(2.0, [0.8; 3], 0.5)]);
    iso.ambient_occlusion = Some(AmbientOcclusion {
        samples: 16,
        steps: 8,
        radius: Some(8.0),
    });
    let mut view = View::fit(v.bounds(), 33, 33);
    view.camera.position = glam::DVec3::new(-60.0, 0.0, 0.0);
    view.camera.focal_point = glam::DVec3::ZERO;
    view.camera.view_up = glam::DVec3::Z;
    view.camera.view_angle = 10.0;
    view.camera.reset_clipping_range(v.bounds());
    let mut r = renderer();
    r.set_unstructured(&v).unwrap();
    r.set_isosurface(&iso).unwrap();
    let img = r
        .render_image(&view, &params(BlendMode::Isosurface))
        .unwrap();
    save_enlarged(&img, "unstructured_iso_ao");
    let gb = r.read_gbuffer().unwrap();
    let mut seen = [Vec::new(), Vec::new()];
    for y in 14..19 {
        for x in 14..19 {
            let hits = gb.hits(x, y);
            assert_eq!(hits.len(), 2, "pixel ({x}, {y}) crosses both walls");
            for (l, h) in hits.iter().enumerate() {
                seen[l].push(h.ambient_access);
            }
        }
    }
    println!(
        "iso AO of the slab's walls, centre pixels: outer {:?}, inner {:?}",
        seen[0], seen[1]
    );
    assert!(seen[0].iter().all(|&a| a == 1.0));
    assert!(seen[1]
        .iter()
        .all(|&a| (a - 0.5).abs() <= 1.0 / 16.0 + 1e-6));
}

/// A device whose one storage binding holds fewer tetrahedra than the mesh has gets them
/// over two bindings (lavapipe binds 128 MiB: 8.4 million tetrahedra): the same image (ray
/// cast and isosurfaces; the walk in lib/mesh.wgsl, which reads them, is every mesh pass's),
/// and a mesh past two bindings refused with its sizes.
#[test]
fn tetrahedra_split_over_two_bindings_draw_the_same_image() {
    let v = synth::tet_wavelet(8);
    let (lo, hi) = range(&v);
    let t = tf(lo, hi, 0.6);
    let view = view_of(&v, 32);
    let iso = IsoParams::with_values(vec![IsoValue::new(lo + 0.5 * (hi - lo), [0.9; 3], 1.0)]);
    let draw_all = |r: &mut Renderer| -> Vec<Image> {
        r.set_unstructured(&v).unwrap();
        r.set_transfer_function(&t).unwrap();
        r.set_isosurface(&iso).unwrap();
        [BlendMode::Composite, BlendMode::Isosurface]
            .iter()
            .map(|&b| r.render_image(&view, &params(b)).unwrap())
            .collect()
    };
    let whole = draw_all(&mut renderer());
    let ctx = common::gpu::context();
    // 2058 tetrahedra: 1100 in the first binding, 958 in the second
    ctx.limit_binding_size(Some(1100 * 16));
    let mut split = Renderer::new(ctx.clone()).unwrap();
    for (a, b) in whole.iter().zip(draw_all(&mut split)) {
        assert!(footprint(a) > 100);
        assert_eq!(a.rgba, b.rgba);
    }
    ctx.limit_binding_size(Some(512 * 16));
    assert_error(
        split.set_unstructured(&v),
        "a mesh past two bindings",
        &["tetrahedra take", "two storage buffers of 8192 bytes"],
    );
}

/// Volumetric shadows of a mesh (shaded composite, VTK's VolumetricScatteringBlending)
/// against the f64 reference under the headlight (its shadow rays run back along the
/// pixel's own ray: the reference integrates them over the pixel's segments), at two
/// blendings and reaches, point and cell scalars; the shadows show (the image differs from
/// the one lit by gradients alone), and a light from the side draws too.
#[test]
fn volumetric_shadows_match_the_reference_under_the_headlight() {
    for (name, v) in [
        ("volumetric_points", synth::tet_wavelet(10)),
        (
            "volumetric_cells",
            synth::mixed_cells(4, ScalarLocation::Cells),
        ),
    ] {
        let (lo, hi) = range(&v);
        let t = tf(lo, hi, 0.5);
        let mut view = View::fit(v.bounds(), 48, 48);
        view.camera.azimuth(30.0);
        view.camera.elevation(20.0);
        // (the near plane in front of the mesh: the shadow rays reach back to its face)
        view.camera.reset_clipping_range(v.bounds());
        let shaded = |blending: f32, reach: f32| RenderParams {
            shading: Shading {
                enabled: true,
                volumetric_blending: blending,
                global_illumination_reach: reach,
                scattering_anisotropy: -0.3,
                ..Default::default()
            },
            ..params(BlendMode::Composite)
        };
        let plain = draw(&v, &t, &view, &shaded(0.0, 0.0));
        for (blending, reach) in [(0.6, 0.2), (1.5, 0.6)] {
            let p = shaded(blending, reach);
            let img = draw(&v, &t, &view, &p);
            let reference = mesh::render_lit(&v, &t, &view, &p, mesh::LightAt::Middle);
            let tag = format!("{name}_{blending}_{reach}");
            save_enlarged(&img, &format!("unstructured_{tag}"));
            let (mean, psnr, max) = compare_to_reference(&img, &reference);
            let (diff, most) = image_diff(&img, &plain);
            println!(
                "{tag}: against the reference mean error {mean:.4}, PSNR {psnr:.1} dB, max \
                 {max:.1}; against gradient lighting alone {diff:.2} levels, most {most}"
            );
            assert!(mean < 0.5 && psnr > 45.0 && max <= 3.0, "{tag}");
            assert!(diff > 2.0 && most > 20, "{tag}: the shadows show");
            assert!(brightness(&img) > 4.0, "{tag}: a nearly black image");
        }
        // a light from the side: its shadow rays cross the mesh, and the side away from
        // it darkens
        let mut side = view.clone();
        let b = v.bounds();
        let c = glam::DVec3::new(b[0] + b[1], b[2] + b[3], b[4] + b[5]) * 0.5;
        side.lights = vec![Light::directional(c + glam::DVec3::X, c, 1.0)];
        let lit = draw(&v, &t, &side, &shaded(0.0, 0.0));
        let shadowed = draw(&v, &t, &side, &shaded(1.0, 1.0));
        save_enlarged(&shadowed, &format!("unstructured_{name}_side"));
        let (diff, most) = image_diff(&shadowed, &lit);
        println!("{name} lit from the side: {diff:.2} levels from gradient lighting, most {most}");
        assert!(
            brightness(&shadowed) > 4.0 && diff > 2.0,
            "{name}: side light"
        );
    }
}

/// The mean colour (0–255) of the drawn pixels.
fn brightness(img: &Image) -> f64 {
    let lit: Vec<&[u8]> = img.rgba.chunks(4).filter(|p| p[3] > 0).collect();
    lit.iter()
        .map(|p| p[0] as f64 + p[1] as f64 + p[2] as f64)
        .sum::<f64>()
        / (3 * lit.len().max(1)) as f64
}
/// A light other than the headlight walks the mesh from every segment's middle: with a
/// transfer function of many points (pieces end at every table entry) those walks stay
/// within lavapipe's loop budget and exact (segment_depth reads the opacity's running
/// integral, a few reads per tetrahedron), as the headlight's shadows from the ray's own
/// depth are. A positional light at the eye lights as the headlight does.
#[test]
fn shadow_walks_stay_exact_with_a_transfer_function_of_many_points() {
    let v = synth::tet_wavelet(17);
    let (lo, hi) = range(&v);
    let color = Piecewise::new(
        (0..200)
            .map(|i| {
                let f = i as f64 / 199.0;
                let odd = (i % 2) as f32;
                (
                    lo + f * (hi - lo),
                    [0.2 + 0.6 * f as f32, 0.8 - 0.5 * f as f32, 0.5 + 0.3 * odd],
                )
            })
            .collect(),
    )
    .unwrap();
    let opacity = Piecewise::new(vec![(lo, [0.0]), (hi, [0.3])]).unwrap();
    let t = TransferFunction::single(ComponentTransfer::new(color, opacity));
    let mut view = View::fit(v.bounds(), 40, 40);
    view.camera.azimuth(35.0);
    view.camera.elevation(25.0);
    view.camera.reset_clipping_range(v.bounds());
    let p = RenderParams {
        shading: Shading {
            enabled: true,
            volumetric_blending: 2.0,
            global_illumination_reach: 0.5,
            scattering_anisotropy: -0.3,
            ..Default::default()
        },
        ..params(BlendMode::Composite)
    };
    let reference = mesh::render_lit(&v, &t, &view, &p, mesh::LightAt::Middle);
    let mut at_eye = view.clone();
    let mut l = Light::positional(view.camera.position, view.camera.focal_point, 1.0);
    l.ambient = [0.0; 3];
    at_eye.lights = vec![l];
    for (name, lights) in [
        ("headlight", &view),
        ("positional light at the eye", &at_eye),
    ] {
        let img = draw(&v, &t, lights, &p);
        let (mean, psnr, max) = compare_to_reference(&img, &reference);
        println!("many points, {name}: mean error {mean:.4}, PSNR {psnr:.1} dB, max {max:.1}");
        assert!(brightness(&img) > 4.0, "{name}: a nearly black image");
        assert!(mean < 0.5 && psnr > 45.0 && max <= 3.0, "{name}");
    }
}
