//! What progressive frames show: the denoiser and its preview, time budgets, the error
//! estimate, restarts on opaque depth, masks, and a coarser level past the memory budget.

use super::*;

/// The optional denoiser: at 4 paths per pixel it brings the shown image closer to a
/// 1024-path reference than the unfiltered 4-path image, and leaves the accumulation as it
/// was.
#[test]
fn denoiser_lowers_the_error_and_keeps_the_accumulation() {
    let vol = ball(24, 11.0);
    let tf = medium([0.9, 0.7, 0.5], 0.0, 0.8, 1.0);
    let (mut r, view) = scene(&vol, tf, white_sky(), 96);
    let p = PathTraceParams {
        samples_per_frame: 64,
        seed: 3,
        ..Default::default()
    };
    trace(&mut r, &view, &p, 1024);
    let reference = r.read_image().unwrap();
    let rmse = |img: &Image| {
        let n = img.rgba.len() as f64;
        (img.rgba
            .iter()
            .zip(&reference.rgba)
            .map(|(a, b)| (*a as f64 - *b as f64).powi(2))
            .sum::<f64>()
            / n)
            .sqrt()
    };
    let noisy = PathTraceParams {
        samples_per_frame: 4,
        ..Default::default()
    };
    let raw = trace(&mut r, &view, &noisy, 4);
    let plain = r.read_image().unwrap();
    let filtered = trace(
        &mut r,
        &view,
        &PathTraceParams {
            denoise: true,
            ..noisy
        },
        4,
    );
    let denoised = r.read_image().unwrap();
    save(&plain, "pathtrace-denoise-off");
    save(&denoised, "pathtrace-denoise-on");
    save(&reference, "pathtrace-denoise-reference");
    let (e_plain, e_denoised) = (rmse(&plain), rmse(&denoised));
    println!(
        "4 paths per pixel against 1024: RMSE {e_plain:.2} levels unfiltered, {e_denoised:.2} \
         denoised"
    );
    // (measured 9.4 against 17.0 levels: a smooth medium, where the guide can only hold
    // the filter back; edges are where it matters)
    assert!(e_denoised < 0.7 * e_plain, "{e_denoised} vs {e_plain}");
    // the same paths (same seed): the accumulation is the unfiltered one
    assert_eq!(raw, filtered, "the denoiser changed the accumulation");
}

/// Pixels of `img` with any coverage.
fn covered(img: &Image) -> usize {
    img.rgba.chunks(4).filter(|p| p[3] > 0).count()
}

#[test]
fn time_budgets_trace_subsets_to_the_same_image() {
    let vol = ball(20, 9.0);
    let tf = medium([0.9, 0.7, 0.5], 0.0, 0.6, 2.0);
    let (mut r, view) = scene(&vol, tf, white_sky(), 48);
    let whole = PathTraceParams {
        samples_per_frame: 2,
        ..Default::default()
    };
    let reference = trace(&mut r, &view, &whole, 2);
    let converged = r.read_image().unwrap();
    // A budget no sixteenth fits: each frame adds exactly one (the least a frame adds).
    let p = PathTraceParams {
        time_budget: 1e-9,
        max_samples: 2,
        ..whole
    };
    r.set_path_tracing(&p).unwrap();
    r.reset_accumulation();
    let mut frames = 0;
    let mut means = vec![];
    let mut first_coverage = 0;
    while r.accumulated_samples() < 2 {
        r.render(&view, &pt_params(), None).unwrap();
        frames += 1;
        if frames == 1 {
            first_coverage = covered(&r.read_image().unwrap());
            save(&r.read_image().unwrap(), "pathtrace-first-sixteenth");
        }
        if frames % 8 == 0 {
            means.push(r.convergence().unwrap().mean_paths_per_pixel);
        }
    }
    let same = r.read_accumulation().unwrap() == reference;
    println!(
        "one sixteenth per frame: {frames} frames for 2 passes; mean paths per pixel every \
         8 frames {means:?}; the first frame shows {first_coverage} covered pixels against \
         {} converged; accumulation equal to whole passes: {same}",
        covered(&converged)
    );
    assert_eq!(frames, 32);
    assert!(same, "subsets trace the same paths as whole passes");
    assert_eq!(r.read_image().unwrap().rgba, converged.rgba);
    for (i, m) in means.iter().enumerate() {
        // (the rectangle's sides need not be multiples of 4: subsets differ slightly in size)
        let expected = (i + 1) as f32 * 0.5;
        assert!(
            (m - expected).abs() < 0.05,
            "{m} paths per pixel, not {expected}"
        );
    }
    // The first sixteenth shows every pixel from a traced neighbour: about the coverage of
    // the converged image (its edge is 4 pixels coarse).
    let ratio = first_coverage as f64 / covered(&converged) as f64;
    assert!((0.85..=1.15).contains(&ratio), "coverage ratio {ratio}");
    // A budget that holds everything: frames trace twice the sixteenths the last rate came
    // from until a frame adds samples_per_frame passes, and no more.
    r.set_path_tracing(&PathTraceParams {
        time_budget: 100.0,
        max_samples: 0,
        samples_per_frame: 3,
        ..whole
    })
    .unwrap();
    r.reset_accumulation();
    let mut added = vec![];
    while added.len() < 16 && !added.ends_with(&[3, 3]) {
        let before = r.accumulated_samples();
        r.render(&view, &pt_params(), None).unwrap();
        added.push(r.accumulated_samples() - before);
    }
    println!("a budget that holds everything: passes added per frame {added:?}");
    assert!(added.ends_with(&[3, 3]), "{added:?}");
    assert!(added.iter().all(|&a| a <= 3), "{added:?}");
}

#[test]
fn the_error_estimate_follows_the_measured_error() {
    let vol = ball(20, 9.0);
    let tf = medium([0.9, 0.7, 0.5], 0.0, 0.6, 2.0);
    let sky = Environment::hemisphere([0.9, 0.95, 1.0], [0.3, 0.25, 0.2]);
    let (mut r, view) = scene(&vol, tf, Some(sky), 24);
    let p = |seed: u32| PathTraceParams {
        samples_per_frame: 256,
        seed,
        anisotropy: 0.3,
        ..Default::default()
    };
    let lum = |v: &[f32; 4]| 0.2126 * v[0] as f64 + 0.7152 * v[1] as f64 + 0.0722 * v[2] as f64;
    let reference = trace(&mut r, &view, &p(1), 2048);
    let mut rows = vec![];
    for spp in [4u32, 16, 64] {
        let img = trace(&mut r, &view, &p(2), spp);
        let c = r.convergence().unwrap();
        let (mut se, mut mean, mut n) = (0.0, 0.0, 0);
        for (a, b) in img.iter().zip(&reference) {
            if a[3] > 0.0 {
                se += (lum(a) - lum(b)).powi(2);
                mean += lum(a);
                n += 1;
            }
        }
        let measured = (se / n as f64).sqrt() / (mean / n as f64);
        let estimate = c.relative_error.expect("two paths or more") as f64;
        println!(
            "{spp:3} paths per pixel: estimated relative error {estimate:.4}, measured against \
             2048 paths {measured:.4}"
        );
        assert_eq!(c.paths_per_pixel, spp);
        rows.push((estimate, measured));
    }
    for (estimate, measured) in &rows {
        // (the estimate is per pixel from a handful of paths; the measurement carries the
        // reference's own noise: within a factor of 1.5 either way)
        let q = estimate / measured;
        assert!((0.67..=1.5).contains(&q), "estimate / measured = {q}");
    }
    let fall = rows[0].0 / rows[2].0;
    println!("estimate at 4 over estimate at 64 paths: {fall:.2} (1/√spp: 4)");
    assert!((3.0..=5.0).contains(&fall), "{fall}");
}

#[test]
fn the_denoised_preview_gives_way_to_the_accumulation() {
    let vol = ball(20, 9.0);
    let tf = medium([0.9, 0.7, 0.5], 0.0, 0.6, 2.0);
    let (mut r, view) = scene(&vol, tf, white_sky(), 32);
    let plain = PathTraceParams {
        samples_per_frame: 2,
        ..Default::default()
    };
    let preview = PathTraceParams {
        denoise_until: 4,
        ..plain
    };
    let shown = |r: &mut Renderer, p: &PathTraceParams, spp: u32| {
        trace(r, &view, p, spp);
        r.read_image().unwrap().rgba
    };
    let (plain2, preview2) = (shown(&mut r, &plain, 2), shown(&mut r, &preview, 2));
    let (plain4, preview4) = (shown(&mut r, &plain, 4), shown(&mut r, &preview, 4));
    let differ = |a: &[u8], b: &[u8]| a.iter().zip(b).filter(|(x, y)| x != y).count();
    println!(
        "denoised until 4 paths per pixel: {} bytes differ from the plain image at 2 paths, \
         {} at 4",
        differ(&plain2, &preview2),
        differ(&plain4, &preview4)
    );
    assert!(differ(&plain2, &preview2) > plain2.len() / 10);
    assert_eq!(plain4, preview4);
}

#[test]
fn opaque_depth_restarts_only_when_it_changes() {
    let vol = volume([8, 8, 8], |x, _, _| x / 7.0);
    let (mut r, view) = scene(&vol, medium([0.8; 3], 0.0, 0.5, 1.0), None, 16);
    r.set_path_tracing(&PathTraceParams {
        samples_per_frame: 2,
        ..Default::default()
    })
    .unwrap();
    r.reset_accumulation();
    let restarts = r.stats().accumulation_restarts;
    let mut depth = vec![1.0f32; 16 * 16];
    let mut counts = vec![];
    for i in 0..5 {
        if i == 2 {
            depth[100] = 0.5;
        }
        r.render(&view, &pt_params(), Some(&depth)).unwrap();
        counts.push(r.accumulated_samples());
    }
    println!("accumulated paths per pixel with a depth input: {counts:?} (one pixel's depth changed before the third frame)");
    assert_eq!(counts, vec![2, 4, 2, 4, 6]);
    assert_eq!(r.stats().accumulation_restarts - restarts, 2);
}

/// Mean absolute difference of 4×4-pixel block means of two n×n images (rgb).
fn block_difference(a: &[[f32; 4]], b: &[[f32; 4]], n: usize) -> f64 {
    let (mut sum, mut count) = (0.0, 0);
    for by in (0..n).step_by(4) {
        for bx in (0..n).step_by(4) {
            for c in 0..3 {
                let mean = |img: &[[f32; 4]]| {
                    let mut m = 0.0;
                    for y in by..by + 4 {
                        for x in bx..bx + 4 {
                            m += img[y * n + x][c] as f64;
                        }
                    }
                    m / 16.0
                };
                sum += (mean(a) - mean(b)).abs();
                count += 1;
            }
        }
    }
    sum / count as f64
}

/// Masks shape the medium: a binary mask empties the points it holds 0 at, a label map gives
/// labelled points their label's colour and opacity. With nearest interpolation both equal a
/// volume whose scalars say the same (0 where masked; another value, which the transfer
/// function colours as the label, where labelled): the converged images agree within the
/// noise of the tracing (measured between 256 and 1024 paths per pixel).
#[test]
fn masks_shape_the_medium() {
    let n = 16usize;
    let size = 32usize;
    let tf = TransferFunction::single(component_transfer(
        &[
            (0.0, [1.0; 3]),
            (0.7, [1.0; 3]),
            (0.71, [1.0, 0.1, 0.1]),
            (1.0, [1.0, 0.1, 0.1]),
        ],
        &[
            (0.0, 0.0),
            (0.2, 0.0),
            (0.21, 0.3),
            (0.7, 0.3),
            (0.71, 0.6),
            (1.0, 0.6),
        ],
        2.0,
    ));
    let params = RenderParams {
        interpolation: Interpolation::Nearest,
        ..pt_params()
    };
    let p = PathTraceParams {
        samples_per_frame: 64,
        ..Default::default()
    };
    let half = |i: usize| i % n < n / 2;
    let uniform = volume([n as u32; 3], |_, _, _| 0.5);
    let (mut r, view) = scene(&uniform, tf.clone(), None, size as u32);
    let noise = {
        let a = trace_with(&mut r, &view, &params, &p, 256);
        let b = trace_with(&mut r, &view, &params, &p, 1024);
        block_difference(&a, &b, size)
    };
    // binary: the left half emptied
    let mask: Vec<u8> = (0..n * n * n).map(|i| u8::from(!half(i))).collect();
    r.set_mask(Some((&mask, MaskKind::Binary))).unwrap();
    let masked = trace_with(&mut r, &view, &params, &p, 1024);
    save(&r.read_image().unwrap(), "pathtrace-binary-mask");
    let emptied = volume(
        [n as u32; 3],
        |x, _, _| if x < (n / 2) as f64 { 0.0 } else { 0.5 },
    );
    r.set_volume(&emptied).unwrap();
    let same = trace_with(&mut r, &view, &params, &p, 1024);
    let d_binary = block_difference(&masked, &same, size);
    // label map: the left half labelled 2, red and twice as opaque
    r.set_volume(&uniform).unwrap();
    let mut labelled_tf = tf.clone();
    labelled_tf.labels = vec![LabelTransfer {
        label: 2,
        color: Some(Piecewise::new(vec![(0.0, [1.0, 0.1, 0.1])]).unwrap()),
        opacity: Some(Piecewise::new(vec![(0.0, [0.6])]).unwrap()),
        gradient_opacity: None,
    }];
    r.set_transfer_function(&labelled_tf).unwrap();
    let labels: Vec<u8> = (0..n * n * n)
        .map(|i| if half(i) { 2 } else { 0 })
        .collect();
    r.set_mask(Some((&labels, MaskKind::LabelMap))).unwrap();
    let labelled = trace_with(&mut r, &view, &params, &p, 1024);
    save(&r.read_image().unwrap(), "pathtrace-label-map");
    let red = volume(
        [n as u32; 3],
        |x, _, _| if x < (n / 2) as f64 { 0.9 } else { 0.5 },
    );
    r.set_volume(&red).unwrap();
    r.set_transfer_function(&tf).unwrap();
    let same_red = trace_with(&mut r, &view, &params, &p, 1024);
    let d_labels = block_difference(&labelled, &same_red, size);
    let d_plain = block_difference(&labelled, &masked, size);
    println!(
        "block means: binary mask vs emptied volume {d_binary:.4}, label map vs relabelled \
         volume {d_labels:.4}; noise (256 vs 1024 paths) {noise:.4}; label map vs binary \
         {d_plain:.4}"
    );
    assert!(d_binary < 2.0 * noise + 0.002, "binary mask: {d_binary}");
    assert!(d_labels < 2.0 * noise + 0.002, "label map: {d_labels}");
    assert!(d_plain > 5.0 * noise, "the scenes differ from each other");
}

/// A volume whose bricks exceed the memory budget is path traced at the finest coarser
/// level that fits: the same accumulation as that level uploaded directly, close to the
/// volume itself (the difference a level costs is printed); a ray-cast frame drops the
/// level's pool and draws the volume itself; a mask, which is not downsampled, is refused.
#[test]
fn past_the_budget_a_coarser_level_is_traced() {
    let vol = blob_volume(48);
    let tf = medium([0.9, 0.7, 0.5], 0.0, 1.0, 3.0);
    let dense = 48u64.pow(3) * 4;
    let opts = |budget: Option<u64>| UploadOptions {
        max_brick_points: Some(32),
        memory_budget: budget,
        ..Default::default()
    };
    let view = View::fit(vol.bounds(), 48, 48);
    let p = PathTraceParams {
        samples_per_frame: 16,
        ..Default::default()
    };
    let traced = |v: &VolumeData, budget: Option<u64>| {
        let mut r = new_renderer();
        r.set_volume_with(v, opts(budget)).unwrap();
        r.set_transfer_function(&tf).unwrap();
        let acc = trace(&mut r, &view, &p, 64);
        (r, acc)
    };
    let (mut r, coarse) = traced(&vol, Some(dense / 4));
    save(&r.read_image().unwrap(), "pathtrace-coarser-level");
    let res = r.residency();
    println!("past the budget: {res:?}");
    assert_eq!(
        res.level, 2,
        "a level 2x coarser fits a quarter of the volume"
    );
    assert_eq!(res.level_dims, [25; 3]);
    assert!(res.pool_bytes <= dense / 4, "only the level's pool is held");
    let (_, direct) = traced(&vol.downsampled(2).unwrap(), Some(dense / 4));
    let same = coarse
        .iter()
        .zip(&direct)
        .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
        .fold(0f32, f32::max);
    assert!(same < 1e-5, "the level traced as uploaded directly: {same}");
    let (_, fine) = traced(&vol, None);
    let level_cost = block_difference(&coarse, &fine, 48);
    let noise = {
        let (_, again) = traced(&vol, None);
        let mut other = new_renderer();
        other.set_volume(&vol).unwrap();
        other.set_transfer_function(&tf).unwrap();
        let q = PathTraceParams { seed: 7, ..p };
        let reseeded = trace(&mut other, &view, &q, 64);
        assert_eq!(again, fine, "the same seed traces the same paths");
        block_difference(&reseeded, &fine, 48)
    };
    println!("coarser level against the volume: {level_cost:.4}; another seed: {noise:.4}");
    assert!(
        level_cost < 3.0 * noise + 0.01,
        "a level 2x coarser of a smooth volume stays within the noise's order"
    );
    // a ray-cast frame draws the volume itself, within the budget
    r.render(&view, &RenderParams::default(), None).unwrap();
    let res = r.residency();
    assert_eq!((res.level, res.level_dims), (1, [48; 3]));
    assert!(
        res.pool_bytes <= dense / 4,
        "the level's pool is dropped: {res:?}"
    );
    let mask = vec![1u8; 48 * 48 * 48];
    r.set_mask(Some((&mask, MaskKind::Binary))).unwrap();
    assert_error(
        r.render(&view, &pt_params(), None),
        "a mask past the budget",
        &["memory budget", "coarser level", "not downsampled"],
    );
}
