"""The two ways frames reach OpenGL give the same pixels: shared memory (zero copy, Vulkan
memory imported with GL_EXT_memory_object_fd) and CPU readback. Also with opaque geometry
(depth in), a reduced image sample distance, window resizes (images re-imported), several
viewports, and single-sampled windows (no multisample resolve of the depth). The automatic
choice shares wherever forcing the shared path works; without GL_EXT_memory_object_fd it
reads back and says why once (the rule itself: TestFerroVolumeOutputChoice.cxx)."""
import json
import os
import subprocess
import sys
import unittest

import numpy as np
import vtk

import ferrovol
import fvtest
from fvtest import Scene, save, tf_property, wavelet


def view(cam):
    cam.Azimuth(30.0)
    cam.Elevation(20.0)
    cam.OrthogonalizeViewUp()


def sphere():
    return fvtest.sphere_actor((8, -8, 18), 9, (0.9, 0.8, 0.2))


def shared_available():
    m = ferrovol.vtkFerroVolumeMapper()
    m.SetOutputPathToShared()
    scene = Scene(m, wavelet(4), tf_property(), size=(16, 16))
    scene.render()
    return m.GetOutputPathName() == "shared", m.GetOutputPathReason()


SHARED, WHY = shared_available()


@unittest.skipUnless(SHARED, "no shared output path here: " + WHY)
class OutputPaths(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.src = wavelet(23)
        fvtest.log("  shared output: " + WHY)

    def both(self, name, configure=None, size=(140, 120), multisamples=None, resize=None,
             actors=True):
        images = {}
        for path in ("Readback", "Shared"):
            scene, errors = fvtest.ferrovol_scene(
                self.src, tf_property(), lambda m: getattr(m, "SetOutputPathTo" + path)(),
                configure, size=size, camera=view, actors=[sphere()] if actors else ())
            m = scene.mapper
            if multisamples is not None:
                scene.window.SetMultiSamples(multisamples)
            scene.renderer.ResetCameraClippingRange()
            img = scene.render()
            if resize:
                scene.window.SetSize(*resize)
                img = scene.render()
            self.assertEqual(m.GetOutputPathName(), path.lower())
            self.assertEqual(errors.messages, [])
            self.assertEqual(errors.warnings, [])
            images[path] = img
        d = np.abs(images["Readback"] - images["Shared"])
        save("paths-" + name, images["Readback"], images["Shared"])
        fvtest.log("  %-28s readback vs shared: max |diff| %.0f, %d px differ"
                   % (name, d.max(), int((d.max(axis=2) > 0).sum())))
        self.assertLessEqual(d.max(), 1.0)
        return images

    def test_plain(self):
        self.both("plain", actors=False)

    def test_opaque_geometry(self):
        self.both("sphere")

    def test_single_sampled_window(self):
        self.both("sphere-no-msaa", multisamples=0)

    def test_image_sample_distance(self):
        for isd in (2.0, 3.0):
            def configure(m, isd=isd):
                m.AutoAdjustSampleDistancesOff()
                m.SetImageSampleDistance(isd)
            self.both("sphere-isd-%g" % isd, configure)

    def test_resize(self):
        self.both("sphere-resized", resize=(90, 160))

    def test_viewports(self):
        images = {}
        for path in ("Readback", "Shared"):
            win = fvtest.new_window()
            win.SetSize(200, 100)
            keep = []
            for x0 in (0.0, 0.5):
                m = ferrovol.vtkFerroVolumeMapper()
                getattr(m, "SetOutputPathTo" + path)()
                m.SetInputConnection(self.src.GetOutputPort())
                vol = vtk.vtkVolume()
                vol.SetMapper(m)
                vol.SetProperty(tf_property())
                ren = vtk.vtkRenderer()
                ren.SetViewport(x0, 0, x0 + 0.5, 1)
                ren.AddVolume(vol)
                ren.AddActor(sphere())
                win.AddRenderer(ren)
                ren.ResetCamera()
                view(ren.GetActiveCamera())
                ren.GetActiveCamera().Azimuth(90 * x0)
                ren.ResetCameraClippingRange()
                keep.append((m, vol, ren))
            win.Render()
            images[path] = fvtest.grab(win)
            self.assertEqual(keep[1][0].GetOutputPathName(), path.lower())
        d = np.abs(images["Readback"] - images["Shared"])
        save("paths-viewports", images["Readback"], images["Shared"])
        fvtest.log("  %-28s readback vs shared: max |diff| %.0f" % ("two viewports", d.max()))
        self.assertLessEqual(d.max(), 1.0)

    def test_switching_paths(self):
        m = ferrovol.vtkFerroVolumeMapper()
        scene = Scene(m, self.src, tf_property(), size=(80, 80), camera=view)
        names = []
        for path in ("Shared", "Readback", "Automatic", "Shared"):
            getattr(m, "SetOutputPathTo" + path)()
            scene.render()
            names.append(m.GetOutputPathName())
        fvtest.log("  switching: %s; automatic chose %s (%s)"
                   % (names, names[2], m.GetOutputPathReason()))
        self.assertEqual(names, ["shared", "readback", "shared", "shared"])
        self.assertRegex(m.GetOutputPathReason(),
                         r"^zero copy: .* device UUID [0-9a-f]{8}(-[0-9a-f]{4}){3}-[0-9a-f]{12}, "
                         r"driver UUID ")
        self.assertEqual(m.GetVolumeUploadCount(), 1)  # the path is not the volume


class ReadbackFallback(unittest.TestCase):
    """Mesa's OpenGL with GL_EXT_memory_object_fd hidden (output_fallback.py, a process of
    its own): automatic mappers read back with the extension named, say so once per process
    in VTK's log and raise no warning; a mapper forced to share warns once, however often it
    chooses its path."""

    def test_without_memory_object_fd(self):
        env = dict(os.environ, MESA_EXTENSION_OVERRIDE="-GL_EXT_memory_object_fd")
        env.pop("FERROVOL_OUTPUT_PATH", None)
        here = os.path.dirname(os.path.abspath(__file__))
        run = subprocess.run([sys.executable, os.path.join(here, "output_fallback.py")],
                             env=env, cwd=here, capture_output=True, text=True, timeout=180)
        self.assertEqual(run.returncode, 0, run.stderr)
        report = json.loads(run.stdout.splitlines()[-1])
        if "Mesa" not in report["vendor"]:
            self.skipTest("OpenGL is not Mesa's (%s): MESA_EXTENSION_OVERRIDE cannot hide "
                          "the extension" % report["vendor"])
        notes = [line for line in run.stderr.splitlines()
                 if "frames go through the CPU (readback)" in line]
        fvtest.log("  without GL_EXT_memory_object_fd: %s; %d log line(s), forced: %d warning(s)"
                   % (report["automatic"]["reason"], len(notes),
                      len(report["forced"]["warnings"])))
        for name in ("automatic", "automatic2", "forced"):
            r = report[name]
            self.assertEqual(r["path"], "readback", name)
            self.assertIn("has no GL_EXT_memory_object_fd", r["reason"], name)
            self.assertEqual(r["errors"], [], name)
        self.assertEqual(report["automatic"]["warnings"], [])
        self.assertEqual(report["automatic2"]["warnings"], [])
        self.assertEqual(len(notes), 1, "\n".join(notes))
        self.assertIn(report["automatic"]["reason"], notes[0])
        self.assertEqual(len(report["forced"]["warnings"]), 1, report["forced"]["warnings"])
        self.assertIn(report["forced"]["reason"], report["forced"]["warnings"][0])


if __name__ == "__main__":
    unittest.main(verbosity=2)
