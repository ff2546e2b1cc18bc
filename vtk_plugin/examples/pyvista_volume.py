"""PyVista with ferrovol: Plotter.add_volume as usual, then one call, ferrovol.use(actor),
puts vtkFerroVolumeMapper under the volume it returns. With --path-trace the volume is path
traced, and in the interactive window the image refines by itself while the camera rests
(press q to close). With --out, renders off screen and writes a PNG.

    pip install dist/ferrovol-*.whl pyvista        (make wheel)
    python vtk_plugin/examples/pyvista_volume.py [--path-trace] [--out volume.png]
"""
import argparse

import pyvista as pv
from pyvista import examples

import ferrovol


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--path-trace", action="store_true", help="path trace the volume")
    ap.add_argument("--out", help="render off screen to this PNG instead of a window")
    args = ap.parse_args()

    grid = examples.load_frog_tissues()
    plotter = pv.Plotter(off_screen=bool(args.out), window_size=(600, 500))
    actor = plotter.add_volume(grid, cmap="bone", opacity="sigmoid_5", shade=True)
    ferrovol.use(actor, path_trace=args.path_trace)
    plotter.camera_position = "xz"
    plotter.camera.azimuth = 30.0
    plotter.camera.elevation = 15.0
    plotter.show(screenshot=args.out)


if __name__ == "__main__":
    main()
