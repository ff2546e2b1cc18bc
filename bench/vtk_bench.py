#!/usr/bin/python3
"""VTK reference timings for ferrovol: VTK's TestGPURayCastMapperBenchmark scene.

Scene (as in VTK's Rendering/VolumeOpenGL2/Testing/Cxx/TestGPURayCastMapperBenchmark.cxx,
OpenGL path): vtkRTAnalyticSource ("wavelet") with WholeExtent -N..N+1 on every axis
(N = 127: 256^3 float32), colour transfer function
  37.3531 -> (0.2, 0.29, 1), 157.091 -> (0.87, 0.87, 0.87), 276.829 -> (0.7, 0.015, 0.15),
scalar opacity 0 at 37.3531 rising linearly to 1 at 276.829, a 900x900 window, the
camera reset once and then, every frame, Azimuth(1), Elevation(1), OrthogonalizeViewUp().
Mapper, volume property and render window settings are VTK's defaults (nearest
interpolation, automatic sample distances, VTK 9.2's 8x multisampled window) unless options
say otherwise.

Each mode (unshaded, then shaded: ShadeOn with the default ambient 0 / diffuse 0.7 /
specular 0.2 / power 10) starts from the same reset camera, renders 2 warm-up frames and
then --frames timed frames. Every frame is followed by renWin.WaitForCompletion()
(glFinish), and the loop is timed with time.perf_counter.

Output: comment lines start with '#'; results are machine-readable lines
    vtk_<mapper> <mode> ms_per_frame=<mean> median_ms=<median> min_ms=<min> max_ms=<max> frames=<n> size=<W>x<H> extent=<N>

Run with Debian's /usr/bin/python3 (VTK 9.2 from ParaView 5.11), offscreen: the caller
provides an X display (e.g. Xvfb) in $DISPLAY.

Examples:
    /usr/bin/python3 bench/vtk_bench.py --frames 3
    /usr/bin/python3 bench/vtk_bench.py --mapper fixed --size 512x512 --png /tmp/vtk.png
"""

import argparse
import os
import statistics
import sys
import time

WARMUP_FRAMES = 2


def parse_size(text):
    try:
        w, h = text.lower().split("x")
        w, h = int(w), int(h)
    except ValueError:
        raise argparse.ArgumentTypeError(f"size '{text}' is not WxH, e.g. 900x900")
    if w <= 0 or h <= 0:
        raise argparse.ArgumentTypeError(f"size '{text}' must be positive")
    return w, h


def positive_int(text):
    v = int(text)
    if v <= 0:
        raise argparse.ArgumentTypeError(f"{text} must be a positive integer")
    return v


def parse_args(argv):
    p = argparse.ArgumentParser(
        description="Time VTK volume rendering of the TestGPURayCastMapperBenchmark scene.",
    )
    p.add_argument("--frames", type=positive_int, default=20,
                   help="timed frames per mode, after %d warm-up frames (default 20)" % WARMUP_FRAMES)
    p.add_argument("--mapper", choices=["gpu", "fixed", "ferrovol"], default="gpu",
                   help="vtkGPUVolumeRayCastMapper (gpu, default), "
                        "vtkFixedPointVolumeRayCastMapper (fixed, CPU) or ferrovol's "
                        "vtkFerroVolumeMapper (ferrovol: needs `. build/env.sh`)")
    p.add_argument("--output-path", choices=["automatic", "shared", "readback"],
                   default="automatic",
                   help="vtkFerroVolumeMapper only: zero-copy shared texture or CPU readback")
    p.add_argument("--size", type=parse_size, default=(900, 900), metavar="WxH",
                   help="window size (default 900x900)")
    p.add_argument("--extent", type=positive_int, default=127, metavar="N",
                   help="wavelet half-width: WholeExtent -N..N+1 per axis (default 127: 256^3)")
    p.add_argument("--modes", choices=["both", "unshaded", "shaded"], default="both",
                   help="which modes to time (default both: unshaded, then shaded)")
    p.add_argument("--interpolation", choices=["nearest", "linear"], default="nearest",
                   help="volume property interpolation (default nearest, VTK's default "
                        "and the benchmark's)")
    p.add_argument("--no-auto-adjust", action="store_true",
                   help="turn off the mapper's AutoAdjustSampleDistances (on by default)")
    p.add_argument("--multisamples", type=int, metavar="N",
                   help="the render window's MultiSamples (default: VTK's own default, 8 on "
                        "VTK 9.2, which VTK's benchmark keeps; 0 turns multisampling off)")
    p.add_argument("--opaque", action="store_true",
                   help="make every value fully opaque: each ray stops at its first sample, "
                        "so a frame costs what the mapper and the window cost without the "
                        "ray march (the floor under any sampling scheme)")
    p.add_argument("--png", metavar="FILE",
                   help="save the last rendered frame (of the last mode) as PNG")
    return p.parse_args(argv)


def opengl_info(ren_win):
    """'vendor | renderer | version' from renWin.ReportCapabilities() (needs a context)."""
    fields = {}
    for line in ren_win.ReportCapabilities().splitlines():
        for key in ("vendor", "renderer", "version"):
            prefix = "OpenGL %s string:" % key
            if line.startswith(prefix):
                fields[key] = line[len(prefix):].strip()
    if not fields:
        return "unknown (ReportCapabilities gave no OpenGL strings)"
    return " | ".join(fields.get(k, "?") for k in ("vendor", "renderer", "version"))


def main(argv):
    args = parse_args(argv)
    if not os.environ.get("DISPLAY"):
        print("# warning: DISPLAY is not set; VTK's X render window needs an X server "
              "(e.g. Xvfb :99 and DISPLAY=:99)", file=sys.stderr)

    import vtk  # noqa: E402  (after argument parsing so --help works without a display)

    n = args.extent
    width, height = args.size

    # Data.
    source = vtk.vtkRTAnalyticSource()
    source.SetWholeExtent(-n, n + 1, -n, n + 1, -n, n + 1)
    source.SetCenter(0.0, 0.0, 0.0)
    t0 = time.perf_counter()
    source.Update()
    make_data_s = time.perf_counter() - t0
    image = source.GetOutput()
    dims = image.GetDimensions()
    lo, hi = image.GetScalarRange()

    # Mapper.
    if args.mapper == "gpu":
        mapper = vtk.vtkGPUVolumeRayCastMapper()
    elif args.mapper == "ferrovol":
        import ferrovol
        mapper = ferrovol.vtkFerroVolumeMapper()
        {"automatic": mapper.SetOutputPathToAutomatic, "shared": mapper.SetOutputPathToShared,
         "readback": mapper.SetOutputPathToReadback}[args.output_path]()
    else:
        mapper = vtk.vtkFixedPointVolumeRayCastMapper()
    mapper.SetInputConnection(source.GetOutputPort())
    if args.no_auto_adjust:
        mapper.AutoAdjustSampleDistancesOff()

    # Transfer functions and property.
    ctf = vtk.vtkColorTransferFunction()
    ctf.AddRGBPoint(37.3531, 0.2, 0.29, 1.0)
    ctf.AddRGBPoint(157.091, 0.87, 0.87, 0.87)
    ctf.AddRGBPoint(276.829, 0.7, 0.015, 0.15)
    pwf = vtk.vtkPiecewiseFunction()
    pwf.AddPoint(37.3531, 1.0 if args.opaque else 0.0)
    pwf.AddPoint(276.829, 1.0)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(ctf)
    prop.SetScalarOpacity(pwf)
    if args.interpolation == "linear":
        prop.SetInterpolationTypeToLinear()
    else:
        prop.SetInterpolationTypeToNearest()
    prop.ShadeOff()

    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)

    # Window and renderer.
    ren_win = vtk.vtkRenderWindow()
    ren_win.SetOffScreenRendering(1)
    ren_win.SetSize(width, height)
    if args.multisamples is not None:
        ren_win.SetMultiSamples(args.multisamples)
    ren_win.Render()  # make sure there is an OpenGL context
    renderer = vtk.vtkRenderer()
    renderer.AddVolume(volume)
    ren_win.AddRenderer(renderer)
    renderer.ResetCamera()
    initial_camera = vtk.vtkCamera()
    initial_camera.DeepCopy(renderer.GetActiveCamera())

    print("# VTK %s, %s" % (vtk.vtkVersion.GetVTKVersion(), ren_win.GetClassName()))
    print("# OpenGL: %s" % opengl_info(ren_win))
    # Every frame clears and resolves the window's multisampled framebuffer, a cost of its
    # own on a CPU rasteriser (docs/PERFORMANCE.md).
    print("# window: MultiSamples=%d" % ren_win.GetMultiSamples())
    print("# data: vtkRTAnalyticSource extent -%d..%d (%dx%dx%d float32), range [%.4f, %.4f], "
          "made in %.2f s" % (n, n + 1, dims[0], dims[1], dims[2], lo, hi, make_data_s))
    print("# mapper: %s, AutoAdjustSampleDistances=%d, interpolation=%s, window %dx%d, "
          "%d warm-up + %d timed frames per mode%s"
          % (mapper.GetClassName(), mapper.GetAutoAdjustSampleDistances(),
             prop.GetInterpolationTypeAsString(), width, height, WARMUP_FRAMES, args.frames,
             ", opacity 1 everywhere (--opaque)" if args.opaque else ""))
    if args.mapper == "gpu" and not mapper.IsRenderSupported(ren_win, prop):
        print("# error: vtkGPUVolumeRayCastMapper reports this OpenGL context unsupported",
              file=sys.stderr)
        return 2
    sys.stdout.flush()

    camera = renderer.GetActiveCamera()

    def frame():
        camera.Azimuth(1)
        camera.Elevation(1)
        camera.OrthogonalizeViewUp()
        ren_win.Render()
        ren_win.WaitForCompletion()

    modes = ["unshaded", "shaded"] if args.modes == "both" else [args.modes]
    for mode in modes:
        if mode == "shaded":
            prop.ShadeOn()
        else:
            prop.ShadeOff()
        camera.DeepCopy(initial_camera)
        renderer.ResetCameraClippingRange()

        t0 = time.perf_counter()
        for _ in range(WARMUP_FRAMES):
            frame()
        warmup_s = time.perf_counter() - t0

        times = []
        t_start = time.perf_counter()
        for _ in range(args.frames):
            t = time.perf_counter()
            frame()
            times.append(time.perf_counter() - t)
        total_s = time.perf_counter() - t_start

        ms = 1000.0 * total_s / args.frames
        print("# %s: warm-up %d frames %.1f ms (first frames include texture upload / shader build)"
              % (mode, WARMUP_FRAMES, 1000.0 * warmup_s))
        name = args.mapper
        if args.mapper == "ferrovol":
            name = "ferrovol_" + mapper.GetOutputPathName().lower()
            print("# ferrovol output path: %s (%s)"
                  % (mapper.GetOutputPathName(), mapper.GetOutputPathReason()))
        print("vtk_%s %s ms_per_frame=%.1f median_ms=%.1f min_ms=%.1f max_ms=%.1f frames=%d size=%dx%d extent=%d"
              % (name, mode, ms, 1000.0 * statistics.median(times), 1000.0 * min(times), 1000.0 * max(times),
                 args.frames, width, height, n))
        sys.stdout.flush()

    if args.png:
        grab = vtk.vtkWindowToImageFilter()
        grab.SetInput(ren_win)
        grab.SetInputBufferTypeToRGB()
        grab.ReadFrontBufferOff()
        grab.Update()
        writer = vtk.vtkPNGWriter()
        writer.SetFileName(args.png)
        writer.SetInputConnection(grab.GetOutputPort())
        writer.Write()
        print("# wrote %s (last %s frame)" % (args.png, modes[-1]))

    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
