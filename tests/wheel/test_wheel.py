"""The wheel as a pip user has it: run in a new venv where only `pip install
ferrovol-*.whl pyvista` was done (make test's `wheel` suite: tests/wheel/run.sh), with an X
display. vtkFerroVolumeMapper against that pip VTK's vtkGPUVolumeRayCastMapper, the same
scene through PyVista, and path tracing refining by itself in an interactive Plotter.

    scripts/with-xvfb.sh VENV/bin/python -m unittest -v tests/wheel/test_wheel.py
"""
import os
import subprocess
import sys
import tempfile
import time
import unittest

import numpy as np
import pyvista as pv
import vtk
from vtk.util.numpy_support import vtk_to_numpy

import ferrovol

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from ferrovol_testing.metrics import coverage, psnr, ssim  # noqa: E402
from ferrovol_testing.png import write_png  # noqa: E402

OUTPUT = os.environ.get("FERROVOL_TEST_OUTPUT", "")
SIZE = 300


def log(*args):
    print(*args, file=sys.stderr, flush=True)


def save(name, *images):
    if OUTPUT:
        os.makedirs(OUTPUT, exist_ok=True)
        write_png(os.path.join(OUTPUT, name + ".png"), np.concatenate(images, axis=1))


def wavelet():
    src = vtk.vtkRTAnalyticSource()
    src.SetWholeExtent(-31, 32, -31, 32, -31, 32)
    src.Update()
    return src.GetOutput()


def draw(mapper, blend=vtk.vtkVolumeMapper.COMPOSITE_BLEND, shade=False):
    """The wavelet with VTK's benchmark transfer function, as ten lines of a user's script
    would draw it, read back from the window."""
    ctf = vtk.vtkColorTransferFunction()
    for x, r, g, b in ((37.35, 0.2, 0.29, 1.0), (157.09, 0.87, 0.87, 0.87), (276.83, 0.7, 0.015, 0.15)):
        ctf.AddRGBPoint(x, r, g, b)
    otf = vtk.vtkPiecewiseFunction()
    otf.AddPoint(37.35, 0.0)
    otf.AddPoint(276.83, 1.0 if blend == vtk.vtkVolumeMapper.MAXIMUM_INTENSITY_BLEND else 0.2)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(ctf)
    prop.SetScalarOpacity(otf)
    prop.SetInterpolationTypeToLinear()
    prop.SetShade(shade)
    mapper.SetInputData(wavelet())
    mapper.SetBlendMode(blend)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    renderer = vtk.vtkRenderer()
    renderer.AddVolume(volume)
    renderer.ResetCamera()
    renderer.GetActiveCamera().Azimuth(30.0)
    renderer.GetActiveCamera().Elevation(20.0)
    renderer.ResetCameraClippingRange()
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(SIZE, SIZE)
    window.AddRenderer(renderer)
    window.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.Update()
    image = grab.GetOutput()
    w, h, _ = image.GetDimensions()
    pixels = vtk_to_numpy(image.GetPointData().GetScalars()).reshape(h, w, -1)[::-1]
    window.Finalize()
    return pixels


class Wheel(unittest.TestCase):
    def test_imports_with_nothing_set(self):
        """`import ferrovol` from the venv, with no PYTHONPATH or LD_LIBRARY_PATH."""
        env = {k: v for k, v in os.environ.items()
               if k not in ("PYTHONPATH", "LD_LIBRARY_PATH", "LD_PRELOAD")}
        out = subprocess.run(
            [sys.executable, "-c",
             "import ferrovol, vtk; ferrovol.vtkFerroVolumeMapper(); "
             "print(ferrovol.__file__, vtk.vtkVersion.GetVTKVersion())"],
            env=env, capture_output=True, text=True, check=False)
        log("import:", out.stdout.strip(), out.stderr.strip())
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn(sys.prefix, out.stdout)

    def test_c_program_through_the_cmake_package(self):
        """A C program of the C ABI (ffi/tests/c/render_demo.c) built by CMake with
        find_package(ferrovol) from the wheel's package, run: a non-blank image."""
        source = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "ffi",
                              "tests", "c")
        with tempfile.TemporaryDirectory() as tmp:
            with open(os.path.join(tmp, "CMakeLists.txt"), "w", encoding="utf-8") as f:
                f.write("cmake_minimum_required(VERSION 3.16)\n"
                        "project(demo C)\n"
                        "find_package(ferrovol 0.2 REQUIRED)\n"
                        "add_executable(render_demo %s/render_demo.c)\n"
                        "target_include_directories(render_demo PRIVATE %s)\n"
                        "target_link_libraries(render_demo PRIVATE ferrovol::ferrovol m)\n"
                        % (source, source))
            build = os.path.join(tmp, "build")
            for cmd in (["cmake", "-S", tmp, "-B", build,
                         "-Dferrovol_DIR=" + ferrovol.get_cmake_dir()],
                        ["cmake", "--build", build],
                        [os.path.join(build, "render_demo"), os.path.join(tmp, "c.png"), "96",
                         "21"]):
                out = subprocess.run(cmd, capture_output=True, text=True, check=False)
                self.assertEqual(out.returncode, 0, "%s: %s%s" % (cmd, out.stdout, out.stderr))
            reader = vtk.vtkPNGReader()
            reader.SetFileName(os.path.join(tmp, "c.png"))
            reader.Update()
            pixels = vtk_to_numpy(reader.GetOutput().GetPointData().GetScalars())
        log("C program through find_package(ferrovol) from %s: %d pixels, %.1f levels "
            "standard deviation" % (ferrovol.get_cmake_dir(), len(pixels), pixels.std()))
        self.assertTrue(os.path.isfile(os.path.join(ferrovol.get_include(), "ferrovol.hpp")))
        self.assertEqual(len(pixels), 96 * 96)
        self.assertGreater(pixels.std(), 5.0)

    def test_matches_this_vtk(self):
        """Composite and MIP at SSIM >= 0.98 against this VTK's own GPU mapper, shaded at
        >= 0.95."""
        for name, blend, shade, floor in (
                ("composite", vtk.vtkVolumeMapper.COMPOSITE_BLEND, False, 0.98),
                ("mip", vtk.vtkVolumeMapper.MAXIMUM_INTENSITY_BLEND, False, 0.98),
                ("shaded", vtk.vtkVolumeMapper.COMPOSITE_BLEND, True, 0.95)):
            ours = draw(ferrovol.vtkFerroVolumeMapper(), blend, shade)
            theirs = draw(vtk.vtkGPUVolumeRayCastMapper(), blend, shade)
            s, p = ssim(ours, theirs), psnr(ours, theirs)
            log("wheel %-9s vtk %s: SSIM %.4f  PSNR %.1f dB  coverage %.3f"
                % (name, vtk.vtkVersion.GetVTKVersion(), s, p, coverage(ours)))
            save("wheel-" + name, ours, theirs)
            self.assertGreater(coverage(ours), 0.1, name)
            self.assertGreaterEqual(s, floor, name)

    def test_pyvista_add_volume(self):
        """Plotter.add_volume, then ferrovol.use on the actor it returns: the same picture as
        PyVista's own mapper."""
        grid = pv.wrap(wavelet())
        images = []
        for use in (False, True):
            p = pv.Plotter(off_screen=True, window_size=(SIZE, SIZE))
            actor = p.add_volume(grid, scalars="RTData", cmap="viridis", opacity="linear")
            if use:
                mapper = ferrovol.use(actor)
                self.assertIs(actor.GetMapper(), mapper)
            p.camera.azimuth = 30.0
            images.append(p.screenshot(return_img=True))
            p.close()
        s = ssim(images[1], images[0])
        log("pyvista add_volume: ferrovol against PyVista's mapper SSIM %.4f  PSNR %.1f dB"
            % (s, psnr(images[1], images[0])))
        save("wheel-pyvista", images[1], images[0])
        self.assertGreater(coverage(images[1]), 0.1)
        self.assertGreaterEqual(s, 0.98)

    def test_pyvista_path_tracing_refines_in_the_event_loop(self):
        """An interactive Plotter: after show() starts the event loop, the path tracer refines
        with no Render() from the script; the loop ends (as `q` ends it) and the screenshot
        taken after show() returns is the refined image, not a new start."""
        spp = 32
        p = pv.Plotter(window_size=(200, 200))
        actor = p.add_volume(pv.wrap(wavelet()), scalars="RTData", cmap="bone",
                             opacity="linear")
        mapper = ferrovol.use(actor, path_trace=True, SamplesPerPixel=spp)
        t0 = time.perf_counter()
        seen = {}

        def check(*_):
            t = time.perf_counter() - t0
            if "converged" not in seen and mapper.GetAccumulatedSamples() >= spp:
                seen["converged"] = t
            if "converged" in seen or t > 60.0:
                p.iren.terminate_app()

        p.iren.add_observer("TimerEvent", check)
        p.iren.create_timer(50, repeating=True)
        p.show(auto_close=False)
        after_loop = mapper.GetMeanAccumulatedSamples()
        image = p.screenshot(return_img=True)
        after_screenshot = mapper.GetMeanAccumulatedSamples()
        log("pyvista path tracing: %s paths per pixel after %.1f s of the event loop alone; "
            "mean paths per pixel after show() returned %.2f, after the screenshot %.2f"
            % (spp, seen.get("converged", -1.0), after_loop, after_screenshot))
        save("wheel-pyvista-path-traced", image)
        p.close()
        self.assertIn("converged", seen, "the accumulation reached SamplesPerPixel")
        self.assertGreaterEqual(after_screenshot, spp)
        self.assertGreater(coverage(image), 0.1)


if __name__ == "__main__":
    unittest.main()
