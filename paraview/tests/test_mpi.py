"""(f) "Ferrovol Volume" on a distributed Wavelet under MPI, against the serial image.

Two steps (make paraview-test runs both):

  pvbatch test_mpi.py serial
      renders the whole Wavelet serially from four cameras in every blend mode (the
      references), and shows that
      ordering matters: the Wavelet cut at z = 0 into the two halves that two ranks hold,
      each half rendered alone, composited back to front in numpy in the right and in the
      wrong order, against the whole;
  mpiexec -n N pvbatch --symmetric test_mpi.py distributed
      each rank holds one piece of the Wavelet (ParaView's extent translator cuts it along z
      for N = 2), draws only that piece with ferrovol, and IceT composites the ranks' RGBA
      images in the order vtkPVRenderView computes from the pieces' bounds (MIP and MinIP:
      by depth); rank 0 compares the result with the serial references (SSIM >= 0.98
      required; additive: see BLENDS), and a 2D transfer function's image with ParaView's
      "Volume" drawing it (TF2D_*).

Why it works (ParaView 5.11): vtkImageVolumeRepresentation reports NEED_ORDERED_COMPOSITING
and USE_BOUNDS_FOR_REDISTRIBUTION. The data is not moved: every rank's local bounds are
all-gathered into one box per rank (vtkPVRenderViewDataDeliveryManager), and for each
frame vtkOrderedCompositingHelper sorts the boxes back to front from the camera position
(vtkBlockSortHelper); IceT then blends the ranks' premultiplied images in that order
instead of z-compositing them. This is right when the pieces do not overlap in space (the
representation crops ghost cells away for that reason), whatever the camera: the cameras
"front" and "back" below look along the cut, so one piece lies entirely behind the other
and the order must flip between them. The ranks sample on the whole volume's lattice
(vtkFerroVolumeMapper::WholeExtent, which the representation sets under MPI), so a
sample on the cut is taken once and the pieces' samples are the serial ray's. For MIP and
MinIP the representation turns ordered compositing off and the mapper writes the
extremum's place in the colour range as the depth (ExtremumDepth): IceT's z-compositing
then keeps the extremum over all ranks.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fvtest as T  # noqa: E402
from paraview.simple import (  # noqa: E402
    ExtractSubset, GetTransferFunction2D, Hide, PythonCalculator, Render, Show, Wavelet)

MODE = sys.argv[1] if len(sys.argv) > 1 else "distributed"
SIZE = (300, 300)
EXTENT = [-10, 10, -10, 10, -10, 10]
# The whole Wavelet's bounds (spacing 1, origin 0), written out: under --symmetric a rank's
# data information may describe only its own piece.
BOUNDS = [float(e) for e in EXTENT]
RGB = [37.35, 0.23, 0.30, 0.75, 157.1, 0.87, 0.87, 0.87, 276.8, 0.71, 0.02, 0.15]
OPACITY = [37.35, 0.0, 0.5, 0.0, 276.8, 0.9, 0.5, 0.0]
# Camera directions (focal point -> camera). front/back look along z, the axis the pieces
# are cut along: the pieces overlap completely on screen, one in front of the other.
CAMERAS = {
    "oblique": [0.5, 0.34, 0.8],
    "front": [0.15, 0.1, 1.0],
    "back": [-0.15, 0.1, -1.0],
    "side": [1.0, 0.2, 0.1],
}
# The distributed image against the serial one: SSIM >= 0.98 (the requirement) and
# PSNR >= 35 dB on the volume's box. The ranks sample on the whole volume's lattice (the
# mapper's WholeExtent), so what differs is rounding: each rank's frame is 8-bit.
MIN_SSIM, MIN_PSNR = 0.98, 35.0
# The other blend modes, each composited as the representation arranges under MPI: MIP and
# MinIP by depth (the extremum's place in the colour range), average as shares of the whole
# ray added by "over", additive summed by the mappers across the ranks (DistributedSum:
# IceT's 8-bit "over" cannot add two sums) and drawn by one rank.
BLENDS = {
    "Maximum Intensity": (MIN_SSIM, MIN_PSNR),
    "Minimum Intensity": (MIN_SSIM, MIN_PSNR),
    "Average Intensity": (MIN_SSIM, MIN_PSNR),
    "Additive": (MIN_SSIM, MIN_PSNR),
    "Isosurface": (0.97, 25.0),
}
# The isosurface blend mode's value (the representation's Isosurface Values). A piece
# samples on the whole's lattice and also at the faces it shares with its neighbours (a
# crossing between one piece's last sample and the next piece's first would otherwise be
# found by neither), so where a ray grazes a thin fold of the surface at a cut, a piece can
# find a crossing the serial ray steps over. From +z and -z the surface's silhouette lies
# along the cut: measured 0.978-0.980 (box), 0.991-0.993 over the image, about 120 pixels
# more surface, with opaque and translucent surfaces alike; 0.991-0.998 (box) from the
# other cameras. Its bar is under that.
ISO_VALUE = 160.0
# The sum is a collective operation, so every rank must render the volume in every frame:
# this close view of the z >= 4 end leaves the pieces nearer z = -10 outside the view
# frustum, where VTK's frustum culler would skip their rank's volume (and the sum would
# wait for it forever) unless every rank culls alike (the mapper reports the whole volume's
# bounds). Additive only.
CLOSE = {"bounds": [-10.0, 10.0, -10.0, 10.0, 4.0, 10.0], "direction": [1.0, 0.2, 0.1],
         "zoom": 3.0}


def cameras(blend):
    """The cameras a blend mode is drawn from: name -> set_camera's bounds and keywords."""
    views = {cam: (BOUNDS, {"direction": d}) for cam, d in CAMERAS.items()}
    if blend == "Additive":
        views["close"] = (CLOSE["bounds"], {"direction": CLOSE["direction"],
                                            "zoom": CLOSE["zoom"]})
    return views

# Volumetric shadows across ranks: each rank traces its piece alone (light is not carried
# between pieces), so the image is measured against serial and reported, not held to a bar.
GI = {"Shade": 1, "VolumetricScatteringBlending": 2.0, "GlobalIlluminationReach": 0.5}
GI_CAMERA = "oblique"
# Path tracing across ranks, likewise measured and reported: paths per pixel of the image.
PATH_SPP = 16

# A label map from an array of the dataset (Mask Array, Label Colors): label 1 (green) where
# RTData > 200, label 2 (yellow) where RTData < 110, the rest unlabelled. Under MPI each rank
# masks its piece with its piece of the array.
LABELS = ("numpy.where(inputs[0].PointData['RTData'] > 200.0, 1, "
          "numpy.where(inputs[0].PointData['RTData'] < 110.0, 2, 0))")
LABEL_COLORS = [1, 0.1, 0.9, 0.2, 0.6, 2, 1.0, 0.9, 0.1, 0.3]
LABEL_CAMERA = "oblique"

# A 2D transfer function set through the representation's properties (Use 2D Transfer
# Function, Transfer Function 2D with two boxes of ParaView's editor), drawn by "Ferrovol
# Volume" and by ParaView's "Volume". Serial, against Volume: 0.9869 / 31.67 dB measured (the
# volume box), where the mappers' samples differ along the box's faces and the wavelet's
# slabs, which the table's per-sample opacity shows more than the 1D functions do, and where
# ferrovol clamps the table to [0, 1]: both mappers resize ParaView's 10x10 table with
# vtkImageResize, whose windowed sinc rings past 1 at the boxes' edges; VTK keeps the
# overshoot (colour above opacity), which IceT's 8-bit "over" wraps under MPI into dark
# blotches in Volume's composited image (0.92 / 19 dB from its serial image). Ferrovol's
# composited image is its serial one (the whole's ranges, a clamped table): measured 0.9995
# / 51.7 dB (box), held to the other modes' bar; Volume's is reported. The floors sit under
# what was measured.
TF2D_SERIAL = (0.975, 30.0)
# The range the 2D transfer function's image spans: RTData's over the whole Wavelet (x) by
# the boxes' gradient axis (y). ParaView rescales a 2D transfer function to the data range
# it knows, which under pvbatch --symmetric is each rank's own piece's.
TF2D_RANGE = [37.35310363769531, 276.8288269042969, 0.0, 1.0]
TF2D_BOXES = [150.0, 0.0, 60.0, 0.6, 1.0, 0.2, 0.1, 0.6, 70.0, 0.3, 70.0, 0.7, 0.1, 0.4, 1.0, 0.5]
TF2D_CAMERA = "oblique"

T.load_plugin(globals())


def path_trace(view, disp, tag):
    """The path-traced image (PATH_SPP paths per pixel) from GI_CAMERA, then ray casting
    again: each rank traces its piece alone, so light stops at the cut (measured)."""
    disp.FerrovolRenderMode = "Path Trace"
    disp.FerrovolSamplesPerPixel = PATH_SPP
    img, _, _ = shot(view, "mpi-%s-pathtrace" % tag, GI_CAMERA)
    disp.FerrovolRenderMode = "Ray Cast"
    return img


def set_gi(disp, on):
    """Volumetric shadows on (GI's settings) or off (the representation's defaults)."""
    for name, value in GI.items():
        setattr(disp, name, value if on else 0)


def setup(view, source, rep="Ferrovol Volume"):
    disp = Show(source, view)
    T.color_by(disp, "RTData", rgb_points=RGB, opacity_points=OPACITY)
    disp.ScalarOpacityUnitDistance = 2.0
    disp.IsosurfaceValues = [ISO_VALUE]
    disp.Representation = rep
    return disp


def show_labels(view, source):
    """The source with a label array, shown with a label map of it."""
    calc = PythonCalculator(Input=source)
    calc.Expression = LABELS
    calc.ArrayName = "labels"
    disp = setup(view, calc)
    disp.FerrovolMaskArray = "labels"
    disp.FerrovolMaskType = "Label Map"
    disp.FerrovolLabelColors = LABEL_COLORS
    return calc, disp


def show_tf2d(view, disp):
    """disp drawn through a 2D transfer function; returns Volume's and ferrovol's images."""
    tf2d = GetTransferFunction2D("RTData")
    tf2d.Boxes = TF2D_BOXES
    # (the whole Wavelet's range: under --symmetric each rank would span its own piece's)
    tf2d.RescaleTransferFunction(*TF2D_RANGE)
    tf2d.Build()
    disp.TransferFunction2D = tf2d
    disp.UseTransfer2D = 1
    imgs = {}
    for rep in ("Volume", "Ferrovol Volume"):
        disp.Representation = rep
        Render(view)
        tag = "vtk" if rep == "Volume" else "ferrovol"
        imgs[rep] = T.screenshot(view, "mpi-%s-tf2d-%s" % (
            "serial" if T.nranks() == 1 else "n%d" % T.nranks(), tag))[0]
    disp.UseTransfer2D = 0
    disp.Representation = "Ferrovol Volume"
    return imgs


def shot(view, name, camera):
    """T.screenshot of the view from CAMERAS[camera] (over BOUNDS), written as
    <name>-<camera>."""
    T.set_camera(view, BOUNDS, direction=CAMERAS[camera])
    Render(view)
    return T.screenshot(view, "%s-%s" % (name, camera))


def serial_image(name):
    """On rank 0, the serial run's image mpi-serial-<name>.png where that run wrote it;
    None otherwise."""
    path = os.path.join(T.OUT_DIR, "mpi-serial-%s.png" % name)
    return T.read_png(path) if T.rank() == 0 and os.path.exists(path) else None


def ref_path(cam, blend=None):
    tag = ("-" + blend.split()[0].lower()) if blend else ""
    return os.path.join(T.OUT_DIR, "mpi-serial%s-%s.png" % (tag, cam))


def empty_pieces(view, failures):
    """Additive on a Wavelet of one cell, which leaves every rank but one an empty piece:
    ParaView then skips those ranks' mappers (no scalars), so the ranks must not start the
    additive sum (a collective operation) that they would never join: the render ends and
    the rank with the cell draws it."""
    tiny = Wavelet()
    tiny.WholeExtent = [0, 1, 0, 1, 0, 1]
    disp = setup(view, tiny)
    disp.FerrovolBlendMode = "Additive"
    T.set_camera(view, [0.0, 1.0, 0.0, 1.0, 0.0, 1.0], direction=CAMERAS["oblique"])
    Render(view)
    img, _, _ = T.screenshot(view, "mpi-n%d-additive-empty-pieces" % T.nranks())
    points = tiny.GetClientSideObject().GetOutputDataObject(0).GetNumberOfPoints()
    T.print_in_rank_order("  rank %d/%d: %d points of the one-cell Wavelet"
                          % (T.rank(), T.nranks(), points))
    Hide(tiny, view)
    if T.rank() == 0:
        drawn = T.coverage(img)
        T.log("  additive with empty pieces: the render ends, %.3f of the frame drawn" % drawn)
        if drawn < 0.05:
            failures.append("additive with empty pieces: %.3f of the frame drawn" % drawn)


def make_view():
    """The view, without FXAA: ParaView smooths the composited image under MPI (not the
    serial one), which these comparisons of the compositing itself would count."""
    view = T.make_view(SIZE)
    view.UseFXAA = 0
    return view


def serial():
    view = make_view()
    src = Wavelet()
    src.WholeExtent = EXTENT
    disp = setup(view, src)
    bounds = BOUNDS
    for blend in [None] + list(BLENDS):
        disp.FerrovolBlendMode = blend or "Follow Blend Mode"
        for cam, (box, kw) in cameras(blend).items():
            T.set_camera(view, box, **kw)
            Render(view)
            name = os.path.splitext(os.path.basename(ref_path(cam, blend)))[0]
            img, path, _ = T.screenshot(view, name)
            T.log("  serial reference %-17s %-8s %s" % (blend or "Composite", cam, path))
    disp.FerrovolBlendMode = "Follow Blend Mode"
    set_gi(disp, True)
    shot(view, "mpi-serial-volumetric", GI_CAMERA)
    set_gi(disp, False)
    path_trace(view, disp, "serial")
    failures = []
    T.set_camera(view, bounds, direction=CAMERAS[TF2D_CAMERA])
    imgs = show_tf2d(view, disp)
    T.compare("2D transfer function vs Volume", imgs["Ferrovol Volume"], imgs["Volume"],
              *TF2D_SERIAL, failures)
    Hide(src, view)

    # The label map: the labels' colours where they are; Mask Blend Factor 0 is the
    # unlabelled image; a binary mask of the same array draws less.
    calc, ldisp = show_labels(view, src)
    img, path, _ = shot(view, "mpi-serial-labels", LABEL_CAMERA)
    rgb = img[..., :3].astype(float)
    # (the colour map has no green: the unlabelled image has no such pixel)
    green = int((rgb[..., 1] - np.maximum(rgb[..., 0], rgb[..., 2]) > 15).sum())
    yellow = int(((rgb[..., 0] > 2 * rgb[..., 2]) & (rgb[..., 1] > 2 * rgb[..., 2])
                  & (rgb[..., 1] > 0.6 * rgb[..., 0])).sum())
    T.log("  serial label map: %d green, %d yellow pixels (%s)" % (green, yellow, path))
    if green < 1000 or yellow < 1000:
        failures.append("label map: %d green, %d yellow pixels (want 1000 each)"
                        % (green, yellow))
    ldisp.FerrovolMaskBlendFactor = 0.0
    Render(view)
    img0, _, _ = T.screenshot(view, "mpi-serial-labels-factor0")
    T.compare("label map, blend factor 0, vs unlabelled", img0,
              T.read_png(ref_path(LABEL_CAMERA)), 0.999, 50.0, failures)
    ldisp.FerrovolMaskBlendFactor = 1.0
    ldisp.FerrovolMaskType = "Binary"
    Render(view)
    imgb, _, _ = T.screenshot(view, "mpi-serial-binary-mask")
    drawn = [T.coverage(i) for i in (img0, imgb)]
    T.log("  binary mask: %.3f of the frame drawn, %.3f unmasked" % (drawn[1], drawn[0]))
    if not drawn[1] < 0.8 * drawn[0]:
        failures.append("binary mask: %.3f of the frame drawn, unmasked %.3f" % (drawn[1], drawn[0]))
    Hide(calc, view)

    # Ordering matters: render the halves z <= 0 and z >= 0 (what two ranks hold) alone,
    # over black and over white (colour over black = premultiplied colour, the difference
    # gives alpha), and composite them back to front in both orders.
    halves = []
    for voi in ([-10, 10, -10, 10, -10, 0], [-10, 10, -10, 10, 0, 10]):
        sub = ExtractSubset(Input=src)
        sub.VOI = voi
        halves.append((sub, setup(view, sub)))
        Hide(sub, view)
    for cam in ("front", "back"):
        T.set_camera(view, bounds, direction=CAMERAS[cam])
        layers = []
        for sub, _ in halves:
            Show(sub, view)
            rgba = []
            for bg in ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0)):
                view.Background = list(bg)
                Render(view)
                img, _, _ = T.screenshot(view, "mpi-half")
                rgba.append(img[..., :3].astype(float) / 255)
            Hide(sub, view)
            black, white = rgba
            alpha = np.clip(1 - (white - black).mean(axis=2, keepdims=True), 0, 1)
            layers.append((black, alpha))
        view.Background = list(T.BACKGROUND)
        bg = np.asarray(T.BACKGROUND)
        ref = T.read_png(ref_path(cam))
        # the camera is on the +z side for "front": the z >= 0 half (layers[1]) is nearer.
        near, far = (layers[1], layers[0]) if cam == "front" else (layers[0], layers[1])

        def over(a, b):
            return a[0] + (1 - a[1]) * b[0], a[1] + (1 - a[1]) * b[1]

        for label, (top, bottom) in (("right order", (near, far)), ("wrong order", (far, near))):
            c, a = over(top, bottom)
            img = np.clip(np.round((c + (1 - a) * bg) * 255), 0, 255).astype(np.uint8)
            T.write_png(os.path.join(T.OUT_DIR, "mpi-halves-%s-%s.png" % (
                cam, label.replace(" ", "-"))), img)
            if label == "right order":
                T.compare("halves %s, %s" % (cam, label), img, ref, MIN_SSIM, MIN_PSNR, failures)
            else:
                T.compare("halves %s, %s" % (cam, label), img, ref, MIN_SSIM, MIN_PSNR, failures,
                          expect_fail=True)
    T.finish(failures, "serial references; the order of translucent pieces matters")


def distributed():
    failures = []
    if T.nranks() < 2:
        failures.append("run me with mpiexec -n 2 (or more) pvbatch --symmetric")
        T.finish(failures, "distributed")
        return
    for cam in CAMERAS:
        if T.rank() == 0 and not os.path.exists(ref_path(cam)):
            failures.append("no serial reference %s: run 'pvbatch test_mpi.py serial' first"
                            % ref_path(cam))
    view = make_view()
    src = Wavelet()
    src.WholeExtent = EXTENT
    disp = setup(view, src)
    bounds = BOUNDS
    Render(view)
    local = src.GetClientSideObject().GetOutputDataObject(0)
    ext = local.GetExtent()
    info = T.ferrovol_info(disp)
    # every rank says what it holds and whether ferrovol drew it
    T.print_in_rank_order(
        "  rank %d/%d: piece extent %s (%d points), ferrovol drew: %d, volume uploads: %d"
        % (T.rank(), T.nranks(), list(ext), local.GetNumberOfPoints(),
           info["FerrovolLastRenderDrew"], info["FerrovolVolumeUploadCount"]))
    total = 21 ** 3
    if local.GetNumberOfPoints() >= total:
        failures.append("rank %d holds the whole Wavelet: the data is not distributed" % T.rank())
    if info["FerrovolLastRenderDrew"] != 1:
        failures.append("rank %d: ferrovol did not draw its piece" % T.rank())
    for blend, (min_ssim, min_psnr) in [(None, (MIN_SSIM, MIN_PSNR))] + list(BLENDS.items()):
        disp.FerrovolBlendMode = blend or "Follow Blend Mode"
        tag = ("-" + blend.split()[0].lower()) if blend else ""
        for cam, (box, kw) in cameras(blend).items():
            T.set_camera(view, box, **kw)
            Render(view)
            img, _, dt = T.screenshot(view, "mpi-n%d%s-%s" % (T.nranks(), tag, cam))
            if T.rank() == 0 and os.path.exists(ref_path(cam, blend)):
                ref = T.read_png(ref_path(cam, blend))
                T.compare("mpi -n %d %s %s vs serial" % (T.nranks(), blend or "Composite", cam),
                          img, ref, min_ssim, min_psnr, failures)
    disp.FerrovolBlendMode = "Follow Blend Mode"
    set_gi(disp, True)
    img, _, _ = shot(view, "mpi-n%d-volumetric" % T.nranks(), GI_CAMERA)
    gi_ref = serial_image("volumetric-%s" % GI_CAMERA)
    if gi_ref is not None:
        T.compare("mpi -n %d volumetric shadows (measured)" % T.nranks(), img, gi_ref)
    set_gi(disp, False)
    img = path_trace(view, disp, "n%d" % T.nranks())
    pt_ref = serial_image("pathtrace-%s" % GI_CAMERA)
    if pt_ref is not None:
        # (the ranks' paths differ from the serial ones: 4x4 means leave the bias, not noise)
        def means(a):
            h, w = (a.shape[0] // 4) * 4, (a.shape[1] // 4) * 4
            b = a[:h, :w, :3].astype(float).reshape(h // 4, 4, w // 4, 4, 3).mean(axis=(1, 3))
            return np.round(b).astype(np.uint8)

        T.compare("mpi -n %d path tracing, 4x4 means (measured)" % T.nranks(), means(img),
                  means(pt_ref))
    T.set_camera(view, bounds, direction=CAMERAS[TF2D_CAMERA])
    imgs = show_tf2d(view, disp)
    tf2d_ref = os.path.join(T.OUT_DIR, "mpi-serial-tf2d-ferrovol.png")
    if T.rank() == 0 and os.path.exists(tf2d_ref):
        T.compare("mpi -n %d 2D transfer function vs serial" % T.nranks(),
                  imgs["Ferrovol Volume"], T.read_png(tf2d_ref), MIN_SSIM, MIN_PSNR, failures)
        T.compare("mpi -n %d Volume's 2D transfer function vs serial (measured)"
                  % T.nranks(), imgs["Volume"], T.read_png(tf2d_ref.replace("ferrovol", "vtk")))
    Hide(src, view)
    show_labels(view, src)
    img, _, _ = shot(view, "mpi-n%d-labels" % T.nranks(), LABEL_CAMERA)
    labels_ref = serial_image("labels-%s" % LABEL_CAMERA)
    if labels_ref is not None:
        T.compare("mpi -n %d label map vs serial" % T.nranks(), img, labels_ref, MIN_SSIM,
                  MIN_PSNR, failures)
    empty_pieces(view, failures)
    # Rank-local failures are printed by their ranks; rank 0 decides the exit status.
    if failures and T.rank() != 0:
        print("FAIL rank %d: %s" % (T.rank(), "; ".join(failures)), flush=True)
        os._exit(1)
    T.finish(failures, "distributed: mpiexec -n %d matches serial" % T.nranks())


if MODE == "serial":
    T.log("MPI test, serial part: references and the ordering control (%dx%d)" % SIZE)
    serial()
else:
    T.log("MPI test, %d ranks (%dx%d)" % (T.nranks(), SIZE[0], SIZE[1]))
    distributed()
