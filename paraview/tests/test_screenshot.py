"""(d) SaveScreenshot at 1920x1080 with "Ferrovol Volume", two ways ParaView 5.11 does it:
- the view is 1920x1080: ferrovol renders one 1920x1080 frame;
- the view is 480x270: SaveScreenshot never enlarges a view, it renders 4x4 tiles of
  480x270 with a magnified camera (vtkSMSaveScreenshotProxy), so ferrovol must honour the
  tile viewport: the stitched picture must match the single frame, without seams.
Both must match ParaView's "Volume" saved the same way, and the PNGs must be 1920x1080.

    pvbatch paraview/tests/test_screenshot.py
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fvtest as T  # noqa: E402
from paraview.simple import Wavelet, Show, Render  # noqa: E402

T.load_plugin(globals())

# Against "Volume": test_wavelet.py's composite thresholds (the same scene, larger).
# Tiled against single frame (both ferrovol): measured SSIM 1.000 / PSNR 83.8 dB, the rest
# being the rounding of per-tile projection matrices; a tile drawn with the full-frame
# camera (a tiling bug) puts 16 small copies of the volume on the picture (SSIM averaged
# over R, G and B, as these tests measured before tests/ferrovol_testing: < 0.5).
MIN_SSIM, MIN_PSNR = 0.96, 33.0
TILED_MIN_SSIM, TILED_MIN_PSNR = 0.98, 40.0
W, H = 1920, 1080

src = Wavelet()
failures = []
shots = {}
for view_size, how in (((W, H), "single"), ((W // 4, H // 4), "tiled")):
    view = T.make_view(view_size)
    disp = Show(src, view)
    T.color_by(disp, "RTData",
               rgb_points=[37.35, 0.23, 0.30, 0.75, 157.1, 0.87, 0.87, 0.87, 276.8, 0.71, 0.02, 0.15],
               opacity_points=[37.35, 0.0, 0.5, 0.0, 276.8, 0.8, 0.5, 0.0])
    disp.ScalarOpacityUnitDistance = 3.0
    T.set_camera(view, src.GetDataInformation().GetBounds(), azimuth=30, elevation=20)
    for rep in ("Volume", "Ferrovol Volume"):
        disp.Representation = rep
        Render(view)
        tag = "screenshot-1080p-%s-%s" % (how, "ferrovol" if rep != "Volume" else "vtk")
        img, path, dt = T.screenshot(view, tag, size=(W, H))
        shots[(how, rep)] = img
        h, w = img.shape[:2]
        T.log("  %-40s view %dx%d -> PNG %dx%d in %.2f s (%.1f%% covered)" % (
            tag, view_size[0], view_size[1], w, h, dt, 100 * T.coverage(img)))
        if (w, h) != (W, H):
            failures.append("%s: the PNG is %dx%d, not %dx%d" % (tag, w, h, W, H))
    info = T.ferrovol_info(disp)
    size = list(info["FerrovolLastRenderSize"])
    T.log("  ferrovol's last frame: %dx%d (drew: %d)" % (size[0], size[1], info["FerrovolLastRenderDrew"]))
    if info["FerrovolLastRenderDrew"] != 1:
        failures.append("%s: ferrovol did not draw" % how)
    if size != list(view_size):
        failures.append("%s: ferrovol's frame was %dx%d, the view %dx%d" % (
            how, size[0], size[1], view_size[0], view_size[1]))
    if T.coverage(shots[(how, "Ferrovol Volume")]) < 0.05:
        failures.append("%s: the screenshot shows no volume" % how)
    T.compare("screenshot-1080p-%s" % how, shots[(how, "Ferrovol Volume")],
              shots[(how, "Volume")], MIN_SSIM, MIN_PSNR, failures)
    T.Delete(disp)
    T.Delete(view)

single, tiled = shots[("single", "Ferrovol Volume")], shots[("tiled", "Ferrovol Volume")]
T.compare("ferrovol tiled vs single frame", tiled, single, TILED_MIN_SSIM, TILED_MIN_PSNR,
          failures)


# Seams: the step across each tile border against the steps next to it.
def seam_ratio(img):
    g = img[..., :3].astype(float)
    dx = np.abs(np.diff(g, axis=1)).mean(axis=(0, 2))
    dy = np.abs(np.diff(g, axis=0)).mean(axis=(1, 2))
    r = []
    for d, n in ((dx, W // 4), (dy, H // 4)):
        for k in (1, 2, 3):
            b = k * n - 1
            r.append(d[b] / max(1e-6, 0.5 * (d[b - 2] + d[b + 2])))
    return max(r)


# The same columns and rows of the single frame give the ratio the picture itself has there.
sr_t, sr_s = seam_ratio(tiled), seam_ratio(single)
T.log("  tile-border step / neighbouring steps: tiled %.2f, single frame %.2f, Volume tiled %.2f"
      % (sr_t, sr_s, seam_ratio(shots[("tiled", "Volume")])))
if sr_t > sr_s + 0.5:
    failures.append("seams between the screenshot's tiles (ratio %.2f, %.2f without tiles)"
                    % (sr_t, sr_s))
T.finish(failures, "screenshot: 1920x1080 SaveScreenshot, single frame and tiled")
