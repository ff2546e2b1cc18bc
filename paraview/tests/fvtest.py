"""Shared pieces of the Ferrovol ParaView tests (run by pvbatch / pvpython, see Makefile).

- load_plugin(): the plugin by name (PV_PLUGIN_PATH, build/paraview/env.sh) or by path
  (FERROVOL_PV_PLUGIN);
- render helpers with a fixed camera and transfer functions, saving PNGs under OUT_DIR
  (build/paraview-test), read back as numpy arrays;
- ssim()/psnr(): the measures the tests print and assert, from tests/ferrovol_testing (shared
  with the VTK module's tests and the regression suite): SSIM of the luminance (Wang et al.
  2004, Gaussian window sigma 1.5), PSNR over R, G and B. compare() reports them over the
  whole frame and over the volume's screen box (pixels that differ from the background in
  either image); the thresholds apply to the box, so an empty background cannot inflate them.
"""
import os
import sys
import time

import numpy as np

from paraview.simple import (  # noqa: F401  (re-exported for the tests)
    ColorBy, CreateRenderView, Delete, GetColorTransferFunction, GetOpacityTransferFunction,
    LoadDistributedPlugin, LoadPlugin, Render, SaveScreenshot, Show, servermanager)

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "tests"))
from ferrovol_testing import metrics  # noqa: E402
from ferrovol_testing.metrics import box, difference_image, footprint, psnr, ssim  # noqa: E402,F401
from ferrovol_testing.png import read_png, write_png  # noqa: E402,F401

OUT_DIR = os.environ.get("FERROVOL_PV_TEST_OUT", os.path.join(os.getcwd(), "build", "paraview-test"))
BACKGROUND = (0.1, 0.1, 0.15)


def pv_version():
    """ParaView's (major, minor): 5.11 on Debian bookworm, 6.1 from scripts/pv6-sdk.sh."""
    pm = servermanager.vtkSMProxyManager
    return (pm.GetVersionMajor(), pm.GetVersionMinor())


# The representations' "Position" (its XML name in both) is "Translation" in Python since
# ParaView 5.13, where disp.Position raises NotSupportedException.
POSITION = "Translation" if pv_version() >= (5, 13) else "Position"


def rank():
    pm = servermanager.vtkProcessModule.GetProcessModule()
    return pm.GetPartitionId() if pm else 0


def nranks():
    pm = servermanager.vtkProcessModule.GetProcessModule()
    return pm.GetNumberOfLocalPartitions() if pm else 1


def print_in_rank_order(msg):
    """Every rank prints msg, rank 0 first (one line each, not interleaved)."""
    from vtkmodules.vtkParallelCore import vtkMultiProcessController
    ctrl = vtkMultiProcessController.GetGlobalController()
    n = ctrl.GetNumberOfProcesses() if ctrl else 1
    for r in range(n):
        if ctrl and n > 1:
            ctrl.Barrier()
        if r == rank():
            print(msg, flush=True)


def log(*args):
    if rank() == 0:
        print(*args, flush=True)


def plugin_loaded(name="Ferrovol"):
    info = servermanager.vtkSMProxyManager.GetProxyManager().GetPluginManager().GetLocalInformation()
    return any(info.GetPluginName(i) == name and info.GetPluginLoaded(i)
               for i in range(info.GetNumberOfPlugins()))


def load_plugin(ns=None):
    """Loads the Ferrovol plugin: from FERROVOL_PV_PLUGIN (a path) if set, else by name with
    LoadDistributedPlugin (PV_PLUGIN_PATH, build/env.sh). ParaView already loaded it at
    start-up when it is in PV_PLUGIN_PATH; loading it again makes ParaView 5.11 log a
    misleading "Plugin load failed: No plugin loaded yet." (and succeed), so that is skipped.
    Returns how it was loaded."""
    path = os.environ.get("FERROVOL_PV_PLUGIN")
    if path:
        LoadPlugin(path, remote=False, ns=ns)
        return path
    if plugin_loaded():
        return "PV_PLUGIN_PATH (at start-up)"
    LoadDistributedPlugin("Ferrovol", remote=False, ns=ns)
    return "LoadDistributedPlugin"


def make_view(size=(400, 400)):
    # paraview.simple.Render() resets the camera on the session's first render: the tests
    # set their cameras themselves. (_DisableFirstRenderCameraReset is in 5.11's simple.py and
    # in 6.x's simple package, where _funcs_internals moved to paraview.simple.session.)
    import paraview.simple
    paraview.simple._DisableFirstRenderCameraReset()
    view = CreateRenderView()
    view.ViewSize = list(size)
    view.OrientationAxesVisibility = 0
    view.Background = list(BACKGROUND)
    # ParaView 5.11 keeps a palette-driven background unless told otherwise.
    if view.GetProperty("UseColorPaletteForBackground") is not None:
        view.UseColorPaletteForBackground = 0
    # Full-resolution still renders only (no LOD, no interactive subsampling).
    view.LODThreshold = 1e20
    return view


def set_camera(view, bounds, azimuth=30.0, elevation=20.0, direction=None, zoom=1.0):
    """Looks at the centre of bounds from a fixed direction (azimuth/elevation about +y, or an
    explicit unit direction from the focal point to the camera)."""
    c = [(bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2, (bounds[4] + bounds[5]) / 2]
    diag = np.linalg.norm([bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4]])
    if direction is None:
        a, e = np.radians(azimuth), np.radians(elevation)
        direction = [np.sin(a) * np.cos(e), np.sin(e), np.cos(a) * np.cos(e)]
    d = np.asarray(direction, float)
    d /= np.linalg.norm(d)
    dist = 1.9 * diag / zoom
    view.CameraFocalPoint = c
    view.CameraPosition = list(np.asarray(c) + dist * d)
    up = [0, 1, 0] if abs(d[1]) < 0.9 else [0, 0, 1]
    view.CameraViewUp = up
    view.CameraViewAngle = 30
    view.CameraParallelProjection = 0
    view.CenterOfRotation = c


def color_by(display, array, rgb_points=None, opacity_points=None, association="POINTS"):
    if nranks() > 1 and pv_version() >= (6, 0) and rgb_points is not None \
            and opacity_points is not None:
        # ParaView 6.1 under pvbatch --symmetric: ColorBy rescales the colour map with a
        # collective operation (vtkSMTransferFunctionProxy::RescaleTransferFunction all-reduces
        # the range) that a rank whose piece lacks the array skips (vtkSMColorMapEditorHelper:
        # "Could not determine array range."): the ranks deadlock (measured: test_mpi.py's
        # one-cell Wavelet, rank 0 in MPI_Allreduce, rank 1 in the representation's
        # gather). Both maps are set here, so the display is coloured without the rescale.
        display.ColorArrayName = [association, array]
        display.LookupTable = GetColorTransferFunction(array)
        display.ScalarOpacityFunction = GetOpacityTransferFunction(array)
    else:
        ColorBy(display, (association, array))
    lut = GetColorTransferFunction(array)
    pwf = GetOpacityTransferFunction(array)
    if rgb_points is not None:
        lut.RGBPoints = list(rgb_points)
    if opacity_points is not None:
        pwf.Points = list(opacity_points)
    lut.ScalarRangeInitialized = 1
    pwf.ScalarRangeInitialized = 1
    lut.AutomaticRescaleRangeMode = "Never"
    pwf.AllowDuplicateScalars = 1
    return lut, pwf


def screenshot(view, name, size=None, transparent=False):
    """Renders view into OUT_DIR/name.png and returns it as an HxWx3 (or x4) uint8 array."""
    os.makedirs(OUT_DIR, exist_ok=True)
    path = os.path.join(OUT_DIR, name + ".png")
    kw = {"ImageResolution": list(size or view.ViewSize)}
    if transparent:
        kw["TransparentBackground"] = 1
    t0 = time.time()
    SaveScreenshot(path, view, **kw)
    dt = time.time() - t0
    img = read_png(path) if rank() == 0 else None
    return img, path, dt


def volume_box(*imgs, background=BACKGROUND, tol=3, pad=4):
    """Rows and columns (slices) covering every pixel that differs from the background in any
    of imgs."""
    return box(footprint(*imgs, background=np.round(np.asarray(background) * 255), tol=tol),
               pad)


def coverage(img, background=BACKGROUND, tol=3):
    return metrics.coverage(img, np.round(np.asarray(background) * 255), tol)


def compare(name, a, b, min_ssim=None, min_psnr=None, failures=None, expect_fail=False):
    """Prints SSIM (frame and volume box) and PSNR of a against b, writes a diff image, and
    records a failure when the box SSIM or PSNR is under its threshold (or, with
    expect_fail, when neither is)."""
    vb = volume_box(a, b)
    s_full, p = ssim(a, b), psnr(a, b)
    s_box = ssim(a[vb], b[vb]) if vb else s_full
    p_box = psnr(a[vb], b[vb]) if vb else p
    write_png(os.path.join(OUT_DIR, name + "-diff.png"), difference_image(a, b))
    ok = True
    why = []
    if min_ssim is not None and s_box < min_ssim:
        ok = False
        why.append("SSIM %.4f < %.3f" % (s_box, min_ssim))
    if min_psnr is not None and p_box < min_psnr:
        ok = False
        why.append("PSNR %.2f dB < %.1f dB" % (p_box, min_psnr))
    if expect_fail:
        verdict = ("fails as it must: " + "; ".join(why)) if not ok else "FAIL: passed"
        ok = not ok
        why = why or ["passed thresholds it must fail"]
    else:
        verdict = "ok" if ok else "FAIL: " + "; ".join(why)
    print("  %-34s SSIM %.4f (box %.4f)  PSNR %.2f dB (box %.2f dB)  %s" % (
        name, s_full, s_box, p, p_box, verdict), flush=True)
    if not ok and failures is not None:
        failures.append("%s: %s" % (name, "; ".join(why)))
    return s_box, p_box


def render_both(view, disp, blend, tag, failures):
    """Renders disp as ParaView's "Volume" and as "Ferrovol Volume" with one blend mode
    (vtkVolumeMapper's enum, set on the shared BlendMode; Ferrovol Blend Mode follows it)
    into OUT_DIR/<tag>-vtk.png and <tag>-ferrovol.png; records a failure when the ferrovol
    mapper did not draw. Returns {representation: image}."""
    # The BlendMode domain lists only Composite/Isosurface/Slice; the property itself passes
    # any vtkVolumeMapper blend mode to both representations.
    disp.GetProperty("BlendMode").SetElement(0, blend)
    disp.FerrovolBlendMode = "Follow Blend Mode"
    disp.UpdateVTKObjects()
    imgs = {}
    for rep in ("Volume", "Ferrovol Volume"):
        disp.Representation = rep
        Render(view)
        name = "%s-%s" % (tag, "ferrovol" if rep != "Volume" else "vtk")
        imgs[rep], _, dt = screenshot(view, name)
        log("  %-40s rendered + saved in %.2f s, %.1f%% of the frame covered" % (
            name, dt, 100 * coverage(imgs[rep])))
    info = ferrovol_info(disp)
    if info["FerrovolLastRenderDrew"] != 1:
        failures.append("%s: the ferrovol mapper did not draw (%s)" % (tag, info))
    return imgs


def finish(failures, what):
    if rank() != 0:
        return
    if failures:
        print("FAIL %s:\n  %s\n  images: %s" % (what, "\n  ".join(failures), OUT_DIR), flush=True)
        sys.stdout.flush()
        os._exit(1)
    print("PASS %s" % what, flush=True)


def ferrovol_info(display):
    display.UpdatePropertyInformation()
    return {p: display.GetProperty(p).GetData() for p in (
        "FerrovolVersion", "FerrovolAdapter", "FerrovolOutputPath",
        "FerrovolLastRenderDrew", "FerrovolLastRenderSize", "FerrovolVolumeUploadCount",
        "FerrovolTableUploadCount")}
