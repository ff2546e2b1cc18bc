"""vtkFerroVolumeMapper's path tracing render mode: a still render traces its whole budget
and later still renders show the converged image; interactive renders add a few paths per
frame; the property's ScatteringAnisotropy changes the image; cropping and positional
lights work. Images: build/vtk/test-images (pathtrace-*.png)."""
import unittest

import numpy as np
import vtk

import ferrovol
import fvtest
from fvtest import coverage, log, roughness, save, wavelet


def view(cam):
    cam.Azimuth(30.0)
    cam.Elevation(20.0)
    cam.OrthogonalizeViewUp()


def medium(g=0.0):
    p = fvtest.tf_property(opacity=[(37.3531, 0.0), (276.829, 0.4)], interpolation="linear")
    p.SetScatteringAnisotropy(g)
    return p


def path_tracing(mapper):
    mapper.SetRenderModeToPathTrace()
    mapper.SetSamplesPerPixel(16)


class PathTrace(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.src = wavelet(15)

    def scene(self, prop=None, configure=None, size=(96, 96)):
        scene, self.errors = fvtest.ferrovol_scene(self.src, prop or medium(), path_tracing,
                                                   configure, size=size, camera=view)
        return scene

    def test_still_renders_trace_the_budget_once(self):
        s = self.scene()
        first = s.render()
        n1 = s.mapper.GetAccumulatedSamples()
        again = s.render()
        n2 = s.mapper.GetAccumulatedSamples()
        log("still renders: %d then %d paths per pixel; coverage %.3f; unchanged: %s"
            % (n1, n2, coverage(first), np.array_equal(first, again)))
        save("pathtrace-still", first)
        self.assertEqual(self.errors.messages, [])
        self.assertEqual((n1, n2), (16, 16))
        self.assertGreater(coverage(first), 0.2)
        self.assertTrue(np.array_equal(first, again), "the converged image, shown again")

    def test_interactive_renders_accumulate(self):
        s = self.scene(configure=lambda m: m.SetInteractiveSamplesPerPixel(2))
        s.window.SetDesiredUpdateRate(15.0)
        counts = []
        for _ in range(3):
            s.render()
            counts.append(s.mapper.GetAccumulatedSamples())
        s.renderer.GetActiveCamera().Azimuth(10.0)
        s.render()
        counts.append(s.mapper.GetAccumulatedSamples())
        log("interactive renders: %s paths per pixel (the camera moved before the last)"
            % counts)
        self.assertEqual(counts, [2, 4, 6, 2])

    def test_anisotropy_changes_the_image(self):
        images = [self.scene(medium(g)).render() for g in (-0.6, 0.0, 0.6)]
        save("pathtrace-anisotropy", *images)
        d = [float(np.abs(images[i] - images[1]).mean()) for i in (0, 2)]
        log("mean |difference| to isotropic: g = -0.6: %.2f, g = +0.6: %.2f levels" % tuple(d))
        self.assertGreater(min(d), 0.3)

    def test_hybrid_model_and_regions_change_the_image(self):
        def hybrid(regions, attenuation=True):
            def configure(m):
                m.SetGradientThreshold(5.0)
                m.SetScatterRegions(regions)
                m.SetAttenuation(attenuation)
                m.SetBsdfRoughness(0.3)
                m.SetTransmission(0.3)
            return configure
        M = ferrovol.vtkFerroVolumeMapper
        base = self.scene().render()
        surfaces = self.scene(configure=hybrid(M.SCATTER_SURFACES)).render()
        between = self.scene(configure=hybrid(M.SCATTER_BETWEEN)).render()
        clear = self.scene(configure=hybrid(M.SCATTER_SURFACES, False)).render()
        save("pathtrace-regions", base, surfaces, between, clear)
        d = [float(np.abs(x - base).mean()) for x in (surfaces, between)]
        d.append(float(np.abs(clear - surfaces).mean()))
        log("mean |difference| to Henyey-Greenstein everywhere: surfaces only %.2f, "
            "between only %.2f levels; surfaces only without attenuation against with: "
            "%.2f levels" % tuple(d))
        self.assertEqual(self.errors.messages, [])
        self.assertGreater(min(d), 0.3)

    def test_ray_budget_shares_primary_rays(self):
        plain = self.scene().render()
        s = self.scene(configure=lambda m: m.SetSecondaryRays(16))
        shared = s.render()
        save("pathtrace-budget", plain, shared)
        d = float(np.abs(shared - plain).mean())
        ratio = float(shared.mean() / plain.mean())
        log("budget 1x16 against 16x1: mean |difference| %.2f levels, mean brightness ratio "
            "%.3f, %d paths per pixel" % (d, ratio, s.mapper.GetAccumulatedSamples()))
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 16)
        # the same image on average (5%: 96x96 pixels of 1 primary ray each), with the noise
        # of one primary ray per pixel
        self.assertLess(abs(ratio - 1.0), 0.05)
        self.assertGreater(d, 0.3)

    def test_denoiser_smooths_the_image(self):
        noisy = self.scene(configure=lambda m: m.SetSamplesPerPixel(4)).render()
        smooth = self.scene(configure=lambda m: (m.SetSamplesPerPixel(4),
                                                 m.PathTracingDenoiseOn())).render()
        save("pathtrace-denoise", noisy, smooth)
        log("4 paths per pixel: pixel-to-neighbours difference %.2f levels, denoised %.2f"
            % (roughness(noisy), roughness(smooth)))
        self.assertLess(roughness(smooth), 0.6 * roughness(noisy))
        self.assertEqual(self.errors.messages, [])

    def test_cropping_and_positional_lights(self):
        full = self.scene().render()
        s = self.scene(configure=lambda m: (m.CroppingOn(),
                                            m.SetCroppingRegionPlanes(-15, 0, -15, 15, -15, 15)))
        cropped = s.render()
        self.assertEqual(self.errors.messages, [])
        self.assertTrue(s.mapper.GetLastRenderDrew())
        s = self.scene()
        light = vtk.vtkLight()
        light.SetPositional(1)
        light.SetPosition(40, 0, 10)
        light.SetFocalPoint(0, 0, 0)
        s.renderer.AddLight(light)
        lit = s.render()
        save("pathtrace-crop-positional", full, cropped, lit)
        # (a light of the renderer's own replaces VTK's automatic headlight)
        d = float(np.abs(lit - full).mean())
        log("coverage: whole %.3f, cropped to x < 0 %.3f; a positional light instead of the "
            "headlight: mean |difference| %.2f levels" % (coverage(full), coverage(cropped), d))
        self.assertEqual(self.errors.messages, [])
        self.assertLess(coverage(cropped), 0.8 * coverage(full))
        self.assertGreater(coverage(cropped), 0.1 * coverage(full))
        self.assertGreater(d, 0.3)
        self.assertGreater(coverage(lit), 0.2)

if __name__ == "__main__":
    unittest.main()
