"""PyVista with ferrovol: Plotter.add_volume as usual, then one call, ferrovol.use(actor),
puts vtkFerroVolumeMapper under the volume it returns. With --path-trace the volume is path
traced, and in the interactive window the image refines by itself while the camera rests
(press q to close). With --out, renders off screen and writes a PNG.

    pip install dist/ferrovol-*.whl pyvista        (make wheel)
    python vtk_plugin/examples/pyvista_volume.py [VOLUME] [--path-trace] [--out volume.png]

VOLUME: any image file PyVista reads (.vti, .nrrd, .mha …), such as build/data/cranium.vti
(scripts/fetch-data.sh); VTK's wavelet when left out.
"""
import argparse

import pyvista as pv

import ferrovol


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("volume", nargs="?", help="an image file (default: VTK's wavelet)")
    ap.add_argument("--path-trace", action="store_true", help="path trace the volume")
    ap.add_argument("--out", help="render off screen to this PNG instead of a window")
    args = ap.parse_args()

    grid = pv.read(args.volume) if args.volume else pv.Wavelet(extent=(-40, 40) * 3)
    plotter = pv.Plotter(off_screen=bool(args.out), window_size=(600, 500))
    plotter.set_background("black")
    actor = plotter.add_volume(grid, cmap="magma", opacity="sigmoid", shade=True,
                               show_scalar_bar=False)
    ferrovol.use(actor, path_trace=args.path_trace)
    plotter.view_isometric()
    plotter.show(screenshot=args.out)


if __name__ == "__main__":
    main()
