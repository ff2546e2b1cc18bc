"""Soak test of vtkFerroVolumeMapper: thousands of renders in one VTK window while the camera,
transfer function, blend mode, shading, window size, input data (scalar type, size,
components) and output path change, with the volume's ReleaseGraphicsResources (what VTK
calls when a prop leaves a window) twice a period. Fails on a VTK error, on an image with
nothing drawn (MinIP excepted: its transfer functions make the lowest values transparent),
and when resident memory, ferrovol's device memory or its GPU objects grow: each is
compared at the same point of the schedule (the data, output path and releases repeat
every period, 1000 renders by default), the highest value over the second period against
the highest over the last.

    . build/env.sh && scripts/with-xvfb.sh /usr/bin/python3 vtk_plugin/tests/soak.py \\
        --renders 10000 --csv build/soak/soak.csv --svg docs/img/soak-memory.svg
"""
import argparse
import math
import os
import sys
import time

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

import ferrovol
from fvtest import Errors, image_from_array, new_window

# Within a period of P renders: a new input every P/5 (the five of datasets()), the volume's
# graphics resources released every P/2, the output path switched every P/4.
DATA_PARTS, RELEASE_PARTS, PATH_PARTS = 5, 2, 4
BLEND_MODES = ["Composite", "MaximumIntensity", "MinimumIntensity", "AverageIntensity",
               "Additive", "IsoSurface"]
SIZES = [(96, 96), (128, 100), (150, 120)]


def resident_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def field(shape, phase):
    """A smooth field on [0, 1] of the given [z, y, x] shape: two blobs and a ripple."""
    z, y, x = np.meshgrid(*[np.linspace(-1, 1, n) for n in shape], indexing="ij")
    r1 = (x - 0.3) ** 2 + y ** 2 + (z + 0.2) ** 2
    r2 = (x + 0.4) ** 2 + (y - 0.3) ** 2 + z ** 2
    f = np.exp(-4 * r1) + 0.7 * np.exp(-6 * r2) + 0.15 * np.sin(6 * x + phase) * np.cos(5 * y)
    return (f - f.min()) / (f.max() - f.min())


def datasets():
    """(name, vtkImageData, scalar range, independent components) of every input the soak
    cycles through."""
    out = []
    f = field((32, 32, 32), 0.0)
    out.append(("uint8 32^3", image_from_array((f * 255).astype(np.uint8)), (0, 255), True))
    f = field((24, 40, 32), 1.0)
    out.append(("int16 32x40x24", image_from_array((f * 3000 - 1000).astype(np.int16)),
                (-1000, 2000), True))
    f = field((28, 28, 28), 2.0)
    g = field((28, 28, 28), 3.0)
    two = np.stack([f, g], axis=-1).astype(np.float32)
    out.append(("float32 28^3 x2 independent", image_from_array(two), (0.0, 1.0), True))
    f = field((36, 20, 30), 4.0)
    out.append(("float64 30x20x36", image_from_array(f.astype(np.float64) * 10.0),
                (0.0, 10.0), True))
    f = field((24, 24, 24), 5.0)
    rgba = np.stack([f * 255, (1 - f) * 255, np.full_like(f, 128), f * 255], axis=-1)
    out.append(("uint8 24^3 RGBA dependent", image_from_array(rgba.astype(np.uint8)),
                (0, 255), False))
    return out


def set_transfer_function(prop, components, lo, hi, shift):
    """Colour and opacity over [lo, hi] per component, the opacity ramp moved by shift
    (0-1)."""
    for c in range(components):
        ctf = vtk.vtkColorTransferFunction()
        ctf.AddRGBPoint(lo, 0.1, 0.2 + 0.2 * c, 0.9)
        ctf.AddRGBPoint(lo + 0.5 * (hi - lo), 0.9, 0.8, 0.3)
        ctf.AddRGBPoint(hi, 0.9, 0.1, 0.1)
        otf = vtk.vtkPiecewiseFunction()
        start = lo + (0.2 + 0.3 * shift) * (hi - lo)
        otf.AddPoint(lo, 0.0)
        otf.AddPoint(start, 0.0)
        otf.AddPoint(hi, 0.8)
        prop.SetColor(c, ctf)
        prop.SetScalarOpacity(c, otf)
    prop.GetIsoSurfaceValues().SetNumberOfContours(1)
    prop.GetIsoSurfaceValues().SetValue(0, lo + (0.45 + 0.2 * shift) * (hi - lo))


def svg_plot(path, rows):
    """Two panels against the render count: resident memory and ferrovol's device memory
    (MiB), each the highest value of every 10 renders."""
    w, panel, left = 640, 170, 70
    blocks = rows[: len(rows) // 10 * 10].reshape(-1, 10, rows.shape[1]).max(axis=1)
    renders = int(rows[-1, 0])
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{2 * panel + 30}" '
             'font-family="sans-serif" font-size="12">',
             f'<rect width="{w}" height="{2 * panel + 30}" fill="white"/>']
    for n, (name, color, column) in enumerate((("resident memory", "#1f77b4", 1),
                                               ("ferrovol device memory", "#d62728", 2))):
        values = blocks[:, column] / 2 ** 20
        top = values.max() * 1.15
        y0, y1 = 20 + n * panel, (n + 1) * panel - 10

        def xy(i, v):
            return (left + (w - left - 20) * i / renders, y1 - (y1 - y0) * v / top)

        parts += [f'<line x1="{left}" y1="{y1}" x2="{w - 20}" y2="{y1}" stroke="black"/>',
                  f'<line x1="{left}" y1="{y0}" x2="{left}" y2="{y1}" stroke="black"/>',
                  f'<text x="{left + 10}" y="{y0 + 4}" fill="{color}">{name} (MiB)</text>']
        step = 10 ** math.floor(math.log10(top / 2))
        for k in range(0, int(top / step) + 1, max(1, int(top / step) // 4)):
            _, y = xy(0, k * step)
            parts.append(f'<text x="{left - 6}" y="{y + 4:.1f}" text-anchor="end">'
                         f'{k * step:g}</text>')
        for k in range(0, renders + 1, renders // 5):
            x, _ = xy(k, 0)
            parts.append(f'<text x="{x:.1f}" y="{y1 + 14}" text-anchor="middle">{k}</text>')
        pts = " ".join("%.1f,%.1f" % xy(int(i), v) for i, v in zip(blocks[:, 0], values))
        parts.append(f'<polyline fill="none" stroke="{color}" stroke-width="1.2" '
                     f'points="{pts}"/>')
    parts.append(f'<text x="{(w + left) / 2}" y="{2 * panel + 24}" '
                 'text-anchor="middle">renders</text>')
    parts.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(parts) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--renders", type=int, default=10000,
                    help="renders (a multiple of the period, at least 3 periods)")
    ap.add_argument("--period", type=int, default=1000,
                    help="renders in one period of the schedule (a multiple of 20)")
    ap.add_argument("--max-growth", type=float, default=0.05,
                    help="largest allowed growth of resident and device memory")
    ap.add_argument("--csv", help="write render, resident bytes, device bytes, objects here")
    ap.add_argument("--svg", help="write the memory curve as an SVG plot here")
    args = ap.parse_args()
    period = args.period
    if period < 20 or period % 20:
        ap.error("--period must be a positive multiple of 20")
    if args.renders < 3 * period or args.renders % period:
        ap.error(f"--renders must be a multiple of {period}, at least {3 * period}")
    data_every = period // DATA_PARTS
    release_every = period // RELEASE_PARTS
    path_every = period // PATH_PARTS

    output = vtk.vtkStringOutputWindow()
    vtk.vtkOutputWindow.SetInstance(output)
    inputs = datasets()
    mapper = ferrovol.vtkFerroVolumeMapper()
    errors = Errors(mapper)
    prop = vtk.vtkVolumeProperty()
    prop.SetInterpolationTypeToLinear()
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    renderer = vtk.vtkRenderer()
    renderer.AddVolume(volume)
    window = new_window()
    window.AddRenderer(renderer)
    window.SetSize(*SIZES[0])

    # preallocated, so that the soak's own records do not grow the resident memory
    rows = np.zeros((args.renders, 4), dtype=np.int64)
    empty, start = [], time.perf_counter()
    for i in range(args.renders):
        if i % data_every == 0:
            _, data, (lo, hi), independent = inputs[(i // data_every) % len(inputs)]
            mapper.SetInputData(data)
            prop.SetIndependentComponents(independent)
            components = data.GetPointData().GetScalars().GetNumberOfComponents()
            renderer.ResetCamera()
        if i % path_every == 0:
            mapper.SetOutputPathToReadback() if (i // path_every) % 2 else \
                mapper.SetOutputPathToAutomatic()
        if i % 7 == 0:
            set_transfer_function(prop, components if independent else 1, lo, hi,
                                  (i // 7) % 5 / 4.0)
        if i % 11 == 0:
            getattr(mapper, "SetBlendModeTo" + BLEND_MODES[(i // 11) % len(BLEND_MODES)])()
        if i % 13 == 0:
            prop.SetShade((i // 13) % 2)
        if i % 17 == 0:
            window.SetSize(*SIZES[(i // 17) % len(SIZES)])
        renderer.GetActiveCamera().Azimuth(3.0)
        renderer.GetActiveCamera().Elevation(0.7 * math.sin(i / 50.0))
        renderer.GetActiveCamera().OrthogonalizeViewUp()
        renderer.ResetCameraClippingRange()
        window.Render()
        if i % release_every == release_every - 1:
            volume.ReleaseGraphicsResources(window)
        if i % 100 == 99 and mapper.GetBlendMode() != mapper.MINIMUM_INTENSITY_BLEND:
            pixels = vtk.vtkUnsignedCharArray()
            window.GetRGBACharPixelData(0, 0, window.GetSize()[0] - 1,
                                        window.GetSize()[1] - 1, 0, pixels)
            if vtk_to_numpy(pixels).max() == 0:
                empty.append(i + 1)
        rows[i] = (i + 1, resident_bytes(), mapper.GetDeviceMemoryInUse(),
                   mapper.GetDeviceObjectsInUse())
        if errors.messages or "ERROR" in output.GetOutput():
            print(f"render {i + 1}: {errors.last() or output.GetOutput()}", file=sys.stderr)
            return 1
        if (i + 1) % period == 0:
            print(f"{i + 1:6d} renders  {(time.perf_counter() - start) / (i + 1) * 1e3:6.1f} "
                  f"ms/render  resident {rows[i][1] / 2 ** 20:7.1f} MiB  device "
                  f"{rows[i][2] / 2 ** 20:6.2f} MiB in {rows[i][3]} objects", flush=True)

    if args.csv:
        with open(args.csv, "w") as f:
            f.write("render,resident_bytes,device_bytes,device_objects\n")
            f.writelines(",".join(map(str, r)) + "\n" for r in rows)
    if args.svg:
        svg_plot(args.svg, rows)
    failed = False
    for column, name in ((1, "resident memory"), (2, "device memory"), (3, "device objects")):
        early = int(rows[period:2 * period, column].max())
        late = int(rows[-period:, column].max())
        growth = late / early - 1.0
        print(f"{name}: highest over renders {period + 1}-{2 * period} {early}, over "
              f"{args.renders - period + 1}-{args.renders} {late}: {growth * 100:+.2f}%")
        failed |= growth > args.max_growth
    if empty:
        print(f"nothing drawn at renders {empty}", file=sys.stderr)
    warnings = sorted(set(errors.warnings))
    print(f"{len(warnings)} distinct warnings" + "".join(f"\n  {w.strip()}" for w in warnings))
    return 1 if failed or empty else 0


if __name__ == "__main__":
    sys.exit(main())
