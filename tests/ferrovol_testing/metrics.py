"""Image comparison: SSIM, PSNR, luminance, and the masks and boxes of what an image shows.

Images are H x W x C arrays of 8-bit levels (uint8, or floats in 0..255) with rows top to
bottom; only the first three channels (RGB) count.
"""
import numpy as np


def rgb(img):
    """The R, G and B channels of an image as float64 levels."""
    return np.asarray(img)[..., :3].astype(np.float64)


def luminance(img):
    """Rec. 601 luma of an RGB image, in the image's levels."""
    return img[..., 0] * 0.299 + img[..., 1] * 0.587 + img[..., 2] * 0.114


def _gauss_blur(x, sigma=1.5, radius=5):
    """Separable Gaussian filter (an 11 x 11 window for the defaults), mirrored borders."""
    k = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma) ** 2)
    k /= k.sum()
    p = np.pad(x, radius, mode="reflect")
    h, w = x.shape
    rows = sum(k[i] * p[:, i:i + w] for i in range(2 * radius + 1))
    return sum(k[i] * rows[i:i + h, :] for i in range(2 * radius + 1))


def ssim(a, b):
    """Mean SSIM of the luminance of two RGB images: Wang, Bovik, Sheikh and Simoncelli,
    "Image quality assessment: from error visibility to structural similarity", IEEE TIP
    13(4), 2004: an 11 x 11 Gaussian window (sigma 1.5), K1 0.01 and K2 0.03 of the 8-bit
    range, averaged over every pixel (borders mirrored)."""
    x, y = luminance(rgb(a)), luminance(rgb(b))
    c1, c2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2
    mx, my = _gauss_blur(x), _gauss_blur(y)
    sxx = _gauss_blur(x * x) - mx * mx
    syy = _gauss_blur(y * y) - my * my
    sxy = _gauss_blur(x * y) - mx * my
    s = ((2 * mx * my + c1) * (2 * sxy + c2)) / ((mx * mx + my * my + c1) * (sxx + syy + c2))
    return float(s.mean())


def psnr(a, b):
    """Peak signal-to-noise ratio over R, G and B in dB (inf for identical images)."""
    d = rgb(a) - rgb(b)
    mse = float(np.mean(d * d))
    return float("inf") if mse == 0 else float(10.0 * np.log10(255.0 ** 2 / mse))


def foreground(img, background=(0.0, 0.0, 0.0), tol=8.0):
    """The pixels whose R, G or B differs from background (8-bit levels) by more than tol."""
    return np.abs(rgb(img) - np.asarray(background, dtype=np.float64)).max(axis=2) > tol


def footprint(*imgs, background=(0.0, 0.0, 0.0), tol=8.0):
    """The pixels that differ from the background in any of imgs."""
    mask = np.zeros(np.shape(imgs[0])[:2], bool)
    for im in imgs:
        mask |= foreground(im, background, tol)
    return mask


def coverage(img, background=(0.0, 0.0, 0.0), tol=8.0):
    """The fraction of the image's pixels that differ from the background."""
    return float(foreground(img, background, tol).mean())


def box(mask, pad=4):
    """Rows and columns (slices) covering every pixel of mask, pad pixels wider on each side
    within the image; None for an empty mask."""
    if not mask.any():
        return None
    rows, cols = np.where(mask.any(axis=1))[0], np.where(mask.any(axis=0))[0]
    h, w = mask.shape
    return (slice(max(rows[0] - pad, 0), min(rows[-1] + pad + 1, h)),
            slice(max(cols[0] - pad, 0), min(cols[-1] + pad + 1, w)))


def difference_image(a, b, gain=4.0):
    """|a - b| in R, G and B, amplified by gain and clipped to 0..255, as float levels."""
    return np.clip(np.abs(rgb(a) - rgb(b)) * gain, 0, 255)
