//! Pixels and image metrics: differences, footprints, error and PSNR against an f64
//! reference, FLIP.

use ferrovol_core::Image;

/// PSNR (dB) of an 8-bit image against another over every channel.
pub fn psnr(img: &Image, reference: &Image) -> f64 {
    let mse = img
        .rgba
        .iter()
        .zip(&reference.rgba)
        .map(|(a, b)| (*a as f64 - *b as f64).powi(2))
        .sum::<f64>()
        / img.rgba.len() as f64;
    10.0 * (255.0f64.powi(2) / mse.max(1e-12)).log10()
}

/// Pixel (x, y) as premultiplied RGBA bytes.
pub fn rgba(img: &Image, x: u32, y: u32) -> [u8; 4] {
    let i = 4 * (y * img.width + x) as usize;
    [
        img.rgba[i],
        img.rgba[i + 1],
        img.rgba[i + 2],
        img.rgba[i + 3],
    ]
}

pub fn alpha(img: &Image, x: u32, y: u32) -> u8 {
    rgba(img, x, y)[3]
}

/// Pixels with any opacity.
/// Per channel (r, g, b, coverage), the sum over the pixels of an accumulation
/// (Renderer::read_accumulation).
pub fn channel_sums(img: &[[f32; 4]]) -> [f64; 4] {
    img.iter().fold([0.0; 4], |mut s, px| {
        for c in 0..4 {
            s[c] += px[c] as f64;
        }
        s
    })
}

pub fn footprint(img: &Image) -> usize {
    img.rgba.chunks(4).filter(|p| p[3] > 0).count()
}

/// (mean, max) absolute difference per channel, in 0–255 units.
pub fn image_diff(a: &Image, b: &Image) -> (f64, u8) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let mut sum = 0u64;
    let mut max = 0u8;
    for (x, y) in a.rgba.iter().zip(&b.rgba) {
        let d = x.abs_diff(*y);
        sum += d as u64;
        max = max.max(d);
    }
    (sum as f64 / a.rgba.len() as f64, max)
}

/// (max abs channel difference, pixels whose depth differs in any bit) of two frames.
pub fn frame_diff(a: &Image, b: &Image) -> (u8, usize) {
    let (_, max) = image_diff(a, b);
    let depth = a
        .depth
        .iter()
        .zip(&b.depth)
        .filter(|(x, y)| x.to_bits() != y.to_bits())
        .count();
    (max, depth)
}

/// Elements that differ.
pub fn count_diff<T: PartialEq>(a: &[T], b: &[T]) -> usize {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).filter(|(x, y)| x != y).count()
}

/// Mean absolute error (0–255 units), PSNR (dB) and max absolute error of the GPU image
/// against the reference (premultiplied RGBA in [0, 1] per pixel).
pub fn compare_to_reference(img: &Image, reference: &[[f64; 4]]) -> (f64, f64, f64) {
    let mut sum = 0.0;
    let mut sq = 0.0;
    let mut max: f64 = 0.0;
    for (p, q) in img.rgba.chunks(4).zip(reference) {
        for c in 0..4 {
            let e = (p[c] as f64 - q[c].clamp(0.0, 1.0) * 255.0).abs();
            sum += e;
            sq += e * e;
            max = max.max(e);
        }
    }
    let n = (img.rgba.len()) as f64;
    let mse = sq / n;
    (
        sum / n,
        10.0 * (255.0 * 255.0 / mse.max(1e-12)).log10(),
        max,
    )
}

/// Pixels with some channel more than `levels` away from the reference.
pub fn pixels_off_by_more(img: &Image, reference: &[[f64; 4]], levels: f64) -> usize {
    img.rgba
        .chunks(4)
        .zip(reference)
        .filter(|(p, q)| {
            (0..4).any(|c| (p[c] as f64 - q[c].clamp(0.0, 1.0) * 255.0).abs() > levels)
        })
        .count()
}

/// The reference as an 8-bit image (for looking at it).
pub fn reference_image(refc: &[[f64; 4]], w: u32, h: u32) -> Image {
    Image {
        width: w,
        height: h,
        rgba: refc
            .iter()
            .flat_map(|p| p.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
            .collect(),
        depth: vec![1.0; (w * h) as usize],
    }
}

/// Linear radiance → 8-bit sRGB (clamped at 1), as an image would show it.
pub fn srgb8(v: f64) -> u8 {
    let v = v.clamp(0.0, 1.0);
    let e = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0).round() as u8
}

/// FLIP (LDR, NVIDIA's nv-flip) of a `size` × `size` 8-bit sRGB test image against the
/// reference: the mean error and the error map in NVIDIA's magma colours (8-bit RGB).
pub fn flip(reference: &[u8], test: &[u8], size: u32) -> (f64, Vec<u8>) {
    let err = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(size, size, reference),
        nv_flip::FlipImageRgb8::with_data(size, size, test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let mean = nv_flip::FlipPool::from_image(&err).mean() as f64;
    (mean, err.apply_color_lut(&nv_flip::magma_lut()).to_vec())
}

/// Exact ambient accessibility of a floor point (dx, dy) inside a corner of two half-space
/// walls (at x = −dx and y = −dy from it), for AO rays of length `radius`: the uniform
/// hemisphere's share of directions with ω_x ≥ −dx/R and ω_y ≥ −dy/R (a ray is occluded iff
/// its end is inside a wall), by quadrature over (cos θ, φ) on an nz × nphi grid.
pub fn corner_accessibility(dx: f64, dy: f64, radius: f64, nz: usize, nphi: usize) -> f64 {
    let mut open = 0usize;
    for i in 0..nz {
        let z = (i as f64 + 0.5) / nz as f64;
        let s = (1.0 - z * z).sqrt();
        for j in 0..nphi {
            let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / nphi as f64;
            if s * phi.cos() >= -dx / radius && s * phi.sin() >= -dy / radius {
                open += 1;
            }
        }
    }
    open as f64 / (nz * nphi) as f64
}
