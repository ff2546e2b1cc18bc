#!/usr/bin/python3
"""Isosurface frame times on the skull CT: vtkGPUVolumeRayCastMapper's isosurface blend mode
against vtkFerroVolumeMapper's (first hit + bisection + deferred shading) with the
renderer's lights only, with environment lighting at 1, 16 and 64 specular samples, and with
ambient occlusion, all in one VTK window setup in one run.

Scene: build/data/cranium.vti (InVesalius skull CT, 256x256x108 int16; scripts/fetch-data.sh),
bone at 400 HU (opaque) and skin at -500 HU (opacity 0.3), Shade on, VTK's headlight, 900x900,
the camera turning 1 degree per frame. Each configuration renders 2 warm-up frames, then
--frames timed frames (wall clock of vtkRenderWindow::Render, which waits for the frame);
configurations alternate over --rounds rounds and each prints the median of its rounds' means.

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
                                "tests"))
import fvtest  # noqa: E402  (offscreen windows on one X connection, transfer functions)

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, ".."))

# name, mapper, ferrovol settings (environment weight, specular samples, AO directions)
CONFIGS = [
    ("vtk_gpu_iso", "gpu", None),
    ("ferrovol_lights_only", "ferrovol", (0.0, 16, 0)),
    ("ferrovol_env_spec1", "ferrovol", (0.6, 1, 0)),
    ("ferrovol_env_spec16", "ferrovol", (0.6, 16, 0)),
    ("ferrovol_env_spec64", "ferrovol", (0.6, 64, 0)),
    ("ferrovol_env_spec16_ao16", "ferrovol", (0.6, 16, 16)),
]


def skull_property():
    p = fvtest.tf_property(
        color=[(-1000, 0.92, 0.68, 0.56), (-500, 0.92, 0.68, 0.56), (400, 0.95, 0.92, 0.84),
               (3071, 1.0, 1.0, 1.0)],
        opacity=[(-1000, 0.3), (-500, 0.3), (400, 1.0), (3071, 1.0)], interpolation="linear")
    p.ShadeOn()
    p.GetIsoSurfaceValues().SetValue(0, -500.0)
    p.GetIsoSurfaceValues().SetValue(1, 400.0)
    return p


def run(data, kind, settings, frames, size, png):
    win = fvtest.new_window()
    win.SetMultiSamples(0)
    win.SetSize(*size)
    ren = vtk.vtkRenderer()
    win.AddRenderer(ren)
    if kind == "gpu":
        m = vtk.vtkGPUVolumeRayCastMapper()
    else:
        m = ferrovol.vtkFerroVolumeMapper()
        env, spec, ao = settings
        m.SetEnvironmentLighting(env)
        m.SetSpecularSamples(spec)
        m.SetAmbientOcclusionSamples(ao)
    m.SetBlendModeToIsoSurface()
    m.SetInputData(data)
    vol = vtk.vtkVolume()
    vol.SetMapper(m)
    vol.SetProperty(skull_property())
    ren.AddVolume(vol)
    cam = ren.GetActiveCamera()
    cam.SetViewUp(0, 0, 1)
    cam.SetPosition(0, -1, 0)
    cam.SetFocalPoint(0, 0, 0)
    ren.ResetCamera()
    cam.Zoom(1.3)
    ren.ResetCameraClippingRange()
    for _ in range(2):
        cam.Azimuth(1.0)
        win.Render()
    times = []
    for _ in range(frames):
        cam.Azimuth(1.0)
        t0 = time.perf_counter()
        win.Render()
        times.append(1000.0 * (time.perf_counter() - t0))
    if png:
        w2i = vtk.vtkWindowToImageFilter()
        w2i.SetInput(win)
        w2i.Update()
        writer = vtk.vtkPNGWriter()
        writer.SetFileName(png)
        writer.SetInputConnection(w2i.GetOutputPort())
        writer.Write()
    if kind != "gpu" and not m.GetLastRenderDrew():
        raise RuntimeError("vtkFerroVolumeMapper drew nothing")
    return statistics.mean(times)


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--input", default=os.path.join(ROOT, "build", "data", "cranium.vti"))
    p.add_argument("--frames", type=int, default=5)
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--size", default="900x900")
    p.add_argument("--png-dir", default="", help="write each configuration's last frame here")
    args = p.parse_args(argv)
    if not os.path.exists(args.input):
        print("# error: %s is missing: run scripts/fetch-data.sh" % args.input)
        return 1
    size = tuple(int(v) for v in args.size.split("x"))
    reader = vtk.vtkXMLImageDataReader()
    reader.SetFileName(args.input)
    reader.Update()
    data = reader.GetOutput()
    print("# %s %s, %s, %d timed frames per round, %d rounds; ferrovol on %s"
          % (os.path.basename(args.input), "x".join(map(str, data.GetDimensions())), args.size,
             args.frames, args.rounds, ferrovol.vtkFerroVolumeMapper.GetAdapterDescription()))
    results = {name: [] for name, _, _ in CONFIGS}
    for r in range(args.rounds):
        for name, kind, settings in CONFIGS:
            png = (os.path.join(args.png_dir, name + ".png")
                   if args.png_dir and r == args.rounds - 1 else "")
            if png:
                os.makedirs(args.png_dir, exist_ok=True)
            results[name].append(run(data, kind, settings, args.frames, size, png))
        print("# round %d of %d done" % (r + 1, args.rounds))
        sys.stdout.flush()
    ref = statistics.median(results["vtk_gpu_iso"])
    for name, _, _ in CONFIGS:
        ms = statistics.median(results[name])
        print("%-26s ms_per_frame=%.1f ratio_to_vtk_gpu_iso=%.2f rounds=[%s]"
              % (name, ms, ms / ref, " ".join("%.1f" % v for v in results[name])))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
