#!/usr/bin/python3
"""Progressive path tracing in a VTK window with an interactor: the skull CT (build/data/
cranium.vti, bone), vtkFerroVolumeMapper in path-tracing mode, the interactor started with
a quit timer and nothing else from the script.

Prints the distribution of the Render() times against the time budget, the paths per pixel
reached, and the mean FLIP (tests/ferrovol_testing/flip.py, over the pixels the reference
covers) of the displayed image against a converged reference after 1, 5 and 30 s, with the
denoised preview (PathTracingDenoiseUntil) and without.

Needs `. build/env.sh` and an X display:
    scripts/with-xvfb.sh /usr/bin/python3 bench/progressive_vtk.py [--size 192] [--ref-spp 256]
"""
import argparse
import os
import sys
import time

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

import ferrovol

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, ".."))
sys.path.insert(0, os.path.join(ROOT, "tests"))
from ferrovol_testing import flip  # noqa: E402
from ferrovol_testing.png import write_png  # noqa: E402

DATA = os.environ.get("FERROVOL_DATA_DIR", os.path.join(ROOT, "build", "data"))
OUT = os.path.join(ROOT, "build", "bench-progressive")


def prop():
    """The CLI's ct-bone preset."""
    p = vtk.vtkVolumeProperty()
    c = vtk.vtkColorTransferFunction()
    for x, r, g, b in ((-1000, 0, 0, 0), (200, 0.9, 0.8, 0.7), (1500, 1.0, 1.0, 0.95)):
        c.AddRGBPoint(x, r, g, b)
    o = vtk.vtkPiecewiseFunction()
    for x, a in ((-1000, 0.0), (200, 0.0), (400, 0.6), (1500, 0.9)):
        o.AddPoint(x, a)
    p.SetColor(c)
    p.SetScalarOpacity(o)
    p.SetInterpolationTypeToLinear()
    p.SetScalarOpacityUnitDistance(1.0)
    return p


def scene(reader, size, configure):
    mapper = ferrovol.vtkFerroVolumeMapper()
    mapper.SetInputConnection(reader.GetOutputPort())
    mapper.SetRenderModeToPathTrace()
    configure(mapper)
    vol = vtk.vtkVolume()
    vol.SetMapper(mapper)
    vol.SetProperty(prop())
    ren = vtk.vtkRenderer()
    ren.AddVolume(vol)
    win = vtk.vtkRenderWindow()
    win.SetSize(size, size)
    win.SetMultiSamples(0)
    win.AddRenderer(ren)
    ren.ResetCamera()
    cam = ren.GetActiveCamera()
    cam.Elevation(-90)  # from the front (-y), as the CLI's --elevation -90 --view-up z
    cam.SetViewUp(0, 0, 1)
    cam.OrthogonalizeViewUp()
    cam.Azimuth(30)
    ren.ResetCamera()
    cam.Zoom(1.3)
    return win, ren, mapper


def grab(win):
    w2i = vtk.vtkWindowToImageFilter()
    w2i.SetInput(win)
    w2i.SetShouldRerender(False)
    w2i.ReadFrontBufferOff()
    w2i.Update()
    img = w2i.GetOutput()
    w, h, _ = img.GetDimensions()
    a = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, -1)[::-1]
    return a[..., :3].copy()


def reference(reader, size, spp):
    win, _, mapper = scene(reader, size, lambda m: (m.SetSamplesPerPixel(spp),
                                                    m.SetProgressiveModeToOff()))
    win.SetOffScreenRendering(1)
    t = time.perf_counter()
    win.Render()
    img = grab(win)
    print("reference: %d paths per pixel at %dx%d in %.1f s" % (
        mapper.GetAccumulatedSamples(), size, size, time.perf_counter() - t), flush=True)
    return img


def progressive(reader, size, spp, denoise_until, marks, ref):
    win, ren, mapper = scene(reader, size, lambda m: (m.SetSamplesPerPixel(spp),
                                                      m.SetPathTracingDenoiseUntil(denoise_until)))
    iren = vtk.vtkRenderWindowInteractor()
    iren.SetRenderWindow(win)
    iren.Initialize()
    times, start = [], {}
    win.AddObserver("StartEvent", lambda *_: start.__setitem__("t", time.perf_counter()))
    win.AddObserver("EndEvent", lambda *_: times.append(time.perf_counter() - start["t"]))
    rows = []
    mask = ref.max(axis=2) > 8
    t0 = time.perf_counter()
    pending = list(marks)

    def check(obj, _):
        now = time.perf_counter() - t0
        if pending and now >= pending[0]:
            pending.pop(0)
            img = grab(win)
            fl = flip.flip_map(ref, img)
            rows.append((now, mapper.GetAccumulatedSamples(), float(fl[mask].mean()), img))
            if not pending:
                iren.TerminateApp()

    iren.AddObserver("TimerEvent", check)
    iren.CreateRepeatingTimer(100)
    win.Render()
    iren.Start()
    return rows, times, mapper


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=192)
    ap.add_argument("--ref-spp", type=int, default=256)
    ap.add_argument("--spp", type=int, default=1024, help="SamplesPerPixel of the window")
    ap.add_argument("--marks", default="1,5,30", help="seconds after the first render")
    ap.add_argument("--denoise-until", type=int, default=16)
    args = ap.parse_args()
    os.makedirs(OUT, exist_ok=True)
    reader = vtk.vtkXMLImageDataReader()
    reader.SetFileName(os.path.join(DATA, "cranium.vti"))
    reader.Update()
    ref = reference(reader, args.size, args.ref_spp)
    write_png(os.path.join(OUT, "reference.png"), ref)
    marks = [float(m) for m in args.marks.split(",")]
    table = {}
    for label, until in (("denoised", args.denoise_until), ("plain", 0)):
        rows, times, _ = progressive(reader, args.size, args.spp, until, marks, ref)
        t = np.array(times[1:]) * 1e3  # (the first render builds the pipelines)
        print("%s: %d renders; Render() ms: median %.1f, p95 %.1f, max %.1f (first %.0f); "
              "automatic budget 100 ms" % (label, len(times), np.median(t),
                                           np.percentile(t, 95), t.max(), times[0] * 1e3))
        for now, n, f, img in rows:
            table.setdefault(round(now), {})[label] = (n, f)
            write_png(os.path.join(OUT, "%s-%02ds.png" % (label, round(now))), img)
    print("\n| after | paths per pixel | mean FLIP, denoised preview | mean FLIP, plain |")
    print("|---|---|---|---|")
    for s in sorted(table):
        d, p = table[s].get("denoised", (0, float("nan"))), table[s].get("plain", (0, float("nan")))
        print("| %d s | %d / %d | %.4f | %.4f |" % (s, d[0], p[0], d[1], p[1]))


if __name__ == "__main__":
    main()
