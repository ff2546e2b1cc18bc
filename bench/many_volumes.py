"""Many volumes in one VTK window: the time to the first frame and to the next one, for
vtkFerroVolumeMapper and vtkGPUVolumeRayCastMapper, alternating. A multiblock dataset's
blocks, an AMR hierarchy or VTK's own test grids put many volumes in one window; each
ferrovol mapper has a renderer of its own, and the pipelines are the device's, so only the
first mapper compiles them.

    . build/env.sh && scripts/with-xvfb.sh /usr/bin/python3 bench/many_volumes.py [--grid 5]
"""
import argparse
import os
import sys
import time

import vtk

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "vtk_plugin", "tests"))
import ferrovol  # noqa: E402
import fvtest  # noqa: E402


def scene(make_mapper, grid, size):
    """grid × grid wavelets (21³ points each) side by side in one window."""
    renderer = vtk.vtkRenderer()
    prop = fvtest.tf_property(interpolation="linear")
    keep = []
    for i in range(grid):
        for j in range(grid):
            src = fvtest.wavelet(10)
            mapper = make_mapper()
            mapper.SetInputConnection(src.GetOutputPort())
            volume = vtk.vtkVolume()
            volume.SetMapper(mapper)
            volume.SetProperty(prop)
            volume.SetPosition(i * 24.0, j * 24.0, 0.0)
            renderer.AddVolume(volume)
            keep.append((src, mapper, volume))
    window = fvtest.new_window()
    window.SetSize(size, size)
    window.AddRenderer(renderer)
    renderer.ResetCamera()
    return window, renderer, keep


def measure(make_mapper, grid, size):
    """(seconds to the first frame, seconds for the next) of a new window."""
    window, renderer, keep = scene(make_mapper, grid, size)
    t = time.perf_counter()
    window.Render()
    first = time.perf_counter() - t
    renderer.GetActiveCamera().Azimuth(10.0)
    t = time.perf_counter()
    window.Render()
    second = time.perf_counter() - t
    window.Finalize()
    del keep
    return first, second


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--grid", type=int, default=5, help="volumes per side (default 5: 25)")
    ap.add_argument("--size", type=int, default=300, help="window size in pixels")
    ap.add_argument("--rounds", type=int, default=2)
    args = ap.parse_args()
    mappers = [("ferrovol", ferrovol.vtkFerroVolumeMapper),
               ("vtkGPUVolumeRayCastMapper", vtk.vtkGPUVolumeRayCastMapper)]
    print(f"{args.grid * args.grid} volumes (21³ wavelets), {args.size}×{args.size} window")
    for r in range(args.rounds):
        for name, make in mappers:
            first, second = measure(make, args.grid, args.size)
            print(f"round {r + 1}  {name:26s} first frame {first:7.3f} s   next frame "
                  f"{second * 1e3:7.1f} ms", flush=True)


if __name__ == "__main__":
    main()
