"""(h) Translucent geometry inside the volume, as ParaView renders it by default: depth
peeling with DepthPeelingForVolumes on, so vtkDualDepthPeelingPass peels the volume with the
geometry. A translucent sphere inside the Wavelet must show through the volume in front of
it, with "Ferrovol Volume" as with ParaView's own "Volume"; without volume peeling both
composite the volume over the sphere.

    pvbatch paraview/tests/test_translucent.py
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fvtest as T  # noqa: E402
from paraview.simple import Render, Show, Sphere, Wavelet  # noqa: E402

T.load_plugin(globals())

# VTK's own image changes under peeling (its rays start at the layers' depths, a sample
# lattice of its own), which bounds the agreement: measured in the VTK suite 36.9 dB
# (composite) between the two peeled images; the sphere's pixels within 2.6/255 on average.
MIN_SSIM, MIN_PSNR = 0.95, 30.0

src = Wavelet()
view = T.make_view((256, 256))
disp = Show(src, view)
T.color_by(disp, "RTData",
           rgb_points=[37.35, 0.23, 0.30, 0.75, 157.1, 0.87, 0.87, 0.87, 276.8, 0.71, 0.02, 0.15],
           opacity_points=[37.35, 0.0, 0.5, 0.0, 276.8, 0.4, 0.5, 0.0])
disp.ScalarOpacityUnitDistance = 3.0
ball = Sphere(Center=[4.0, -2.0, 6.0], Radius=5.0, ThetaResolution=32, PhiResolution=32)
ball_disp = Show(ball, view)
ball_disp.DiffuseColor = [1.0, 0.3, 0.3]
ball_disp.AmbientColor = [1.0, 0.3, 0.3]
ball_disp.Opacity = 0.5
T.set_camera(view, src.GetDataInformation().GetBounds(), azimuth=30, elevation=20)
failures = []
T.log("  view: DepthPeeling %d, DepthPeelingForVolumes %d"
      % (view.DepthPeeling, view.DepthPeelingForVolumes))
if not (view.DepthPeeling and view.DepthPeelingForVolumes):
    failures.append("ParaView's defaults changed: DepthPeeling %d, DepthPeelingForVolumes %d"
                    % (view.DepthPeeling, view.DepthPeelingForVolumes))
imgs = {}
for peel in (1, 0):
    view.DepthPeelingForVolumes = peel
    for rep in ("Volume", "Ferrovol Volume"):
        disp.Representation = rep
        Render(view)
        name = "translucent-%s-%s" % ("peeled" if peel else "over",
                                      "ferrovol" if rep != "Volume" else "vtk")
        imgs[(peel, rep)], _, dt = T.screenshot(view, name)
        T.log("  %-40s %.2f s, %.1f%% covered" % (name, dt, 100 * T.coverage(imgs[(peel, rep)])))
    info = T.ferrovol_info(disp)
    if info["FerrovolLastRenderDrew"] != 1:
        failures.append("peeling %d: the ferrovol mapper did not draw (%s)" % (peel, info))
if T.rank() == 0:
    T.compare("translucent-peeled", imgs[(1, "Ferrovol Volume")], imgs[(1, "Volume")],
              MIN_SSIM, MIN_PSNR, failures)
    T.compare("translucent-over", imgs[(0, "Ferrovol Volume")], imgs[(0, "Volume")],
              MIN_SSIM, MIN_PSNR, failures)
    # the sphere shows through the volume only when it is peeled
    T.compare("translucent-ferrovol-peeled-vs-over", imgs[(1, "Ferrovol Volume")],
              imgs[(0, "Ferrovol Volume")], MIN_SSIM, MIN_PSNR, failures, expect_fail=True)
T.finish(failures, "translucent geometry with Ferrovol Volume")
