"""(a) The Wavelet source rendered with "Ferrovol Volume" and with ParaView's own "Volume"
(vtkMultiBlockVolumeMapper -> vtkSmartVolumeMapper -> vtkGPUVolumeRayCastMapper on llvmpipe),
same view, same transfer functions: composite, composite with Shade, maximum, minimum and
average intensity, additive; and a 3-component array by magnitude and by component.

    pvbatch paraview/tests/test_wavelet.py        (after . build/env.sh; make paraview-test)
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fvtest as T  # noqa: E402
from paraview.simple import Wavelet, Gradient, Show, Hide, Render  # noqa: E402

T.load_plugin(globals())

# Thresholds (SSIM and PSNR on the volume's screen box), set after looking at the images in
# build/paraview-test. The two ray casters sample the same trilinear field at different
# positions (VTK's rays start on the box's near face, ferrovol's step from its own entry
# point: ferrovol shows faint slicing rings on the cube's faces that VTK does not), so small
# differences in the translucent interior remain: measured SSIM 0.93-0.99, PSNR 32.7-47.4 dB.
# Smooth translucent images keep SSIM high even when wrong; PSNR is the sharper measure here:
# half the opacity measured 17.5 dB (SSIM 0.929), a reversed colour map or half the unit
# distance 18-20 dB (SSIM 0.92-0.94 averaged over R, G and B, the SSIM these tests used
# before tests/ferrovol_testing), and the run below checks that half the opacity fails the
# composite thresholds.
CASES = [
    # name, shade, blend (vtkVolumeMapper enum), min SSIM, min PSNR
    ("composite", 0, 0, 0.96, 33.0),
    ("composite-shade", 1, 0, 0.95, 32.0),
    # MIP and MinIP on this 21^3 volume decide single samples near the faces. When ferrovol
    # adopted VTK 9.2's sample lattice (tests/regression/SAMPLING.md: first sample one step
    # in), agreement with plain VTK rose across tests/regression, but against ParaView's
    # Volume here MIP went 45.8 -> 39.2 dB and MinIP 37.3 -> 32.7 dB (box): not explained
    # yet (ParaView's vtkSmartVolumeMapper path may place samples differently).
    ("mip", 0, 1, 0.975, 38.0),
    # ParaView's Volume offers none of these three in its BlendMode list; its mapper has
    # them. Average and additive come out grey in both (VTK maps neither through the
    # colour table). The MinIP "wedge" near the cube's back corner comes from where each
    # ray's last sample falls before the back face; VTK's plain GPU mapper shows the same
    # at this view (tests/regression/SAMPLING.md).
    ("minip", 0, 2, 0.92, 31.5),
    ("average", 0, 3, 0.98, 42.0),
    ("additive", 0, 4, 0.96, 34.0),
]

view = T.make_view((400, 400))
src = Wavelet()
src.WholeExtent = [-10, 10, -10, 10, -10, 10]
disp = Show(src, view)
lut, pwf = T.color_by(
    disp, "RTData",
    rgb_points=[37.35, 0.23, 0.30, 0.75, 157.1, 0.87, 0.87, 0.87, 276.8, 0.71, 0.02, 0.15],
    opacity_points=[37.35, 0.0, 0.5, 0.0, 276.8, 0.8, 0.5, 0.0])
disp.ScalarOpacityUnitDistance = 3.0
T.set_camera(view, src.GetDataInformation().GetBounds(), azimuth=30, elevation=20)

failures = []
T.log("Wavelet 21^3, 400x400: Ferrovol Volume vs ParaView Volume")
for name, shade, blend, min_ssim, min_psnr in CASES:
    disp.Shade = shade
    imgs = T.render_both(view, disp, blend, "wavelet-" + name, failures)
    T.compare("wavelet-%s" % name, imgs["Ferrovol Volume"], imgs["Volume"],
              min_ssim, min_psnr, failures)
disp.GetProperty("BlendMode").SetElement(0, 0)

# The thresholds must be able to fail: half the opacity has to fall under the composite ones.
disp.Shade = 0
ref = T.read_png(os.path.join(T.OUT_DIR, "wavelet-composite-vtk.png"))
pwf.Points = [37.35, 0.0, 0.5, 0.0, 276.8, 0.4, 0.5, 0.0]
Render(view)
half, _, _ = T.screenshot(view, "wavelet-half-opacity-ferrovol")
T.compare("control: half opacity", half, ref, CASES[0][3], CASES[0][4], failures,
          expect_fail=True)
# A 3-component array (the Wavelet's gradient) coloured by its magnitude and by its X
# component: "Volume" hands the mapper one component (vtkSmartVolumeMapper's VectorMode),
# "Ferrovol Volume" does the same in the representation. Measured 0.906 / 30.9 dB and
# 0.919 / 29.7 dB (the gradient's sharp faces show ferrovol's slicing rings); before the
# representation converted, ferrovol drew the three components independently, nearly
# black (4 dB in a similar view).
Hide(src, view)
grad = Gradient(Input=src)
grad.ScalarArray = ["POINTS", "RTData"]
gdisp = Show(grad, view)
gdisp.ScalarOpacityUnitDistance = 3.0
for comp, min_ssim, min_psnr in (("Magnitude", 0.90, 28.0), ("X", 0.91, 27.0)):
    T.ColorBy(gdisp, ("POINTS", "Gradient", comp))
    imgs = {}
    for rep in ("Volume", "Ferrovol Volume"):
        gdisp.Representation = rep
        Render(view)
        imgs[rep], _, _ = T.screenshot(view, "wavelet-gradient-%s-%s" % (
            comp.lower(), "ferrovol" if rep != "Volume" else "vtk"))
    T.compare("wavelet-gradient-%s" % comp.lower(), imgs["Ferrovol Volume"], imgs["Volume"],
              min_ssim, min_psnr, failures)

T.log("  ferrovol: %(FerrovolVersion)s on %(FerrovolAdapter)s, output path %(FerrovolOutputPath)s"
      % T.ferrovol_info(gdisp))
T.finish(failures, "wavelet: Ferrovol Volume matches Volume")
