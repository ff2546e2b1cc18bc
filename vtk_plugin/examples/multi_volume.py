#!/usr/bin/python3
"""Two volumes intermixed per sample with vtkFerroVolumeMapper, set up as VTK's
vtkMultiVolume sets up vtkGPUVolumeRayCastMapper: one mapper with an input per port, one
vtkVolume per port giving that input's placement (its matrix) and its vtkVolumeProperty,
and the vtkMultiVolume in the renderer. Each ray samples both volumes at the same points
and composites them there, in port order, so each shows through the other where they
overlap. Writes a PNG.

    . build/env.sh
    /usr/bin/python3 vtk_plugin/examples/multi_volume.py --out multi.png [--vtk vtk.png]

--vtk also renders the scene with vtkGPUVolumeRayCastMapper for comparison. Needs an X
display (e.g. scripts/with-xvfb.sh) for VTK's OpenGL.
"""
import argparse

import vtk
import ferrovol
import volume_scene
from volume_scene import offscreen_window, write_png


def volume_property(colors, opacities, unit_distance):
    """volume_scene.volume_property, linear, with its opacity's unit distance."""
    prop = volume_scene.volume_property(colors, opacities)
    prop.SetScalarOpacityUnitDistance(unit_distance)
    prop.SetInterpolationTypeToLinear()
    return prop


def wavelet(extent):
    src = vtk.vtkRTAnalyticSource()
    src.SetWholeExtent(-extent, extent, -extent, extent, -extent, extent)
    # (updated now: the vtkMultiVolume's bounds, which ResetCamera reads, are its inputs')
    src.Update()
    return src


def render(mapper, size, out):
    # Port 0: VTK's wavelet in blue to red, where it stands.
    big = wavelet(40)
    mapper.SetInputConnection(0, big.GetOutputPort())
    first = vtk.vtkVolume()
    first.SetProperty(volume_property(
        [(37.0, 0.2, 0.3, 1.0), (160.0, 0.9, 0.9, 0.9), (277.0, 0.7, 0.0, 0.15)],
        [(37.0, 0.0), (277.0, 0.15)], 2.0))
    # Port 1: a smaller wavelet in orange, grown, turned and moved half out of the first.
    small = wavelet(10)
    mapper.SetInputConnection(1, small.GetOutputPort())
    second = vtk.vtkVolume()
    second.SetProperty(volume_property(
        [(37.0, 1.0, 0.5, 0.0), (277.0, 1.0, 0.9, 0.3)],
        [(37.0, 0.0), (150.0, 0.0), (277.0, 0.6)], 1.0))
    second.SetScale(2.0, 2.0, 2.0)
    second.RotateZ(30.0)
    second.RotateX(20.0)
    second.SetPosition(35.0, 5.0, 0.0)
    # The vtkMultiVolume draws both through the one mapper (ports 0 and 1).
    multi = vtk.vtkMultiVolume()
    multi.SetMapper(mapper)
    multi.SetVolume(first, 0)
    multi.SetVolume(second, 1)

    ren = vtk.vtkRenderer()
    ren.AddVolume(multi)
    win = offscreen_window(ren, size)
    ren.ResetCamera()
    cam = ren.GetActiveCamera()
    cam.Azimuth(30.0)
    cam.Elevation(20.0)
    cam.OrthogonalizeViewUp()
    ren.ResetCameraClippingRange()
    win.Render()
    write_png(win, out)
    win.Finalize()
    print("wrote", out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="multi_volume.png")
    ap.add_argument("--vtk", help="also render with vtkGPUVolumeRayCastMapper into this PNG")
    ap.add_argument("--size", type=int, default=400)
    args = ap.parse_args()
    render(ferrovol.vtkFerroVolumeMapper(), args.size, args.out)
    if args.vtk:
        render(vtk.vtkGPUVolumeRayCastMapper(), args.size, args.vtk)


if __name__ == "__main__":
    main()
