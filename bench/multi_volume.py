#!/usr/bin/python3
"""Two volumes intermixed per sample (vtkMultiVolume): vtkFerroVolumeMapper against
vtkGPUVolumeRayCastMapper in one run.

The scene of vtk_plugin/examples/multi_volume.py at a benchmark's size: VTK's wavelet
(--extent, default 64: 129^3) on port 0 and a wavelet of a third the extent on port 1,
grown, turned and moved half out of the first, composite, linear, unshaded (--shade: on).
Each mapper draws in its own window; the two alternate for --rounds rounds of --frames
frames, the camera turning a degree per frame, so that machine noise hits both alike.
Prints each mapper's ms/frame (the median over rounds of each round's mean) and ferrovol's
ratio to VTK's.

Needs `. build/env.sh` (the ferrovol Python module) and an X display (scripts/with-xvfb.sh).
"""
import argparse
import os
import statistics
import sys
import time

import vtk
import ferrovol

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "vtk_plugin",
                                "examples"))
from volume_scene import offscreen_window, volume_property  # noqa: E402


def prop(colors, opacities, unit_distance, shade):
    p = volume_property(colors, opacities)
    p.SetScalarOpacityUnitDistance(unit_distance)
    p.SetInterpolationTypeToLinear()
    p.SetShade(shade)
    return p


class Scene:
    def __init__(self, mapper, extent, size, shade):
        self.keep = []
        self.multi = vtk.vtkMultiVolume()
        self.multi.SetMapper(mapper)
        small = max(extent // 3, 2)
        ports = [
            (extent, prop([(37.0, 0.2, 0.3, 1.0), (160.0, 0.9, 0.9, 0.9), (277.0, 0.7, 0.0, 0.15)],
                          [(37.0, 0.0), (277.0, 0.15)], 2.0, shade), None),
            (small, prop([(37.0, 1.0, 0.5, 0.0), (277.0, 1.0, 0.9, 0.3)],
                         [(37.0, 0.0), (150.0, 0.0), (277.0, 0.6)], 1.0, shade),
             (2.0, 30.0, 20.0, (0.9 * extent, 0.1 * extent, 0.0))),
        ]
        for port, (e, p, place) in enumerate(ports):
            src = vtk.vtkRTAnalyticSource()
            src.SetWholeExtent(-e, e, -e, e, -e, e)
            src.Update()
            mapper.SetInputConnection(port, src.GetOutputPort())
            vol = vtk.vtkVolume()
            vol.SetProperty(p)
            if place:
                scale, rz, rx, pos = place
                vol.SetScale(scale, scale, scale)
                vol.RotateZ(rz)
                vol.RotateX(rx)
                vol.SetPosition(*pos)
            self.multi.SetVolume(vol, port)
            self.keep += [src, vol]
        self.ren = vtk.vtkRenderer()
        self.ren.AddVolume(self.multi)
        self.win = offscreen_window(self.ren, size)
        self.ren.ResetCamera()
        cam = self.ren.GetActiveCamera()
        cam.Azimuth(30.0)
        cam.Elevation(20.0)
        cam.OrthogonalizeViewUp()
        self.ren.ResetCameraClippingRange()

    def frames(self, n):
        """Mean ms per frame over n frames, the camera turning a degree each."""
        t0 = time.perf_counter()
        for _ in range(n):
            self.ren.GetActiveCamera().Azimuth(1.0)
            self.ren.ResetCameraClippingRange()
            self.win.Render()
        return (time.perf_counter() - t0) * 1e3 / n


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--frames", type=int, default=10)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--extent", type=int, default=64)
    p.add_argument("--shade", action="store_true")
    args = p.parse_args(argv)
    scenes = {"vtk_gpu": Scene(vtk.vtkGPUVolumeRayCastMapper(), args.extent, args.size,
                               args.shade),
              "ferrovol": Scene(ferrovol.vtkFerroVolumeMapper(), args.extent, args.size,
                                args.shade)}
    for s in scenes.values():
        s.frames(2)  # uploads, shader and pipeline builds
    times = {k: [] for k in scenes}
    for _ in range(args.rounds):
        for k, s in scenes.items():
            times[k].append(s.frames(args.frames))
    ms = {k: statistics.median(v) for k, v in times.items()}
    print("# two intermixed wavelets (extent %d and %d), %dx%d, %s, %d rounds x %d frames"
          % (args.extent, max(args.extent // 3, 2), args.size, args.size,
             "shaded" if args.shade else "unshaded", args.rounds, args.frames))
    for k in scenes:
        print("%s ms_per_frame=%.1f" % (k, ms[k]))
    print("ferrovol/vtk_gpu=%.2f" % (ms["ferrovol"] / ms["vtk_gpu"]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
