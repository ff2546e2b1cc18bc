//! Silhouettes of an opaque box against the analytic projection (parallel projection,
//! anisotropic spacing, a rotated direction matrix), and rays only over the volume's
//! projected rectangle with the rest of the image cleared.

use crate::common::gpu::{new_renderer, renderer};
use crate::common::images::save_enlarged;
use crate::common::metrics::{compare_to_reference, footprint, frame_diff};
use crate::common::raycast::{self, index_box, pixel_ray, ray_segment};
use crate::common::scenes::{blob_transfer, blob_volume, shaded, volume, white};
use crate::{box_corners, mask_extents, projected_extents};
use ferrovol_core::*;
use glam::DVec3;

// ---------------------------------------------------------------------------------------
// Silhouettes of an opaque box
// ---------------------------------------------------------------------------------------

/// Renders the whole volume as an opaque box and compares its silhouette with the
/// analytic one: per pixel (does the pixel's ray meet the box?) and by pixel extents of the
/// projected corners.
fn check_silhouette(vol: &VolumeData, view: &View, name: &str) {
    let mut r = renderer();
    r.set_volume(vol).unwrap();
    let opaque = [(0.0, 0.0), (0.5, 0.0), (0.51, 1.0), (1.0, 1.0)];
    r.set_transfer_function(&white(&opaque, 1.0)).unwrap();
    let img = r.render_image(view, &RenderParams::default()).unwrap();
    save_enlarged(&img, name);
    let (w, h) = (view.width, view.height);
    // analytic mask: the pixel centre's ray meets the box
    let hit: Vec<bool> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let (_, _, t0, t1) = ray_segment(vol, &pixel_ray(view, x, y));
            t0 < t1
        })
        .collect();
    let gpu: Vec<bool> = img.rgba.chunks(4).map(|p| p[3] > 127).collect();
    let mut mismatches = 0;
    let mut off_edge = 0;
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let i = (y * w as i64 + x) as usize;
            if hit[i] != gpu[i] {
                mismatches += 1;
                let edge = (-1..=1).any(|dy| {
                    (-1..=1).any(|dx| {
                        let (u, v) = (x + dx, y + dy);
                        u >= 0
                            && v >= 0
                            && u < w as i64
                            && v < h as i64
                            && hit[(v * w as i64 + u) as usize] != hit[i]
                    })
                });
                if !edge {
                    off_edge += 1;
                }
            }
        }
    }
    let m = vol.index_to_data();
    let (lo, hi) = index_box(vol);
    let expect = projected_extents(view, box_corners(lo, hi).map(|p| m.transform_point3(p)));
    let got = mask_extents(&gpu, w, h).unwrap_or_else(|| panic!("{name}: empty silhouette"));
    let worst = (0..4)
        .map(|i| (got[i] - expect[i]).abs())
        .fold(0.0, f64::max);
    let area = gpu.iter().filter(|&&b| b).count();
    let area_exp = hit.iter().filter(|&&b| b).count();
    println!(
        "{name}: silhouette columns {}..{} rows {}..{} vs analytic {}..{} / {}..{}: worst {worst} px; {area} px vs {area_exp} analytic, {mismatches} differ ({off_edge} away from the edge)",
        got[0], got[1], got[2], got[3], expect[0], expect[1], expect[2], expect[3]
    );
    // Pixel extents agree to one pixel (a pixel centre lying within float rounding of an
    // edge may go either way); every differing pixel must lie on the silhouette's edge.
    assert!(worst <= 1.0, "{name}: extents off by {worst} px");
    assert_eq!(
        off_edge, 0,
        "{name}: {off_edge} pixels differ away from the silhouette edge"
    );
    assert!(
        mismatches * 50 <= area_exp,
        "{name}: {mismatches} of {area_exp} pixels differ"
    );
}

fn parallel_view(vol: &VolumeData, w: u32, h: u32, azimuth: f64, elevation: f64) -> View {
    let b = vol.bounds();
    let mut view = View::fit(b, w, h);
    view.camera.azimuth(azimuth);
    view.camera.elevation(elevation);
    view.camera.orthogonalize_view_up();
    view.camera.parallel = true;
    view.camera.reset_clipping_range(b);
    view
}

/// Checks the silhouette of `vol` in two parallel views of `w` × `h` pixels, each given as
/// (azimuth, elevation, image name).
fn check_silhouettes(vol: &VolumeData, [w, h]: [u32; 2], views: [(f64, f64, &str); 2]) {
    for (azimuth, elevation, name) in views {
        check_silhouette(vol, &parallel_view(vol, w, h, azimuth, elevation), name);
    }
}

#[test]
fn parallel_projection_silhouette() {
    let vol = volume([17, 9, 13], |_, _, _| 1.0)
        .with_origin([-3.0, 2.0, 1.0])
        .unwrap();
    check_silhouettes(
        &vol,
        [96, 80],
        [
            (35.0, 25.0, "silhouette_parallel"),
            (0.0, 0.0, "silhouette_parallel_front"),
        ],
    );
}

#[test]
fn anisotropic_spacing_silhouette() {
    let vol = volume([16, 8, 6], |_, _, _| 1.0)
        .with_spacing([1.0, 2.0, 3.0])
        .unwrap();
    check_silhouettes(
        &vol,
        [96, 96],
        [
            (30.0, 20.0, "silhouette_anisotropic"),
            (90.0, 0.0, "silhouette_anisotropic_side"),
        ],
    );
}

#[test]
fn rotated_direction_silhouette() {
    let (s, c) = 30f64.to_radians().sin_cos();
    let rot = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
    let vol = volume([20, 10, 8], |_, _, _| 1.0)
        .with_direction(rot)
        .unwrap()
        .with_origin([4.0, -2.0, 0.0])
        .unwrap();
    // straight down z the silhouette is the rotated rectangle itself
    check_silhouettes(
        &vol,
        [96, 96],
        [
            (0.0, 0.0, "silhouette_rotated"),
            (40.0, 30.0, "silhouette_rotated_oblique"),
        ],
    );
}

// ---------------------------------------------------------------------------------------
// Rays only over the volume's projected rectangle, the rest cleared
// ---------------------------------------------------------------------------------------

/// Pixels whose square [x, x+1) × [y, y+1) touches the bounding rectangle of the
/// projected corners of the volume's box: no pixel outside can have a ray through the box
/// (its centre is at least half a pixel from the projection). `None` when a corner is
/// not in front of the camera (the projection is not bounded by the corners).
fn box_footprint(vol: &VolumeData, view: &View) -> Option<Vec<bool>> {
    let vp = view.camera.view_projection(view.aspect());
    let m = vol.index_to_data();
    let (lo, hi) = index_box(vol);
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for p in box_corners(lo, hi) {
        let c = vp * m.transform_point3(p).extend(1.0);
        if c.w <= 0.0 {
            return None;
        }
        let x = (c.x / c.w + 1.0) * 0.5 * view.width as f64;
        let y = (1.0 - c.y / c.w) * 0.5 * view.height as f64;
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    Some(
        (0..view.height)
            .flat_map(|y| (0..view.width).map(move |x| (x as f64, y as f64)))
            .map(|(x, y)| x + 1.0 > x0 && x < x1 && y + 1.0 > y0 && y < y1)
            .collect(),
    )
}

#[test]
fn outside_rectangle_is_cleared() {
    let mut r = renderer();
    let vol = blob_volume(24);
    let tf = TransferFunction::single(blob_transfer());
    r.set_volume(&vol).unwrap();
    r.set_transfer_function(&tf).unwrap();
    let b = vol.bounds();
    let (w, h) = (96u32, 80u32);
    let npix = (w * h) as usize;
    let params = shaded();
    let mut small = View::fit(b, w, h);
    small.camera.azimuth(30.0);
    small.camera.elevation(20.0);
    small.camera.orthogonalize_view_up();
    small.camera.reset_clipping_range(b);
    let mut zoomed = small.clone();
    zoomed.camera.zoom(4.0);
    zoomed.camera.reset_clipping_range(b);

    // 1. The zoomed frame: the box covers the whole image (a full-image dispatch) and the
    // blob's core shows everywhere.
    let zoom_img = r.render_image(&zoomed, &params).unwrap();
    save_enlarged(&zoom_img, "rect_zoomed");
    let zoom_hits = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let (_, _, t0, t1) = ray_segment(&vol, &pixel_ray(&zoomed, x, y));
            t0 < t1
        })
        .count();
    let zoom_fp = footprint(&zoom_img);

    // 2. The small frame right after it, on the same renderer and targets.
    let fp_mask = box_footprint(&vol, &small).expect("the box is in front of the camera");
    let img = r.render_image(&small, &params).unwrap();
    save_enlarged(&img, "rect_small");
    let inside = fp_mask.iter().filter(|&&m| m).count();
    let mut outside = 0;
    let mut stale = 0; // outside pixels the zoomed frame had drawn
    let mut bad_color = 0;
    let mut bad_depth = 0;
    let mut first_bad = None;
    for (i, &m) in fp_mask.iter().enumerate() {
        if m {
            continue;
        }
        outside += 1;
        stale += (zoom_img.rgba[4 * i + 3] > 0) as usize;
        let c = &img.rgba[4 * i..4 * i + 4];
        let d = img.depth[i];
        bad_color += (c != [0u8; 4]) as usize;
        bad_depth += (d != 1.0) as usize;
        if (c != [0u8; 4] || d != 1.0) && first_bad.is_none() {
            first_bad = Some((i as u32 % w, i as u32 / w, [c[0], c[1], c[2], c[3]], d));
        }
    }
    let small_fp = footprint(&img);
    let small_fp_out = img
        .rgba
        .chunks(4)
        .zip(&fp_mask)
        .filter(|(p, &m)| p[3] > 0 && !m)
        .count();

    // 3. The same small view by a renderer that never drew anything else.
    let mut fresh = new_renderer();
    fresh.set_volume(&vol).unwrap();
    fresh.set_transfer_function(&tf).unwrap();
    let fresh_img = fresh.render_image(&small, &params).unwrap();
    let (max_fresh, depth_fresh) = frame_diff(&img, &fresh_img);
    println!(
        "rect: zoomed frame: {zoom_hits} of {npix} px on the box, {zoom_fp} with opacity; small frame: analytic footprint {inside} px, {outside} outside it ({stale} of them drawn by the zoomed frame), {small_fp} px with opacity ({small_fp_out} outside the footprint); outside: {bad_color} px not rgba 0, {bad_depth} px depth not 1 (first {first_bad:?}); vs a fresh renderer: max abs diff {max_fresh}/255, {depth_fresh} depths differ"
    );
    assert_eq!(zoom_hits, npix, "the zoomed box must cover the image");
    assert!(
        zoom_fp * 10 >= npix * 9,
        "the zoomed frame must fill the image ({zoom_fp} of {npix} px)"
    );
    assert!(inside > 0 && small_fp > 0, "empty footprint");
    // the test means something only where the zoomed frame left pixels to clear
    assert!(
        outside * 4 >= npix && stale * 10 >= outside * 9,
        "too little outside the footprint: {outside} px, {stale} drawn before"
    );
    // Outside the footprint no ray meets the box: the pixels are cleared, never left from
    // the zoomed frame, and exactly so (clear values, not computed ones).
    assert_eq!(
        (bad_color, bad_depth),
        (0, 0),
        "pixels outside the footprint not cleared (first: {first_bad:?})"
    );
    // Inside, every pixel is written by the rays: nothing of the previous frame remains.
    assert_eq!(
        (max_fresh, depth_fresh),
        (0, 0),
        "the small frame depends on the frame before it"
    );

    // 4. The volume entirely off-screen (the camera shifted sideways by three box
    // widths): an empty rectangle, everything cleared.
    let mut away = small.clone();
    let right = away
        .camera
        .direction()
        .cross(away.camera.view_up)
        .normalize();
    let shift = right * 3.0 * (b[1] - b[0]);
    away.camera.position += shift;
    away.camera.focal_point += shift;
    away.camera.reset_clipping_range(b);
    let away_mask = box_footprint(&vol, &away).expect("the box is in front of the camera");
    r.render_image(&zoomed, &params).unwrap();
    let away_img = r.render_image(&away, &params).unwrap();
    let away_inside = away_mask.iter().filter(|&&m| m).count();
    let away_color = away_img.rgba.iter().filter(|&&c| c != 0).count();
    let away_depth = away_img.depth.iter().filter(|&&d| d != 1.0).count();
    println!(
        "rect: volume off-screen after the zoomed frame: footprint {away_inside} px, {away_color} channels not 0, {away_depth} depths not 1"
    );
    assert_eq!(away_inside, 0, "the shifted view still sees the box");
    assert_eq!(
        (away_color, away_depth),
        (0, 0),
        "an off-screen volume left pixels uncleared"
    );

    // 5. The camera inside the volume (a corner behind the camera: the full-image path),
    // right after the small frame, against the fresh renderer and the f64 reference.
    let mut inside_view = small.clone();
    inside_view.camera.position = DVec3::new(10.5, 11.0, 12.5);
    inside_view.camera.focal_point = DVec3::new(2.0, 5.0, 4.0);
    inside_view.camera.view_angle = 70.0;
    inside_view.camera.orthogonalize_view_up();
    inside_view.camera.reset_clipping_range(b);
    assert!(
        box_footprint(&vol, &inside_view).is_none(),
        "the camera must be inside the box"
    );
    r.render_image(&small, &params).unwrap();
    let in_img = r.render_image(&inside_view, &params).unwrap();
    save_enlarged(&in_img, "rect_camera_inside");
    let in_fresh = fresh.render_image(&inside_view, &params).unwrap();
    let (max_in, depth_in) = frame_diff(&in_img, &in_fresh);
    let dt = r.sample_distance(&params).unwrap();
    let (refc, _) = raycast::render(&vol, &blob_transfer(), &inside_view, &params, dt);
    let (mae, psnr, max) = compare_to_reference(&in_img, &refc);
    let in_fp = footprint(&in_img);
    println!(
        "rect: camera inside: {in_fp} of {npix} px with opacity; vs a fresh renderer: max abs diff {max_in}/255, {depth_in} depths differ; vs the f64 reference: mean abs error {mae:.3}/255, max {max:.1}/255, PSNR {psnr:.1} dB"
    );
    // Every ray starts inside the blob's core (value ≈ 0.9 at the camera), so every pixel
    // has opacity.
    assert_eq!(in_fp, npix, "pixels without opacity with the camera inside");
    assert_eq!(
        (max_in, depth_in),
        (0, 0),
        "the frame depends on the one before"
    );
    // as cpu_reference_composite_shaded
    assert!(psnr >= 35.0, "camera inside: PSNR {psnr:.1} dB");
    assert!(mae < 1.5, "camera inside: mean abs error {mae:.3}/255");
}
