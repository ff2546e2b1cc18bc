"""vtkFerroVolumeMapper has vtkGPUVolumeRayCastMapper's whole public interface (issue 18,
item 1). The walk takes every public name of a script's vtk.vtkGPUVolumeRayCastMapper()
(the object factory makes a vtkOpenGLGPUVolumeRayCastMapper, whose extra names count too):
each exists on vtkFerroVolumeMapper, each constant has VTK's value, each method is called
with a valid argument without an exception, and each setting (Set*, Add*, Remove*,
Select*, *On, *Off) is checked for one of
  image   the rendered image changes (a setting VTK draws),
  effect  something measured changes (progress events, the RenderToImage depth image),
  state   the state reads back as set (pipeline and object bookkeeping, which VTK's mapper
          does not draw either, and settings that only undo another),
  warned  a warning or error on the mapper names it (what ferrovol does not support).
The settings ferrovol implements in this issue's item 1 are also compared with VTK's own
mapper: RenderToImage (colour and depth images, against the window and against VTK's),
the transfer function range types, FinalColorWindow/Level, LockSampleDistanceToInputSpacing;
and the render start/end events, CreateCanonicalView, PreLoadData, IsRenderSupported.
"""
import types
import unittest

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

import ferrovol
import fvtest
from fvtest import Errors, psnr, save, ssim
from interface_settings import (ARGS, DEFAULTS_DIFFER, OWN_MAPPER, SETTINGS, Rig, is_setting,
                                make_property, plain, plane, view, wrapped_properties)


class Interface(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.rig = Rig()
        ref = vtk.vtkGPUVolumeRayCastMapper()
        cls.properties = sorted(wrapped_properties(ref))
        cls.names = sorted(n for n in dir(ref)
                           if not n.startswith("_") and n not in cls.properties)

    @classmethod
    def tearDownClass(cls):
        # (the window goes before fvtest's display owner does, at exit)
        cls.rig.window.Finalize()
        del cls.rig

    def tearDown(self):
        vtk.vtkObject.GlobalWarningDisplayOn()
        vtk.vtkAlgorithm.SetDefaultExecutivePrototype(None)

    def test_names_and_constants(self):
        m = ferrovol.vtkFerroVolumeMapper()
        ref = vtk.vtkGPUVolumeRayCastMapper()
        self.assertTrue(isinstance(m, vtk.vtkGPUVolumeRayCastMapper))
        self.assertEqual([n for n in self.names if not hasattr(m, n)], [])
        constants = 0
        for n in self.names:
            theirs, ours = getattr(ref, n), getattr(m, n)
            if isinstance(theirs, type):
                self.assertEqual(theirs.__name__, ours.__name__, n)
                constants += 1
            elif not callable(theirs):
                self.assertEqual(theirs, ours, n)
                constants += 1
        self.assertEqual(sorted(set(self.properties) - wrapped_properties(m)), [])
        fvtest.log("  %d public names of vtkOpenGLGPUVolumeRayCastMapper, all on "
                   "vtkFerroVolumeMapper (%d constants and enum types with VTK's values), "
                   "and %d wrapped properties" % (len(self.names), constants,
                                                  len(self.properties)))

    def test_defaults_are_vtks(self):
        src = fvtest.wavelet(7)
        m = ferrovol.vtkFerroVolumeMapper()
        ref = vtk.vtkGPUVolumeRayCastMapper()
        m.SetInputConnection(src.GetOutputPort())
        ref.SetInputConnection(src.GetOutputPort())
        compared = []
        for n in self.names:
            if not n.startswith("Get") or n in DEFAULTS_DIFFER or n in ARGS:
                continue
            theirs = getattr(ref, n)()
            if plain(theirs):
                self.assertEqual(getattr(m, n)(), theirs, n)
                compared.append(n)
        # the wrapped properties (VTK >= 9.4) that read the same getters
        differ = {n[3:].lower() for n in DEFAULTS_DIFFER}
        properties = 0
        for n in self.properties:
            if n.replace("_", "") in differ:
                continue
            try:
                theirs = getattr(ref, n)
            except AttributeError:  # write-only
                continue
            if plain(theirs):
                self.assertEqual(getattr(m, n), theirs, n)
                properties += 1
        self.assertEqual(m.GetMaxMemoryInBytes(), 0)
        fvtest.log("  %d getters and %d wrapped properties give VTK's defaults; "
                   "MaxMemoryInBytes is 0 (the device's limit) where VTK's is %d"
                   % (len(compared), properties, ref.GetMaxMemoryInBytes()))

    def test_every_method(self):
        """Each public method called with a valid argument, each setting checked."""
        rig = self.rig
        rig.canonical = vtk.vtkImageData()
        rig.canonical.SetDimensions(32, 32, 1)
        rig.canonical.AllocateScalars(vtk.VTK_UNSIGNED_CHAR, 3)
        m = ferrovol.vtkFerroVolumeMapper()
        settings = [n for n in self.names if callable(getattr(m, n))
                    and not isinstance(getattr(m, n), type) and is_setting(n)]
        others = [n for n in self.names if callable(getattr(m, n))
                  and not isinstance(getattr(m, n), type) and not is_setting(n)]
        self.assertEqual(sorted(set(settings) - set(SETTINGS)), [],
                         "settings without an expectation")

        # the other methods, on one rendered mapper (the volume upload, the frame)
        m = rig.new()
        rig.render()
        m.AddClippingPlane(plane(rig))  # (for GetClippingPlaneInDataCoords)
        for n in others:
            target = m
            if n in OWN_MAPPER:
                target = ferrovol.vtkFerroVolumeMapper()
                OWN_MAPPER[n](target)
            args = ARGS[n](rig) if n in ARGS else ()
            getattr(target, n)(*args)
        self.assertGreater(m.GetTimeToDraw(), 0.0)
        rig.done(m)

        counts = {"image": [], "effect": [], "state": [], "warned": []}
        for n in settings:
            kind, prepare, call, check = SETTINGS[n]
            m = rig.new()
            if prepare:
                prepare(m, rig)
            if kind == "image":
                before = rig.render()
                call(m, rig)
                after = rig.render()
                diff = np.abs(before - after).max()
                self.assertGreaterEqual(diff, 2.0, "%s does not change the image" % n)
            elif kind == "effect":
                before = check(m, rig)
                call(m, rig)
                after = check(m, rig)
                self.assertNotEqual(before, after, "%s changes nothing measured" % n)
            elif kind == "state":
                call(m, rig)
                self.assertTrue(check(m, rig), "%s does not read back" % n)
            else:
                call(m, rig)
                rig.render()
                said = m.errors.warnings + m.errors.messages
                self.assertTrue(any(check in w for w in said),
                                "%s: no warning naming '%s' (%s)" % (n, check, said))
            counts[kind].append(n)
            m.DebugOff()
            rig.done(m)
            vtk.vtkObject.GlobalWarningDisplayOn()
            vtk.vtkAlgorithm.SetDefaultExecutivePrototype(None)
        fvtest.log("  %d methods called; %d settings: %d change the image, %d a measured "
                   "effect, %d read back (bookkeeping), %d warned"
                   % (len(others), len(settings), len(counts["image"]), len(counts["effect"]),
                      len(counts["state"]), len(counts["warned"])))
        fvtest.log("  warned: " + ", ".join(counts["warned"]))


# ---- the settings implemented here, against VTK's mapper ---------------------------------
def reference_scene(mapper, size=(96, 80), background=(0.0, 0.0, 0.0)):
    return fvtest.Scene(mapper, fvtest.wavelet(15), reference_property(), size=size,
                        camera=view, background=background)


def reference_property(opacity=((37.0, 0.0), (150.0, 0.05), (277.0, 0.8))):
    p = make_property()
    p.ShadeOff()
    otf = vtk.vtkPiecewiseFunction()
    for x, a in opacity:
        otf.AddPoint(x, a)
    p.SetScalarOpacity(otf)
    return p


def rgba(img, comps):
    nx, ny, _ = img.GetDimensions()
    return vtk_to_numpy(img.GetPointData().GetScalars()).reshape(ny, nx, comps).astype(
        np.float64)


def render_to_image(mapper, configure=None, **scene_args):
    mapper.RenderToImageOn()
    if configure:
        configure(mapper)
    scene = reference_scene(mapper, **scene_args)
    window = scene.render()
    color, depth = vtk.vtkImageData(), vtk.vtkImageData()
    mapper.GetColorImage(color)
    mapper.GetDepthImage(depth)
    return scene, window, color, depth


class RenderToImage(unittest.TestCase):
    def test_images_are_the_windows(self):
        """The colour image is what the window shows over black, the depth image what the
        volume leaves in the window's depth buffer; the window itself keeps its
        background."""
        m = ferrovol.vtkFerroVolumeMapper()
        _, window, color, depth = render_to_image(m, background=(0.2, 0.3, 0.4))
        self.assertEqual(color.GetDimensions(), (96, 80, 1))
        self.assertEqual(color.GetScalarType(), vtk.VTK_UNSIGNED_CHAR)
        self.assertEqual(depth.GetScalarType(), vtk.VTK_FLOAT)
        self.assertEqual(np.abs(window - np.array([51.0, 76.0, 102.0])).max(), 0.0,
                         "RenderToImage drew into the window")
        self.assertTrue(m.GetColorTexture() is not None and m.GetDepthTexture() is not None)
        c = rgba(color, 4)[::-1]
        d = rgba(depth, 1)[::-1, :, 0]

        w = ferrovol.vtkFerroVolumeMapper()
        scene = reference_scene(w)
        on_black = scene.render()
        z = vtk.vtkFloatArray()
        scene.window.GetZbufferData(0, 0, 95, 79, z)
        zbuf = vtk_to_numpy(z).reshape(80, 96)[::-1]
        seen = c[..., 3] > 0
        color_diff = np.abs(c[..., :3] - on_black)[seen].max()
        depth_diff = np.abs(d - zbuf)[seen].max()
        fvtest.log("  RenderToImage vs the window: %.1f%% of the pixels, colour within %.0f "
                   "levels, depth within %.2e" % (100 * seen.mean(), color_diff, depth_diff))
        self.assertGreater(seen.mean(), 0.2)
        self.assertLessEqual(color_diff, 1.0)
        self.assertLess(depth_diff, 1e-4)
        # (a first visible sample fainter than half a level of alpha has a depth but no
        # colour, as in VTK's images)
        self.assertLess(np.mean(d[~seen] < 1.0), 0.05)

    def test_images_are_vtks(self):
        """The colour and depth images against vtkGPUVolumeRayCastMapper's, in each depth
        type, with ClampDepthToBackface, and at ImageSampleDistance 2."""
        transparent_inside = ((37.0, 0.0), (220.0, 0.0), (277.0, 0.8))
        for label, configure, opacity in (
                ("float", None, None),
                ("unsigned char", lambda m: m.SetDepthImageScalarTypeToUnsignedChar(), None),
                ("unsigned short", lambda m: m.SetDepthImageScalarTypeToUnsignedShort(), None),
                ("clamped", lambda m: m.ClampDepthToBackfaceOn(), transparent_inside),
                ("sample distance 2", lambda m: m.SetImageSampleDistance(2.0), None)):
            images = []
            for mapper in (ferrovol.vtkFerroVolumeMapper(), vtk.vtkGPUVolumeRayCastMapper()):
                prop = reference_property(opacity) if opacity else reference_property()
                mapper.RenderToImageOn()
                if configure:
                    configure(mapper)
                scene = fvtest.Scene(mapper, fvtest.wavelet(15), prop, size=(96, 80),
                                     camera=view)
                scene.render()
                color, depth = vtk.vtkImageData(), vtk.vtkImageData()
                mapper.GetColorImage(color)
                mapper.GetDepthImage(depth)
                images.append((color, depth))
            (c0, d0), (c1, d1) = images
            self.assertEqual(c0.GetDimensions(), c1.GetDimensions(), label)
            self.assertEqual(d0.GetScalarType(), d1.GetScalarType(), label)
            a0, a1 = rgba(c0, 4), rgba(c1, 4)
            scale = {vtk.VTK_UNSIGNED_CHAR: 255.0, vtk.VTK_UNSIGNED_SHORT: 65535.0}.get(
                d0.GetScalarType(), 1.0)
            z0, z1 = rgba(d0, 1)[..., 0] / scale, rgba(d1, 1)[..., 0] / scale
            s, p = ssim(a0, a1), psnr(a0, a1)
            alpha = np.abs(a0[..., 3] - a1[..., 3]).mean()
            near = (z0 < 1.0) | (z1 < 1.0)
            dz = np.abs(z0 - z1)[near].mean()
            save("interface-render-to-image-" + label.replace(" ", "-"), a0[::-1, :, :3],
                 a1[::-1, :, :3])
            fvtest.log("  RenderToImage %-17s colour SSIM %.4f PSNR %.1f dB, alpha %.2f levels "
                       "mean, depth %.4f mean over %.0f%% of the pixels"
                       % (label, s, p, alpha, dz, 100 * near.mean()))
            self.assertGreater(s, 0.98, label)
            self.assertGreater(p, 35.0, label)
            self.assertLess(alpha, 1.0, label)
            # (clamped: VTK's entry point lies about a sample step inside the box)
            self.assertLess(dz, 0.02 if label == "clamped" else 0.005, label)
            self.assertTrue(np.array_equal(z0 < 1.0, z1 < 1.0) or
                            np.mean((z0 < 1.0) != (z1 < 1.0)) < 0.01, label)


class AgainstVTK(unittest.TestCase):
    def test_settings_draw_what_vtk_draws(self):
        """Each setting changes the image, and into VTK's."""
        def gradient_property():
            p = reference_property()
            gof = vtk.vtkPiecewiseFunction()
            gof.AddPoint(0, 0.0)
            gof.AddPoint(10, 1.0)
            p.SetGradientOpacity(gof)
            return p

        def coarse(m):
            m.AutoAdjustSampleDistancesOff()
            m.SetSampleDistance(6.0)

        # (label, property, the configuration compared with, the setting on top of it)
        cases = [
            ("ColorRangeType NATIVE", reference_property, None,
             lambda m: m.SetColorRangeType(m.NATIVE)),
            ("ScalarOpacityRangeType NATIVE",
             lambda: reference_property(((100.0, 0.0), (200.0, 0.3))), None,
             lambda m: m.SetScalarOpacityRangeType(m.NATIVE)),
            ("GradientOpacityRangeType NATIVE", gradient_property, None,
             lambda m: m.SetGradientOpacityRangeType(m.NATIVE)),
            ("FinalColorWindow and Level", reference_property, None,
             lambda m: (m.SetFinalColorWindow(0.5), m.SetFinalColorLevel(0.4))),
            # (a thin shell of opacity, which a step of 6 misses)
            ("LockSampleDistanceToInputSpacing",
             lambda: reference_property(((150.0, 0.0), (160.0, 0.8), (170.0, 0.0))), coarse,
             lambda m: (coarse(m), m.LockSampleDistanceToInputSpacingOn())),
        ]
        for label, prop, base, configure in cases:
            plain, _, _ = fvtest.render_pair(fvtest.wavelet(15), prop, size=(128, 128),
                                             camera=view, configure=base)
            ours, theirs, _ = fvtest.render_pair(fvtest.wavelet(15), prop, size=(128, 128),
                                                 camera=view, configure=configure)
            s, p = fvtest.compare("interface-" + label.split()[0], ours, theirs)
            change = np.abs(ours - plain).mean()
            fvtest.log("    (%s changes the image by %.1f levels on average)" % (label, change))
            self.assertGreater(change, 1.0, label)
            self.assertGreater(s, 0.98, label)
            self.assertGreater(p, 35.0, label)


class Behaviour(unittest.TestCase):
    def test_render_events_and_time(self):
        """VolumeMapperRenderStartEvent and EndEvent around each render, TimeToDraw set,
        as vtkGPUVolumeRayCastMapper::Render."""
        m = ferrovol.vtkFerroVolumeMapper()
        events = []
        m.AddObserver("VolumeMapperRenderStartEvent", lambda o, e: events.append("start"))
        m.AddObserver("VolumeMapperRenderEndEvent", lambda o, e: events.append("end"))
        scene = reference_scene(m)
        scene.render()
        scene.render()
        self.assertEqual(events, ["start", "end", "start", "end"])
        self.assertGreater(m.GetTimeToDraw(), 0.0)

    def test_shader_property_and_update_shader_event_are_warned(self):
        """The volume's ShaderProperty (custom GLSL, replacements, uniforms) and
        UpdateShaderEvent observers belong to VTK's GLSL ray caster: each is warned once,
        and the image stays ferrovol's."""
        m = ferrovol.vtkFerroVolumeMapper()
        errors = Errors(m)
        scene = reference_scene(m)
        plain = scene.render()
        self.assertEqual(errors.warnings, [])
        shader = scene.volume.GetShaderProperty()
        shader.AddFragmentShaderReplacement("//VTK::Shading::Impl", True,
                                            "//VTK::Shading::Impl\n", False)
        shader.GetFragmentCustomUniforms().SetUniformf("fvUnused", 1.0)
        m.AddObserver("UpdateShaderEvent", lambda o, e: None)
        changed = scene.render()
        scene.render()
        self.assertEqual(errors.messages, [])
        self.assertEqual(len(errors.warnings), 2, errors.warnings)
        self.assertIn("ShaderProperty", errors.warnings[0])
        self.assertIn("UpdateShaderEvent", errors.warnings[1])
        np.testing.assert_array_equal(plain, changed)

    def test_support_ratio_preload(self):
        m = ferrovol.vtkFerroVolumeMapper()
        self.assertEqual(m.IsRenderSupported(None, None), 1)
        ratio = [0.0, 0.0, 0.0]
        m.GetReductionRatio(ratio)
        self.assertEqual(ratio, [1.0, 1.0, 1.0])
        scene = reference_scene(m)
        self.assertTrue(m.PreLoadData(scene.renderer, scene.volume))
        self.assertEqual(m.GetVolumeUploadCount(), 1)
        scene.render()
        # (the volume was not uploaded again; ferrovol uploads the tables with a frame)
        self.assertEqual((m.GetVolumeUploadCount(), m.GetTableUploadCount()), (1, 1))
        self.assertTrue(m.GetTransformedInput(0) is not None)
        self.assertEqual(m.GetInputCount(), 1)
        self.assertEqual(m.GetCurrentPass(), m.RenderPass)

    def test_canonical_view(self):
        """CreateCanonicalView renders the volume alone through a parallel camera along the
        direction given and returns the pixels, resampled to the image's size."""
        m = ferrovol.vtkFerroVolumeMapper()
        scene = reference_scene(m, size=(96, 96))
        scene.renderer.AddActor(fvtest.sphere_actor((0, 0, 0), 20.0, (1, 0, 0)))
        scene.render()
        camera = scene.renderer.GetActiveCamera()  # (VTK's method keeps no reference)
        canonical = vtk.vtkImageData()
        canonical.SetDimensions(48, 48, 1)
        canonical.AllocateScalars(vtk.VTK_UNSIGNED_CHAR, 3)
        m.CreateCanonicalView(scene.renderer, scene.volume, canonical, 0, [0.0, 0.0, 1.0],
                              [0.0, 1.0, 0.0])
        self.assertIs(scene.renderer.GetActiveCamera(), camera)
        got = rgba(canonical, 3)[::-1]
        # the same view by hand: the volume alone, parallel, looking along +z
        w = ferrovol.vtkFerroVolumeMapper()
        ref = reference_scene(w, size=(96, 96))
        cam = ref.renderer.GetActiveCamera()
        b = ref.volume.GetBounds()
        centre = ref.volume.GetCenter()
        d = b[1] - b[0]
        cam.SetFocalPoint(centre)
        cam.ParallelProjectionOn()
        cam.SetPosition(centre[0], centre[1], centre[2] - d)
        cam.SetViewUp(0.0, 1.0, 0.0)
        cam.SetParallelScale(d / 2)
        ref.renderer.ResetCameraClippingRange()
        full = ref.render()
        expected = full.reshape(48, 2, 48, 2, 3).mean(axis=(1, 3))
        s = ssim(got, expected)
        save("interface-canonical-view", got, expected)
        fvtest.log("  CreateCanonicalView against the same view rendered by hand: SSIM %.4f"
                   % s)
        self.assertGreater(got.std(), 5.0)
        self.assertGreater(s, 0.9)


if __name__ == "__main__":
    unittest.main(verbosity=2)
