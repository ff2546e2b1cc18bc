#!/usr/bin/python3
"""Renders a CT volume with vtkFerroVolumeMapper (ferrovol) and writes a PNG.

Uses build/data/cranium.vti, an int16 skull CT made by scripts/fetch-data.sh, with a CT
bone transfer function; when the file is missing it says so and renders VTK's wavelet.

    . build/env.sh
    /usr/bin/python3 vtk_plugin/examples/cranium.py --out cranium.png [--vtk vtk.png]

--vtk also renders the same scene with vtkGPUVolumeRayCastMapper for comparison.
Needs an X display (e.g. scripts/with-xvfb.sh) for VTK's OpenGL.
"""
import argparse
import os
import sys
import time

import vtk
import ferrovol
from volume_scene import offscreen_window, volume_property, write_png

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_INPUT = os.path.join(
    os.environ.get("FERROVOL_DATA_DIR", os.path.join(HERE, "..", "..", "build", "data")),
    "cranium.vti")


def ct_bone_property(spacing):
    """CT bone in Hounsfield units: soft tissue transparent, bone ivory and opaque."""
    prop = volume_property(
        [(-3024, 0.0, 0.0, 0.0), (-16.4458, 0.729412, 0.254902, 0.301961),
         (641.385, 0.905882, 0.815686, 0.552941), (3071, 1.0, 1.0, 1.0)],
        [(-3024, 0.0), (-16.4458, 0.0), (641.385, 0.715686), (3071, 0.705882)])
    prop.SetScalarOpacityUnitDistance(sum(spacing) / 3.0)
    return prop


def wavelet_property():
    """VTK's GPU ray cast benchmark transfer function for its wavelet."""
    return volume_property(
        [(37.3531, 0.2, 0.29, 1.0), (157.091, 0.87, 0.87, 0.87), (276.829, 0.7, 0.015, 0.15)],
        [(37.3531, 0.0), (276.829, 1.0)])


def render(mapper, port, prop, have_ct, size, out):
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOn()
    prop.SetAmbient(0.2)
    prop.SetDiffuse(0.9)
    prop.SetSpecular(0.3)
    prop.SetSpecularPower(15.0)
    mapper.SetInputConnection(port)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren = vtk.vtkRenderer()
    ren.AddVolume(volume)
    ren.SetBackground(0.1, 0.1, 0.12)
    win = offscreen_window(ren, size)
    ren.ResetCamera()
    cam = ren.GetActiveCamera()
    if have_ct:
        # The face looks toward -y: view it from the front, head up (+z).
        cam.Elevation(-90.0)
        cam.SetViewUp(0.0, 0.0, 1.0)
        cam.OrthogonalizeViewUp()
        ren.ResetCamera()
        cam.Zoom(1.3)
    else:
        cam.Azimuth(30.0)
        cam.Elevation(20.0)
    t0 = time.perf_counter()
    win.Render()
    ms = 1000.0 * (time.perf_counter() - t0)
    write_png(win, out)
    return ms


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--input", default=DEFAULT_INPUT, help="a .vti volume (default: %(default)s)")
    p.add_argument("--out", default="cranium-ferrovol.png", help="PNG to write")
    p.add_argument("--vtk", metavar="PNG", help="also render with vtkGPUVolumeRayCastMapper")
    p.add_argument("--size", type=int, default=512, help="window size in pixels")
    args = p.parse_args(argv)

    have_ct = os.path.exists(args.input)
    if have_ct:
        reader = vtk.vtkXMLImageDataReader()
        reader.SetFileName(args.input)
        reader.Update()
        port = reader.GetOutputPort()
        make_prop = lambda: ct_bone_property(reader.GetOutput().GetSpacing())  # noqa: E731
    else:
        print("cranium.py: %s not found (run scripts/fetch-data.sh to make it); rendering "
              "VTK's wavelet instead." % args.input)
        source = vtk.vtkRTAnalyticSource()
        source.SetWholeExtent(-63, 64, -63, 64, -63, 64)
        port = source.GetOutputPort()
        make_prop = wavelet_property

    mapper = ferrovol.vtkFerroVolumeMapper()
    ms = render(mapper, port, make_prop(), have_ct, args.size, args.out)
    if not mapper.GetLastRenderDrew():
        print("cranium.py: the volume was not drawn (see the errors above)", file=sys.stderr)
        return 1
    print("cranium.py: %s on %s: first frame %.0f ms (uploads included), wrote %s"
          % (os.path.basename(args.input) if have_ct else "wavelet",
             mapper.GetAdapterDescription(), ms, args.out))
    if args.vtk:
        ms = render(vtk.vtkGPUVolumeRayCastMapper(), port, make_prop(), have_ct, args.size,
                    args.vtk)
        print("cranium.py: vtkGPUVolumeRayCastMapper: first frame %.0f ms, wrote %s"
              % (ms, args.vtk))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
