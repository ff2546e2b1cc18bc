#!/usr/bin/python3
"""VTK's unstructured-grid volume mappers on a mesh of at least a million tetrahedra, in one
VTK window: the anchors ferrovol's unstructured mapper is measured against (issue 40).

The mesh is tests/regression/meshes.py's timing mesh (VTK's wavelet tetrahedralised, 5
tetrahedra per voxel: 1 080 000 for the default million), drawn at 900x900 with the
regression suite's wavelet transfer function (composite, point scalars), camera at azimuth
30 and elevation 20, then turned by +1 degree of azimuth per frame (as VTK's
TestGPURayCastMapperBenchmark). One window and one vtkVolume; each mapper in turn is set on
the volume and timed: its first frame (which builds its structures: the ray caster's face
lists, the Z-sweep's vertex lists, projected tetrahedra's colours and sort), then --frames
frames, of which the median is printed (steady state). A mapper whose frames take long stops
after --budget seconds of steady frames (at least one), and says so.

Rows: vtkUnstructuredGridVolumeRayCastMapper (Bunyk; its default integrator for point
scalars), vtkUnstructuredGridVolumeZSweepMapper, vtkProjectedTetrahedraMapper (VTK's factory
gives vtkOpenGLProjectedTetrahedraMapper) and, once the module `ferrovol` has it,
vtkFerroUnstructuredVolumeMapper: one more entry of MAPPERS. With --cli, ferrovol's CLI
draws the same mesh (written to a .vtu), transfer function, size and camera path in the
same run, before VTK's mappers (`ferrovol render --repeat`, its own device; the mean of
its steady frames); --cli may be given more than once (two builds in one run).

--tf picks the transfer function: `wavelet` (the regression suite's: opacity rising from 0
at the scalar range's low end, nothing empty) or `partly-empty` (the same with opacity 0 up
to 170, over about 60% of the mesh's points: what a user looking at the high values sets).

    . build/env.sh
    scripts/with-xvfb.sh /usr/bin/python3 bench/unstructured_vtk.py [--tets 1000000]
        [--size 900x900] [--frames 5] [--budget 300] [--only bunyk,pt] [--png-dir DIR]
        [--tf wavelet|partly-empty] [--cli [NAME=]target/release/ferrovol ...]
"""
import argparse
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path[:0] = [os.path.join(ROOT, "tests", "regression"),
                os.path.join(ROOT, "vtk_plugin", "examples")]

import vtk  # noqa: E402

import meshes  # noqa: E402  tests/regression/meshes.py
from volume_scene import (  # noqa: E402  vtk_plugin/examples/volume_scene.py
    WAVELET_COLOR, WAVELET_OPACITY, volume_property, write_png)

# --tf: name -> (colour points, opacity points)
TRANSFER_FUNCTIONS = {
    "wavelet": (WAVELET_COLOR, WAVELET_OPACITY),
    "partly-empty": (WAVELET_COLOR, [(37.3531, 0.0), (170.0, 0.0), (276.829, 1.0)]),
}


def _ray_cast_mapper(cls):
    def make():
        m = cls()
        m.AutoAdjustSampleDistancesOff()   # one ray per pixel, every frame
        m.SetImageSampleDistance(1.0)
        return m
    return make


def _ferrovol():
    try:
        import ferrovol
    except ImportError:
        return None
    return getattr(ferrovol, "vtkFerroUnstructuredVolumeMapper", None)


# name -> () -> mapper, or None where there is no such mapper in this build
MAPPERS = {
    "bunyk": _ray_cast_mapper(vtk.vtkUnstructuredGridVolumeRayCastMapper),
    "zsweep": _ray_cast_mapper(vtk.vtkUnstructuredGridVolumeZSweepMapper),
    "pt": vtk.vtkProjectedTetrahedraMapper,
    "ferrovol": _ferrovol(),
}


def time_mapper(win, ren, vol, mesh, make, frames, budget, png=None):
    """(first frame ms, [steady frame ms], class name) for one mapper on the volume."""
    m = make()
    m.SetInputData(mesh)
    vol.SetMapper(m)
    cam = ren.GetActiveCamera()
    t0 = time.perf_counter()
    win.Render()
    first = (time.perf_counter() - t0) * 1e3
    if png:
        write_png(win, png)
    steady = []
    spent = 0.0
    for _ in range(frames):
        cam.Azimuth(1.0)
        ren.ResetCameraClippingRange()
        t0 = time.perf_counter()
        win.Render()
        ms = (time.perf_counter() - t0) * 1e3
        steady.append(ms)
        spent += ms / 1e3
        if spent > budget:
            break
    return first, steady, m.GetClassName()


def time_cli(cli, mesh, tf, size, frames, png=None):
    """(prepare ms, [mean steady frame ms]) of ferrovol's CLI drawing the mesh (as a .vtu)
    with the transfer function (colour points, opacity points) at size (w, h): the
    benchmark's camera, then frames turns of +1 degree."""
    with tempfile.TemporaryDirectory() as tmp:
        vtu = os.path.join(tmp, "timing.vtu")
        meshes.write_vtu(mesh, vtu, mode="raw", compress=False)
        tf_json = os.path.join(tmp, "tf.json")
        with open(tf_json, "w") as f:
            json.dump({"color": [list(p) for p in tf[0]], "opacity": [list(p) for p in tf[1]],
                       "unit_distance": 1.0}, f)
        out = png or os.path.join(tmp, "ferrovol.png")
        cmd = [cli, "render", vtu, "--size", "%dx%d" % size, "--tf", tf_json, "--azimuth",
               "30", "--elevation", "20", "--repeat", str(frames + 1), "--orbit", "1",
               "--out", out]
        done = subprocess.run(cmd, capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError("%s failed:\n%s%s" % (" ".join(cmd), done.stdout, done.stderr))
    prepared = float(re.search(r"prepared in ([0-9.]+) s", done.stdout).group(1))
    mean = float(re.search(r"([0-9.]+) ms/frame", done.stdout).group(1))
    return prepared * 1e3, [mean]


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tets", type=int, default=1_000_000)
    ap.add_argument("--size", default="900x900")
    ap.add_argument("--frames", type=int, default=5, help="steady frames per mapper")
    ap.add_argument("--budget", type=float, default=300.0,
                    help="seconds of steady frames per mapper before it stops (>= 1 frame)")
    ap.add_argument("--only", default="", help="comma-separated names of MAPPERS")
    ap.add_argument("--multisamples", type=int, metavar="N",
                    help="the window's MultiSamples (default VTK's: 8 on VTK 9.2)")
    ap.add_argument("--png-dir", help="write each mapper's first frame here")
    ap.add_argument("--tf", choices=sorted(TRANSFER_FUNCTIONS), default="wavelet")
    ap.add_argument("--cli", action="append", default=[], metavar="[NAME=]PATH",
                    help="ferrovol's CLI: time it on the same mesh (row NAME, default "
                    "ferrovol-cli); repeatable, e.g. before=OLD after=NEW")
    a = ap.parse_args(argv)
    w, h = (int(v) for v in a.size.split("x"))
    names = [n.strip() for n in a.only.split(",") if n.strip()] or list(MAPPERS)

    t0 = time.perf_counter()
    mesh = meshes.timing(a.tets)
    made = time.perf_counter() - t0
    print("# mesh: %d tetrahedra, %d points (tests/regression/meshes.py timing(%d), made in "
          "%.2f s); %dx%d; --tf %s; VTK %s; %s, %d CPUs; load average %s"
          % (mesh.GetNumberOfCells(), mesh.GetNumberOfPoints(), a.tets, made, w, h, a.tf,
             vtk.vtkVersion.GetVTKVersion(), platform.node(), os.cpu_count(),
             " ".join("%.2f" % v for v in os.getloadavg())), flush=True)

    win = vtk.vtkRenderWindow()
    win.SetSize(w, h)
    if a.multisamples is not None:
        win.SetMultiSamples(a.multisamples)
    ren = vtk.vtkRenderer()
    ren.SetBackground(0.0, 0.0, 0.0)
    win.AddRenderer(ren)
    tf = TRANSFER_FUNCTIONS[a.tf]
    prop = volume_property(*tf)
    prop.SetInterpolationTypeToLinear()
    prop.SetScalarOpacityUnitDistance(1.0)
    vol = vtk.vtkVolume()
    vol.SetProperty(prop)
    ren.AddVolume(vol)
    ren.ResetCamera(mesh.GetBounds())
    cam = ren.GetActiveCamera()
    start = vtk.vtkCamera()
    cam.Azimuth(30.0)
    cam.Elevation(20.0)
    cam.OrthogonalizeViewUp()
    start.DeepCopy(cam)
    if a.png_dir:
        os.makedirs(a.png_dir, exist_ok=True)

    rows = []
    for spec in a.cli:
        name, _, path = spec.rpartition("=")
        name = name or "ferrovol-cli"
        png = os.path.join(a.png_dir, "unstructured-%s.png" % name) if a.png_dir else None
        prepared, steady = time_cli(path, mesh, tf, (w, h), a.frames, png)
        print("%-9s %-42s prepare_ms=%.0f steady_ms_mean=%.0f (%d frames)"
              % (name, path, prepared, steady[0], a.frames), flush=True)
        rows.append((name, steady[0]))
    for name in names:
        make = MAPPERS.get(name)
        if make is None:
            print("%-9s (no such mapper in this build)" % name, flush=True)
            continue
        cam.DeepCopy(start)
        ren.ResetCameraClippingRange()
        png = os.path.join(a.png_dir, "unstructured-%s.png" % name) if a.png_dir else None
        first, steady, cls = time_mapper(win, ren, vol, mesh, make, a.frames, a.budget, png)
        med = statistics.median(steady)
        cut = " (stopped after %d of %d frames: --budget %.0f s)" % (
            len(steady), a.frames, a.budget) if len(steady) < a.frames else ""
        print("%-9s %-42s first_ms=%.0f steady_ms_median=%.0f frames=[%s]%s"
              % (name, cls, first, med, " ".join("%.0f" % v for v in steady), cut), flush=True)
        rows.append((name, med))
    win.Finalize()
    times = dict(rows)
    for anchor in ("bunyk", "zsweep", "pt"):
        if anchor in times and len(times) > 1:
            print("# ratio of steady frame time to %s's: " % anchor + ", ".join(
                "%s %.3f" % (n, ms / times[anchor]) for n, ms in rows if n != anchor))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
