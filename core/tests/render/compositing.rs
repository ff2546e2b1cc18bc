//! The composite integral (Beer–Lambert through a slab, sample-distance invariance, early
//! termination), MIP and MinIP, a camera inside the volume, the other blend modes with
//! cropping and clipping, pieces compositing to the whole, and the slice blend mode.

use crate::common::gpu::renderer;
use crate::common::images::save_enlarged;
use crate::common::metrics::{alpha, footprint, image_diff, rgba};
use crate::common::raycast::to_pixel;
use crate::common::scenes::{
    blob_transfer, blob_volume, component_transfer, shaded, slab, volume, white, with_clip_plane,
};
use crate::{box_corners, mask_extents, projected_extents};
use ferrovol_core::*;
use glam::DVec3;

// ---------------------------------------------------------------------------------------
// Beer–Lambert through a homogeneous slab
// ---------------------------------------------------------------------------------------

#[test]
fn slab_opacity_matches_beer_lambert() {
    let mut r = renderer();
    // A slab L = 32 thick (points sit at index · spacing); expected opacity 0.75 =
    // 1 − (1 − α)^(L/u) with u = 8: α = 1 − 0.25^(1/4) ≈ 0.293.
    let (view, a, u) = slab(&mut r);
    let l = 32.0;
    let sigma = -(1.0 - a).ln() / u;
    let expected = 1.0 - (-sigma * l).exp();
    // dt = 1 (the default, the spacing) and 0.5 divide L (32 and 64 samples); 0.3 does not
    // (107 samples, reaching 0.1 past L). The opacity stays far below the early
    // termination threshold, so every sample counts.
    for dt in [None, Some(0.5), Some(0.3)] {
        let params = RenderParams {
            sample_distance: dt,
            ..RenderParams::default()
        };
        let img = r.render_image(&view, &params).unwrap();
        let centre = rgba(&img, 16, 16);
        let got = centre[3] as f64 / 255.0;
        let rel = (got - expected).abs() / expected;
        // white, premultiplied: colour = opacity
        assert!(
            centre[..3].iter().all(|c| c.abs_diff(centre[3]) <= 1),
            "{centre:?}"
        );
        println!(
            "slab: dt {:.2}: opacity {got:.4} expected {expected:.4} (σ {sigma:.4}/unit, L {l}) rel err {rel:.4}",
            r.sample_distance(&params).unwrap()
        );
        if dt.is_none() {
            save_enlarged(&img, "slab");
        }
        // 1%: the u8 output alone is ±0.5/255 = 0.26% of 0.75; what remains is the Riemann
        // sum's end effect (a last sample reaching at most dt·σ·(1 − O)/O ≈ 0.14% for 0.3).
        assert!(
            rel < 0.01,
            "slab opacity {got:.4} vs Beer–Lambert {expected:.4} (dt {dt:?})"
        );
    }
}

// ---------------------------------------------------------------------------------------
// The image does not depend on the sample distance (opacity correction)
// ---------------------------------------------------------------------------------------

#[test]
fn sample_distance_invariance() {
    let mut r = renderer();
    let vol = synth::marschner_lobb(41);
    let mut tf = component_transfer(
        &[
            (0.0, [0.2, 0.4, 1.0]),
            (0.5, [1.0, 1.0, 0.4]),
            (1.0, [1.0, 0.4, 0.3]),
        ],
        &[(0.0, 0.0), (0.3, 0.0), (1.0, 0.6)],
        0.5,
    );
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(tf.clone()))
        .unwrap();
    let mut view = View::fit(vol.bounds(), 64, 64);
    view.camera.azimuth(30.0);
    view.camera.elevation(20.0);
    view.camera.orthogonalize_view_up();
    view.camera.reset_clipping_range(vol.bounds());
    let d = vol.spacing[0];
    let imgs: Vec<Image> = [d, d / 2.0, d / 4.0]
        .iter()
        .map(|&s| {
            r.render_image(
                &view,
                &RenderParams {
                    sample_distance: Some(s),
                    ..shaded()
                },
            )
            .unwrap()
        })
        .collect();
    save_enlarged(&imgs[0], "ml_dt1");
    save_enlarged(&imgs[2], "ml_dt4");
    assert!(
        footprint(&imgs[0]) > 1000,
        "the Marschner–Lobb image is almost empty"
    );
    let mut means = Vec::new();
    for (i, name) in [(0, "d vs d/4"), (1, "d/2 vs d/4")] {
        let (mean, max) = image_diff(&imgs[i], &imgs[2]);
        let mut d: Vec<u8> = imgs[i]
            .rgba
            .iter()
            .zip(&imgs[2].rgba)
            .map(|(a, b)| a.abs_diff(*b))
            .collect();
        d.sort_unstable();
        let p99 = d[d.len() * 99 / 100];
        println!("sample distance invariance: {name}: mean abs diff {mean:.3}/255, 99th percentile {p99}/255, max {max}/255");
        // Opacity correction removes the O(1) dependence on dt (16 levels on average here
        // without it, see below); what remains is the Riemann sum's O(dt) discretisation
        // error. The signal's rings are ~3 samples apart at d, so on average the images
        // agree to under a level and 99% of channels to a few levels; the worst pixel (a
        // ring seen edge-on, where a sample more or less of a thin shell falls inside) may
        // move by up to ~10%.
        assert!(mean < 1.0, "{name}: mean abs diff {mean:.3}");
        assert!(p99 <= 8, "{name}: 99th percentile abs diff {p99}");
        assert!(max <= 24, "{name}: max abs diff {max}");
        means.push(mean);
    }
    // and the difference shrinks as the sampling is refined (first order: d/2 vs d/4 is
    // about a third of d vs d/4)
    assert!(means[1] < 0.6 * means[0], "no convergence: {means:?}");

    // What the tolerance guards against: without opacity correction the samples at d/4
    // would keep the opacity meant for d, as with the unit distance divided by 4.
    tf.unit_distance /= 4.0;
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    let params = RenderParams {
        sample_distance: Some(d / 4.0),
        ..shaded()
    };
    let uncorrected = r.render_image(&view, &params).unwrap();
    let (mean_u, max_u) = image_diff(&imgs[0], &uncorrected);
    println!("sample distance invariance: d vs d/4 without opacity correction would differ by mean {mean_u:.3}/255, max {max_u}/255");
    assert!(
        mean_u > 5.0 * means[0],
        "the test cannot tell corrected from uncorrected"
    );
}

// ---------------------------------------------------------------------------------------
// Early ray termination changes nothing visible
// ---------------------------------------------------------------------------------------

#[test]
fn early_termination_agrees() {
    let mut r = renderer();
    let vol = synth::marschner_lobb(41);
    let tf = component_transfer(
        &[(0.0, [0.2, 0.4, 1.0]), (1.0, [1.0, 0.8, 0.3])],
        &[(0.2, 0.0), (1.0, 1.0)],
        0.1,
    );
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    let view = View::fit(vol.bounds(), 64, 64);
    let on = r.render_image(&view, &shaded()).unwrap();
    let off = r
        .render_image(
            &view,
            &RenderParams {
                termination_threshold: 1.0,
                ..shaded()
            },
        )
        .unwrap();
    save_enlarged(&on, "early_termination");
    let opaque = on.rgba.chunks(4).filter(|p| p[3] >= 254).count();
    let (mean, max) = image_diff(&on, &off);
    println!(
        "early termination: {opaque} pixels terminate; mean abs diff {mean:.4}/255, max {max}/255"
    );
    assert!(
        opaque > 500,
        "the scene must be opaque enough for termination to happen"
    );
    // Rays stop once α ≥ 1 − 1/255, so what they skip adds at most (1 − α)·1 ≤ 1/255 to any
    // channel; the u8 rounding of the two results can add one more level.
    assert!(max <= 2, "max abs diff {max}/255");
}

// ---------------------------------------------------------------------------------------
// MIP / MinIP find a planted extremum where it projects
// ---------------------------------------------------------------------------------------

fn brightest(img: &Image) -> (u32, u32, u8) {
    let mut best = (0, 0, 0u8);
    for y in 0..img.height {
        for x in 0..img.width {
            let p = rgba(img, x, y);
            if p[0] > best.2 {
                best = (x, y, p[0]);
            }
        }
    }
    best
}

fn check_planted(img: &Image, at: (f64, f64), label: &str) {
    let (bx, by, bv) = brightest(img);
    let dist = ((bx as f64 + 0.5 - at.0).powi(2) + (by as f64 + 0.5 - at.1).powi(2)).sqrt();
    // farthest-away bright pixel: nothing but the plant may light up
    let mut stray = 0u8;
    for y in 0..img.height {
        for x in 0..img.width {
            let d = ((x as f64 + 0.5 - at.0).powi(2) + (y as f64 + 0.5 - at.1).powi(2)).sqrt();
            if d > 6.0 {
                stray = stray.max(rgba(img, x, y)[0]);
            }
        }
    }
    println!(
        "{label}: brightest pixel ({bx}, {by}) = {bv}/255, planted voxel projects to ({:.2}, {:.2}), {dist:.2} px away; brightest pixel > 6 px away {stray}/255",
        at.0, at.1
    );
    // The pixel whose centre is nearest the projection passes within half a pixel (~0.45
    // voxel) of the planted voxel, and samples are 0.9 apart: its ray meets a point within
    // about half a voxel of the peak on every axis, where trilinear interpolation gives at
    // least 0.6 + 0.4·0.5³ = 0.65, more than any ray through the 0.6 shell alone can see.
    // The blob is ~3 px wide, so the brightest pixel must be within 1.5 px of the projection.
    assert!(
        dist <= 1.5,
        "{label}: brightest pixel {dist:.2} px from the planted voxel"
    );
    assert!(
        bv as f64 >= 0.65 * 255.0,
        "{label}: planted maximum shows as {bv}/255"
    );
    assert!(
        stray <= 2,
        "{label}: {stray}/255 far from the planted voxel"
    );
}

#[test]
fn mip_finds_planted_maximum() {
    let mut r = renderer();
    let n = 32u32;
    let plant = [20u32, 9, 14];
    // a 3×3×3 blob: 1 at the centre, 0.6 around it, so linear interpolation keeps the peak
    let field = |x: f64, y: f64, z: f64| {
        let d = [
            x - plant[0] as f64,
            y - plant[1] as f64,
            z - plant[2] as f64,
        ];
        if d.iter().all(|c| *c == 0.0) {
            1.0
        } else if d.iter().all(|c| c.abs() <= 1.0) {
            0.6
        } else {
            0.0
        }
    };
    let vol = volume([n; 3], field).with_spacing([1.0, 1.2, 0.9]).unwrap();
    let mut view = View::fit(vol.bounds(), 64, 64);
    view.camera.azimuth(25.0);
    view.camera.elevation(15.0);
    view.camera.orthogonalize_view_up();
    view.camera.reset_clipping_range(vol.bounds());
    let world = vol.index_to_data().transform_point3(DVec3::new(
        plant[0] as f64,
        plant[1] as f64,
        plant[2] as f64,
    ));
    let at = to_pixel(&view, world);

    // white, opacity from `opacity`: a pixel shows the extremum it found as its grey level
    let project = |r: &mut Renderer,
                   vol: &VolumeData,
                   opacity: &[(f64, f32)],
                   blend: BlendMode,
                   name: &str| {
        r.set_volume(vol).unwrap();
        r.set_transfer_function(&white(opacity, 1.0)).unwrap();
        let params = RenderParams {
            blend,
            ..RenderParams::default()
        };
        let img = r.render_image(&view, &params).unwrap();
        save_enlarged(&img, name);
        img
    };
    // opacity = value: the maximum
    let mip = project(
        &mut r,
        &vol,
        &[(0.0, 0.0), (1.0, 1.0)],
        BlendMode::Maximum,
        "mip",
    );
    check_planted(&mip, at, "MIP");

    // MinIP of the inverted volume with an inverted opacity map shows the same picture.
    let inv = volume([n; 3], |x, y, z| 1.0 - field(x, y, z))
        .with_spacing([1.0, 1.2, 0.9])
        .unwrap();
    let img = project(
        &mut r,
        &inv,
        &[(0.0, 1.0), (1.0, 0.0)],
        BlendMode::Minimum,
        "minip",
    );
    check_planted(&img, at, "MinIP");
    // min(1 − v) = 1 − max(v), and the opacity map is mirrored: the same picture
    let (mean, max) = image_diff(&mip, &img);
    println!("MIP vs MinIP of the inverted volume: mean abs diff {mean:.4}/255, max {max}/255");
    assert!(
        max <= 1,
        "MIP and MinIP pictures differ by {max}/255 (1 − v rounds in f32)"
    );
}

// ---------------------------------------------------------------------------------------
// A camera inside the volume
// ---------------------------------------------------------------------------------------

#[test]
fn camera_inside_volume() {
    let mut r = renderer();
    let ball = |c: [f64; 3]| {
        move |x: f64, y: f64, z: f64| {
            let d = ((x - c[0]).powi(2) + (y - c[1]).powi(2) + (z - c[2]).powi(2)).sqrt();
            ((5.0 - d) / 2.0).clamp(0.0, 1.0)
        }
    };
    let tf = component_transfer(
        &[(0.0, [1.0, 0.6, 0.2]), (1.0, [1.0, 0.9, 0.6])],
        &[(0.2, 0.0), (1.0, 1.0)],
        0.5,
    );
    r.set_transfer_function(&TransferFunction::single(tf))
        .unwrap();
    let mut view = View::fit([0.0, 32.0, 0.0, 32.0, 0.0, 32.0], 64, 64);
    // the camera at the centre of the volume, looking down −z with a 60° view angle
    view.camera.position = DVec3::new(16.0, 16.0, 16.0);
    view.camera.focal_point = DVec3::new(16.0, 16.0, 0.0);
    view.camera.view_up = DVec3::Y;
    view.camera.view_angle = 60.0;
    view.camera
        .reset_clipping_range([0.0, 32.0, 0.0, 32.0, 0.0, 32.0]);

    // a ball ahead of the camera (z = 6 < 16)
    let ahead = volume([33; 3], ball([16.0, 16.0, 6.0]));
    r.set_volume(&ahead).unwrap();
    let img = r.render_image(&view, &shaded()).unwrap();
    save_enlarged(&img, "camera_inside_ahead");
    let fp = footprint(&img);
    let centre = rgba(&img, 32, 32);
    let depth = img.depth[(32 * 64 + 32) as usize];
    // The ball's opacity starts where its value passes 0.2, at radius 4.6; seen from 10
    // away it subtends asin(0.46), in a 60° view 64 px high.
    let exp_radius_px = (0.46f64).asin().tan() / 30f64.to_radians().tan() * 32.0;
    let exp_fp = std::f64::consts::PI * exp_radius_px * exp_radius_px;
    println!("camera inside, ball ahead: footprint {fp} px (≈{exp_fp:.0} expected), centre pixel {centre:?}, depth {depth:.4}");
    assert!(
        centre[3] == 255 && centre[0] > 50,
        "the ball ahead must be visible: {centre:?}"
    );
    assert!(
        depth.is_finite() && depth > 0.0 && depth < 1.0,
        "depth {depth}"
    );
    // Footprint within ±10% of the projected ball: the rim's pixels (~180, 7%) may fall
    // either way, and only rays starting at the camera see exactly this disc.
    assert!(
        (fp as f64) > 0.9 * exp_fp && (fp as f64) < 1.1 * exp_fp,
        "footprint {fp}"
    );

    // the same ball behind the camera (z = 26 > 16): nothing to see
    let behind = volume([33; 3], ball([16.0, 16.0, 26.0]));
    r.set_volume(&behind).unwrap();
    let img = r.render_image(&view, &shaded()).unwrap();
    save_enlarged(&img, "camera_inside_behind");
    let max = img.rgba.iter().max().copied().unwrap_or(0);
    println!(
        "camera inside, ball behind: footprint {}, max channel {max}",
        footprint(&img)
    );
    assert_eq!(max, 0, "structure behind the camera was rendered");
    assert!(
        img.depth.iter().all(|&d| d == 1.0),
        "depth must stay at 1 with nothing visible"
    );
}

// ---------------------------------------------------------------------------------------
// Other blend modes, cropping and clipping
// ---------------------------------------------------------------------------------------

#[test]
fn blend_modes_cropping_clipping() {
    let mut r = renderer();
    let vol = blob_volume(24);
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&TransferFunction::ramp([0.0, 1.0], 0.8))
        .unwrap();
    let b = vol.bounds();
    let view = View::fit(b, 64, 64);
    let composite = r.render_image(&view, &RenderParams::default()).unwrap();
    let fp_composite = footprint(&composite);
    save_enlarged(&composite, "blend_composite");

    for mode in [BlendMode::Average, BlendMode::Additive] {
        let img = r
            .render_image(
                &view,
                &RenderParams {
                    blend: mode,
                    ..RenderParams::default()
                },
            )
            .unwrap();
        save_enlarged(&img, &format!("blend_{mode:?}").to_lowercase());
        // Every ray through the volume ends as an opaque grey: black where it met only
        // (nearly) transparent values, as in the blob's far corners.
        let mut grey = 0;
        let mut black = 0;
        let mut not_grey = 0;
        let mut brightest = 0u8;
        for p in img.rgba.chunks(4) {
            if p[3] > 0 {
                if p[0] != p[1] || p[1] != p[2] || p[3] != 255 {
                    not_grey += 1;
                } else if p[0] > 0 {
                    grey += 1;
                } else {
                    black += 1;
                }
                brightest = brightest.max(p[0]);
            }
        }
        let centre = rgba(&img, 32, 32);
        println!("{mode:?}: {grey} non-black grey pixels, {black} black, {not_grey} others, brightest {brightest}/255, centre {centre:?}");
        assert_eq!(
            not_grey, 0,
            "{mode:?}: a pixel with opacity is not an opaque grey"
        );
        // the blob shows over most of the volume's ~1760-pixel projection
        assert!(grey > 1000, "{mode:?}: only {grey} non-black grey pixels");
        assert!(
            centre[3] == 255 && centre[0] > 20,
            "{mode:?}: centre {centre:?}"
        );
        // rays that miss the volume stay empty
        assert_eq!(rgba(&img, 0, 0), [0; 4], "{mode:?}: background");
    }

    // cropping to the middle third keeps the centre and loses the rest
    let third = |a: usize| {
        (
            b[2 * a] + (b[2 * a + 1] - b[2 * a]) / 3.0,
            b[2 * a] + 2.0 * (b[2 * a + 1] - b[2 * a]) / 3.0,
        )
    };
    let (x, y, z) = (third(0), third(1), third(2));
    let crop = Cropping {
        planes: [x.0, x.1, y.0, y.1, z.0, z.1],
        regions: Cropping::SUBVOLUME,
    };
    let cropped = r
        .render_image(
            &view,
            &RenderParams {
                cropping: Some(crop),
                ..RenderParams::default()
            },
        )
        .unwrap();
    save_enlarged(&cropped, "cropped_subvolume");
    let fp_crop = footprint(&cropped);
    // the cropped box seen from the front spans the middle third: ~ (1/3 · 1.1)² of the
    // whole box's projection, far below the blob's footprint
    println!(
        "cropping: footprint {fp_crop} px vs {fp_composite} uncropped; centre alpha {} vs {}",
        alpha(&cropped, 32, 32),
        alpha(&composite, 32, 32)
    );
    assert!(
        fp_crop > 0 && (fp_crop as f64) < 0.5 * fp_composite as f64,
        "cropped footprint {fp_crop}"
    );
    assert!(alpha(&cropped, 32, 32) > 0);
    // The kept region is the box between the planes (data = world here): its projection
    // bounds what is seen. Every ray through it has a sample inside unless its chord is
    // shorter than a step, so the extents agree to a pixel.
    let expect = projected_extents(
        &view,
        box_corners(DVec3::new(x.0, y.0, z.0), DVec3::new(x.1, y.1, z.1)),
    );
    let mask: Vec<bool> = cropped.rgba.chunks(4).map(|p| p[3] > 0).collect();
    let got = mask_extents(&mask, 64, 64).unwrap();
    let worst = (0..4)
        .map(|i| (got[i] - expect[i]).abs())
        .fold(0.0, f64::max);
    println!("cropping: extents {got:?} vs the projected crop box {expect:?}: worst {worst} px");
    assert!(worst <= 1.0, "cropped extents {got:?} vs {expect:?}");

    // a clipping plane through the centre, normal +x, keeps the right half
    let centre = DVec3::new(0.5 * (b[0] + b[1]), 0.0, 0.0);
    let clip = with_clip_plane(RenderParams::default(), centre, DVec3::X);
    let clipped = r.render_image(&view, &clip).unwrap();
    save_enlarged(&clipped, "clipped_half");
    let fp_clip = footprint(&clipped);
    let ratio = fp_clip as f64 / fp_composite as f64;
    let left = (0..64)
        .flat_map(|y| (0..32).map(move |x| (x, y)))
        .filter(|&(x, y)| alpha(&clipped, x, y) > 0)
        .count();
    let right_changed = (0..64)
        .flat_map(|y| (32..64).map(move |x| (x, y)))
        .filter(|&(x, y)| rgba(&clipped, x, y) != rgba(&composite, x, y))
        .count();
    println!("clip plane: footprint {fp_clip} px of {fp_composite} ({ratio:.3}); {left} pixels shown left of the centre, {right_changed} changed right of it");
    // The blob's main lobe sits near the centre but its second lobe is right of it, so the
    // kept half holds a bit more than half; perspective adds a little at the cut.
    assert!(
        (0.4..0.7).contains(&ratio),
        "clipped footprint ratio {ratio:.3}"
    );
    // The camera sits on x = centre, so rays left of the centre never reach x ≥ centre and
    // rays right of it never leave it: the left half is empty, the right half untouched.
    assert_eq!(left, 0, "the clipped half still shows ({left} px)");
    assert_eq!(
        right_changed, 0,
        "the kept half changed ({right_changed} px)"
    );
}

// ---------------------------------------------------------------------------------------
// A volume drawn in pieces (ParaView under MPI) composites to the whole's image
// ---------------------------------------------------------------------------------------

/// "over" for premultiplied RGBA8 pixels: `front` over `back`.
fn over(front: [u8; 4], back: [u8; 4]) -> [u8; 4] {
    let a = front[3] as f64 / 255.0;
    std::array::from_fn(|i| {
        (front[i] as f64 + (1.0 - a) * back[i] as f64)
            .round()
            .min(255.0) as u8
    })
}

/// The blob volume cut at z = 17 into two pieces sharing that plane of points, as
/// ParaView's extent translator cuts an image for two ranks, each drawn alone with the
/// whole volume's box (`RenderParams::whole_box`): composited back to front with "over"
/// (composite, additive, average) or by depth with `extremum_depth` (MIP, MinIP), as IceT
/// composites the ranks, they give the whole volume's image, sample for sample (within a
/// level of rounding), but for additive: there "over" of 8-bit colours that cannot exceed
/// 1 gives 1 − (1 − a)(1 − b) for the pieces' sums a and b where the whole has
/// min(1, a + b).
#[test]
fn pieces_composite_to_the_whole() {
    let mut r = renderer();
    let n = 33u32;
    let cut = 17u32;
    let blob = blob_volume(n);
    let at = |v: &VolumeData, x: f64, y: f64, z: f64| match &v.scalars {
        Scalars::F32(d) => {
            d[x as usize + n as usize * (y as usize + n as usize * z as usize)] as f64
        }
        _ => unreachable!(),
    };
    // MinIP sees the blob as a hole: its minima lie inside the volume, not on its faces
    let hole = volume([n; 3], |x, y, z| 1.0 - at(&blob, x, y, z));
    // the points z0..=z1 of `whole`, in place, with the whole's box in their index space
    let piece = |whole: &VolumeData, z0: u32, z1: u32| {
        let mut v = volume([n, n, z1 - z0 + 1], |x, y, z| {
            at(whole, x, y, z + z0 as f64)
        });
        v.origin = [0.0, 0.0, z0 as f64];
        let m = (n - 1) as f64;
        (v, [[0.0, 0.0, -(z0 as f64)], [m, m, m - z0 as f64]])
    };
    let mut view = View::fit(blob.bounds(), 48, 48);
    // from +z (the near piece holds z >= cut), tilted so that rays cross the cut obliquely
    view.camera.position = view.camera.focal_point + DVec3::new(0.35, 0.25, 1.0) * 90.0;
    view.camera.reset_clipping_range(blob.bounds());
    let tf = TransferFunction::single(blob_transfer());
    r.set_transfer_function(&tf).unwrap();
    for blend in [
        BlendMode::Composite,
        BlendMode::Additive,
        BlendMode::Average,
        BlendMode::Maximum,
        BlendMode::Minimum,
    ] {
        let extremum = matches!(blend, BlendMode::Maximum | BlendMode::Minimum);
        let whole = if blend == BlendMode::Minimum {
            &hole
        } else {
            &blob
        };
        let (near, near_box) = piece(whole, cut, n - 1);
        let (far, far_box) = piece(whole, 0, cut);
        let params = RenderParams {
            blend,
            extremum_depth: extremum,
            ..RenderParams::default()
        };
        r.set_volume(whole).unwrap();
        let reference = r.render_image(&view, &params).unwrap();
        // the whole as a piece of itself: the same image
        let itself = RenderParams {
            whole_box: Some([[0.0; 3], [(n - 1) as f64; 3]]),
            ..params.clone()
        };
        let (_, most) = image_diff(&r.render_image(&view, &itself).unwrap(), &reference);
        assert_eq!(most, 0, "{blend:?}: the whole volume as its own piece");
        let mut frames = Vec::new();
        for (v, b) in [(&near, near_box), (&far, far_box)] {
            r.set_volume(v).unwrap();
            let p = RenderParams {
                whole_box: Some(b),
                ..params.clone()
            };
            frames.push(r.render_image(&view, &p).unwrap());
        }
        let mut worst = 0u8;
        let mut total = 0u64;
        let mut drawn = 0;
        for i in 0..(48 * 48) as usize {
            let px = |img: &Image| -> [u8; 4] { img.rgba[4 * i..4 * i + 4].try_into().unwrap() };
            let got = if extremum {
                // by depth, the smaller wins (IceT's z-buffer compositing)
                if frames[0].depth[i] <= frames[1].depth[i] {
                    px(&frames[0])
                } else {
                    px(&frames[1])
                }
            } else {
                over(px(&frames[0]), px(&frames[1]))
            };
            let want = px(&reference);
            drawn += usize::from(want[3] > 0);
            let d = (0..4).map(|c| got[c].abs_diff(want[c])).max().unwrap();
            worst = worst.max(d);
            total += d as u64;
            if blend == BlendMode::Additive {
                // 1 − (1 − a)(1 − b) in place of min(1, a + b): never more, opaque alike
                assert!(
                    got[0] <= want[0].saturating_add(1) && got[3] == want[3],
                    "{got:?} {want:?}"
                );
            }
        }
        println!(
            "{blend:?}: {drawn} pixels drawn, pieces composited differ by at most {worst} \
             levels, {:.3} on average",
            total as f64 / drawn as f64
        );
        assert!(drawn > 400, "{blend:?}: the whole volume is drawn");
        // additive: the sum's error a·b is at most a quarter (64 levels)
        let bound = if blend == BlendMode::Additive { 64 } else { 2 };
        assert!(worst <= bound, "{blend:?}: {worst} levels");
    }
}

// ---------------------------------------------------------------------------------------
// The slice blend mode: the transfer function where each ray meets the plane
// ---------------------------------------------------------------------------------------

#[test]
fn slice_shows_the_plane_and_nothing_else() {
    let mut r = renderer();
    let n = 24u32;
    // a ramp along x, 0 at x = 0 to 1 at x = n − 1; white, opacity = value
    let vol = volume([n; 3], |x, _, _| x / (n - 1) as f64);
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&white(&[(0.0, 0.0), (1.0, 1.0)], 1.0))
        .unwrap();
    let mut view = View::fit(vol.bounds(), 64, 64);
    view.camera.azimuth(35.0);
    view.camera.elevation(20.0);
    view.camera.orthogonalize_view_up();
    view.camera.reset_clipping_range(vol.bounds());
    let c = 15.0;
    let params = RenderParams {
        blend: BlendMode::Slice,
        slice_plane: Some(ClipPlane {
            origin: DVec3::new(c, 0.0, 0.0),
            normal: DVec3::new(-2.0, 0.0, 0.0),
        }),
        ..RenderParams::default()
    };
    let img = r.render_image(&view, &params).unwrap();
    save_enlarged(&img, "slice");
    let want = (c / (n - 1) as f64 * 255.0) as i32;
    let hi = DVec3::splat((n - 1) as f64);
    let (mut covered, mut mismatched, mut worst) = (0, 0, 0);
    for y in 0..view.height {
        for x in 0..view.width {
            let ray = crate::common::raycast::pixel_ray(&view, x, y);
            let t = (c - ray.origin.x) / ray.dir.x;
            let p = ray.origin + t * ray.dir;
            let inside = t >= 0.0 && p.cmpge(DVec3::ZERO).all() && p.cmple(hi).all();
            let px = rgba(&img, x, y);
            if inside != (px[3] > 0) {
                mismatched += 1;
                continue;
            }
            if inside {
                covered += 1;
                // premultiplied white: grey = alpha = the opacity at x = c, not corrected
                worst = worst
                    .max((px[3] as i32 - want).abs())
                    .max((px[0] as i32 - want).abs());
                let d = img.depth[(y * view.width + x) as usize] as f64;
                let clip = view.camera.view_projection(view.aspect()) * p.extend(1.0);
                let expected = 0.5 * clip.z / clip.w + 0.5;
                assert!(
                    (d - expected).abs() < 1e-4,
                    "pixel ({x}, {y}): depth {d} where the plane's is {expected}"
                );
            }
        }
    }
    println!(
        "slice x = {c}: {covered} pixels on the plane, {mismatched} differ in coverage, \
         colour within {worst}/255 of {want}"
    );
    assert!(covered > 400, "the slice covers only {covered} pixels");
    assert!(
        mismatched <= covered / 50,
        "{mismatched} pixels disagree about whether the ray meets the plane in the box"
    );
    assert!(worst <= 1, "slice colour off by {worst}/255");
    // without a plane the mode is refused
    let err = r
        .render_image(
            &view,
            &RenderParams {
                blend: BlendMode::Slice,
                ..RenderParams::default()
            },
        )
        .unwrap_err()
        .to_string();
    assert!(err.contains("slice plane"), "{err}");
}
