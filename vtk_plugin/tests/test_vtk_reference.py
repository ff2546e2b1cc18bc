"""vtkFerroVolumeMapper against VTK's own vtkGPUVolumeRayCastMapper: the same scene, the
same settings, SSIM and PSNR printed for each, images saved (ferrovol | VTK | 4x difference).

Thresholds: each sits a margin below what was measured on lavapipe/llvmpipe (the numbers in
the comments), so that a real change in what the mapper hands ferrovol fails while driver
noise does not. Differences that remain are the renderers' own: both march rays on a lattice
anchored at the box entry, but VTK 9.2 takes its first sample one step inside the box
(g_rayOrigin += g_dirStep) where ferrovol samples the entry face, so ferrovol has one extra
sample per ray, which weighs less the finer the step (tests/regression/SAMPLING.md has the
whole comparison).
"""
import os
import unittest

import numpy as np
import vtk

import ferrovol
import fvtest
from fvtest import compare, render_pair, tf_property, wavelet


def shaded():
    p = tf_property(interpolation="linear")
    p.ShadeOn()
    return p


def view(az=30.0, el=20.0):
    def f(cam):
        cam.Azimuth(az)
        cam.Elevation(el)
        cam.OrthogonalizeViewUp()
    return f


class VtkReference(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.src = wavelet(31)

    def check(self, name, min_ssim, min_psnr, prop=None, configure=None, camera=view(),
              data=None, size=(160, 160), actors_factory=None, fine=False):
        if fine:
            # Sample distance 0.25 on both: the sampling lattices' difference mostly vanishes,
            # what remains is what the mapper hands ferrovol.
            inner = configure

            def configure(m):
                if inner:
                    inner(m)
                m.AutoAdjustSampleDistancesOff()
                m.SetSampleDistance(0.25)
        ours, theirs, mapper = render_pair(
            data if data is not None else self.src, prop or (lambda: tf_property()),
            size=size, camera=camera, configure=configure, actors_factory=actors_factory)
        self.assertTrue(mapper.GetLastRenderDrew(), "ferrovol drew nothing")
        self.assertGreater(fvtest.coverage(theirs), 0.02, "VTK's image is empty: bad scene")
        s, p = compare(name, ours, theirs)
        self.assertGreaterEqual(s, min_ssim, "%s: SSIM %.4f" % (name, s))
        self.assertGreaterEqual(p, min_psnr, "%s: PSNR %.1f dB" % (name, p))
        return ours, theirs

    # -- the wavelet composite scene (VTK's TestGPURayCastMapperBenchmark transfer function)
    def test_composite_nearest(self):
        # measured SSIM 0.976, PSNR 33.5 dB (VTK's default: nearest, automatic sampling)
        self.check("ref-composite-nearest", 0.95, 31.0, size=(200, 200))

    def test_composite_linear(self):
        # measured SSIM 0.980, PSNR 33.7 dB
        self.check("ref-composite-linear", 0.96, 31.0, size=(200, 200),
                   prop=lambda: tf_property(interpolation="linear"))

    def test_composite_linear_fine_sampling(self):
        # measured SSIM 0.998, PSNR 43.8 dB
        self.check("ref-composite-linear-fine", 0.99, 40.0, size=(200, 200),
                   prop=lambda: tf_property(interpolation="linear"), fine=True)

    def test_composite_shaded(self):
        # measured SSIM 0.943, PSNR 29.5 dB: shading shows the lattice difference most (with
        # fine sampling it vanishes, next test)
        self.check("ref-composite-shaded", 0.92, 27.5, prop=shaded, size=(200, 200))

    def test_composite_shaded_fine_sampling(self):
        # measured SSIM 0.996, PSNR 41.3 dB
        self.check("ref-composite-shaded-fine", 0.985, 38.0, prop=shaded, size=(200, 200),
                   fine=True)

    # -- other blend modes
    def test_maximum_intensity(self):
        # measured SSIM 0.994, PSNR 42.9 dB
        self.check("ref-mip", 0.97, 30.0, configure=lambda m: m.SetBlendModeToMaximumIntensity())

    def test_minimum_intensity(self):
        # MinIP needs opacity at low values to show anything. Measured SSIM 0.981, PSNR 32.1 dB
        self.check("ref-minip", 0.95, 28.0,
                   prop=lambda: tf_property(opacity=[(37.3531, 1.0), (276.829, 0.2)]),
                   configure=lambda m: m.SetBlendModeToMinimumIntensity())

    def test_average_intensity(self):
        def configure(m):
            m.SetBlendModeToAverageIntensity()
            m.SetAverageIPScalarRange(100.0, 300.0)
        # measured SSIM 0.993, PSNR 46.5 dB
        self.check("ref-average", 0.95, 28.0, configure=configure)

    def test_additive(self):
        # measured SSIM 0.998, PSNR 53.1 dB
        self.check("ref-additive", 0.95, 28.0,
                   prop=lambda: tf_property(opacity=[(37.3531, 0.0), (276.829, 0.02)]),
                   configure=lambda m: m.SetBlendModeToAdditive())

    # -- property settings
    def test_gradient_opacity(self):
        def prop():
            p = tf_property(interpolation="linear")
            g = vtk.vtkPiecewiseFunction()
            # VTK's units: central-difference magnitude times the mean spacing
            g.AddPoint(0.0, 0.0)
            g.AddPoint(12.0, 1.0)
            p.SetGradientOpacity(g)
            return p
        # measured SSIM 0.985, PSNR 35.5 dB
        ours, theirs = self.check("ref-gradient-opacity", 0.95, 28.0, prop=prop)
        plain, _, _ = render_pair(self.src, lambda: tf_property(interpolation="linear"),
                                  camera=view())
        self.assertGreater(np.abs(ours - plain).mean(), 3.0,
                           "gradient opacity did not change the image")

    def test_gradient_opacity_units(self):
        # A step in the gradient opacity function at g (VTK's units) hides every sample with
        # a gradient magnitude below g: sweeping g across the wavelet's gradients, ferrovol's
        # image must darken exactly as VTK's does, which only happens when ferrovol's x axis
        # (|grad s| per world unit) is VTK's divided by the mean spacing.
        def step(g):
            def prop():
                p = tf_property(interpolation="linear")
                f = vtk.vtkPiecewiseFunction()
                f.AddPoint(0.0, 0.0)
                f.AddPoint(g, 0.0)
                f.AddPoint(g + 0.5, 1.0)
                f.AddPoint(100.0, 1.0)
                p.SetGradientOpacity(f)
                return p
            return prop
        small = wavelet(23)
        lums = []
        for g in (4.0, 8.0, 12.0, 16.0):
            ours, theirs, _ = render_pair(small, step(g), size=(120, 120), camera=view())
            lo, lt = fvtest.luminance(ours).mean(), fvtest.luminance(theirs).mean()
            fvtest.log("  gradient opacity step at %4.1f: mean luminance ferrovol %5.1f, "
                       "VTK %5.1f" % (g, lo, lt))
            self.assertLess(abs(lo - lt), 0.08 * lt + 1.0, "step at %g" % g)
            lums.append(lt)
        self.assertGreater(lums[0] - lums[-1], 20.0, "the sweep shows nothing: bad scene")

    def test_transfer_function_midpoint_sharpness(self):
        # VTK's per-node midpoint and sharpness shape the curves between nodes: sampled with
        # VTK's GetTable they reach ferrovol exactly
        def prop():
            ctf = vtk.vtkColorTransferFunction()
            ctf.AddRGBPoint(37.35, 0.1, 0.2, 1.0, 0.2, 0.9)
            ctf.AddRGBPoint(157.1, 1.0, 1.0, 0.8, 0.7, 0.5)
            ctf.AddRGBPoint(276.8, 0.9, 0.1, 0.1)
            otf = vtk.vtkPiecewiseFunction()
            otf.AddPoint(37.35, 0.0, 0.8, 1.0)
            otf.AddPoint(150.0, 0.6, 0.3, 0.7)
            otf.AddPoint(276.8, 1.0)
            p = vtk.vtkVolumeProperty()
            p.SetColor(ctf)
            p.SetScalarOpacity(otf)
            p.SetInterpolationTypeToLinear()
            return p
        # measured SSIM 0.9994, PSNR 43.6 dB
        self.check("ref-midpoint-sharpness-fine", 0.99, 40.0, prop=prop, fine=True)

    def test_direction_matrix(self):
        img = vtk.vtkImageData()
        img.DeepCopy(self.src.GetOutput())
        t = vtk.vtkTransform()
        t.RotateZ(30.0)
        t.RotateX(20.0)
        d = vtk.vtkMatrix3x3()
        for r in range(3):
            for c in range(3):
                d.SetElement(r, c, t.GetMatrix().GetElement(r, c))
        img.SetDirectionMatrix(d)
        # measured SSIM 0.989, PSNR 36.3 dB
        self.check("ref-direction-matrix", 0.96, 31.0, data=img)

    def light_kit(self, name, fine):
        images = []
        for mapper in (ferrovol.vtkFerroVolumeMapper(), vtk.vtkGPUVolumeRayCastMapper()):
            if fine:
                mapper.AutoAdjustSampleDistancesOff()
                mapper.SetSampleDistance(0.25)
            scene = fvtest.Scene(mapper, self.src, shaded(), camera=view())
            kit = vtk.vtkLightKit()  # key, fill and back camera lights plus a headlight
            kit.AddLightsToRenderer(scene.renderer)
            images.append(scene.render())
        return compare(name, images[0], images[1])

    def test_light_kit(self):
        # measured SSIM 0.953, PSNR 32.5 dB
        s, p = self.light_kit("ref-light-kit", fine=False)
        self.assertGreaterEqual(s, 0.93)
        self.assertGreaterEqual(p, 30.0)

    def test_light_kit_fine_sampling(self):
        # measured SSIM 0.994, PSNR 41.0 dB: the lights (camera lights through VTK's light
        # transform, colours, intensities) reach ferrovol as VTK uses them
        s, p = self.light_kit("ref-light-kit-fine", fine=True)
        self.assertGreaterEqual(s, 0.98)
        self.assertGreaterEqual(p, 36.0)

    # -- mapper settings
    def test_cropping_fence(self):
        def configure(m):
            m.CroppingOn()
            m.SetCroppingRegionPlanes(-10, 10, -10, 10, -10, 10)
            m.SetCroppingRegionFlagsToFence()
        # measured SSIM 0.977, PSNR 32.8 dB
        self.check("ref-cropping-fence", 0.95, 27.0, configure=configure)

    def test_clipping_plane(self):
        def configure(m):
            plane = vtk.vtkPlane()
            plane.SetOrigin(0.0, 0.0, 0.0)
            plane.SetNormal(1.0, 0.3, 0.0)
            m.AddClippingPlane(plane)
        # measured SSIM 0.979, PSNR 32.6 dB
        self.check("ref-clipping-plane", 0.96, 28.0, configure=configure)

    def test_clipped_voxel_intensity_units(self):
        # VTK reads ClippedVoxelIntensity in its texture's units: the data's for float, the
        # normalised texel for 8- and 16-bit integers, the range mapped onto [0, 1] for int.
        # Each value below puts the wall beyond the plane mid-range.
        src = vtk.vtkRTAnalyticSource()
        src.SetWholeExtent(-24, 23, -24, 23, -24, 23)
        for kind, scale, value in (("UnsignedChar", 1.0, 0.5), ("Short", 100.0, 0.4),
                                   ("Int", 1000.0, 0.5), ("Float", 1.0, 120.0)):
            cast = vtk.vtkImageShiftScale()
            cast.SetInputConnection(src.GetOutputPort())
            cast.SetShift(-37.35)
            cast.SetScale(scale)
            getattr(cast, "SetOutputScalarTypeTo" + kind)()
            cast.ClampOverflowOn()
            cast.Update()
            data = cast.GetOutput()
            lo, hi = data.GetScalarRange()

            def prop(on=True):
                p = tf_property(color=[(lo, 0.2, 0.29, 1.0), ((lo + hi) / 2, 0.87, 0.87, 0.87),
                                       (hi, 0.7, 0.015, 0.15)],
                                opacity=[(lo, 0.0), (hi, 1.0)], interpolation="linear")
                p.ShadeOn()
                p.SetUseClippedVoxelIntensity(on)
                p.SetClippedVoxelIntensity(value)
                return p

            def configure(m):
                plane = vtk.vtkPlane()
                plane.SetNormal(-0.47, -0.34, -0.81)   # facing the camera
                m.AddClippingPlane(plane)
                m.AutoAdjustSampleDistancesOff()
                m.SetSampleDistance(0.25)
            ours, ref, _ = render_pair(data, prop, camera=view(), configure=configure)
            off, _, _ = render_pair(data, lambda: prop(False), camera=view(),
                                    configure=configure)
            s, p = compare("ref-clipped-voxel-intensity-" + kind, ours, ref)
            effect = float(np.abs(ours - off).mean())
            fvtest.log("    (%s: ClippedVoxelIntensity %g changes the image by %.1f levels)"
                       % (kind, value, effect))
            # measured SSIM 0.9992-0.9997, 51-55 dB; the setting moves the image ~9 levels
            self.assertGreater(s, 0.99, kind)
            self.assertGreater(p, 40.0, kind)
            self.assertGreater(effect, 1.0, kind)

    def test_volume_matrix(self):
        def camera(cam):
            cam.SetPosition(0, 0, 300)
            cam.SetFocalPoint(0, 0, 0)
            cam.SetViewUp(0, 1, 0)
            cam.SetClippingRange(100, 500)
        images = []
        for mapper in (ferrovol.vtkFerroVolumeMapper(), vtk.vtkGPUVolumeRayCastMapper()):
            scene = fvtest.Scene(mapper, self.src, tf_property(), camera=camera)
            scene.volume.SetPosition(15.0, -5.0, 0.0)
            scene.volume.RotateZ(30.0)
            scene.volume.RotateX(20.0)
            scene.volume.SetScale(1.0, 1.4, 0.8)
            images.append(scene.render())
        # measured SSIM 0.994, PSNR 39.7 dB
        s, p = compare("ref-volume-matrix", images[0], images[1])
        self.assertGreaterEqual(s, 0.96)
        self.assertGreaterEqual(p, 28.0)

    def test_parallel_projection(self):
        def camera(cam):
            view()(cam)
            cam.ParallelProjectionOn()
        # measured SSIM 0.977, PSNR 33.9 dB
        self.check("ref-parallel", 0.95, 31.0, camera=camera)

    def test_sample_distance(self):
        def configure(m):
            m.AutoAdjustSampleDistancesOff()
            m.SetSampleDistance(2.5)
        # measured SSIM 0.899, PSNR 27.8 dB: at 2.5 voxels per step the two lattices differ most
        self.check("ref-sample-distance-2.5", 0.87, 25.5, configure=configure)

    def test_cell_data(self):
        point = wavelet(23).GetOutput()
        img = vtk.vtkImageData()
        img.SetExtent(-23, 25, -23, 25, -23, 25)  # one more point per axis: cells = points
        cells = vtk.vtkFloatArray()
        cells.DeepCopy(point.GetPointData().GetScalars())
        cells.SetName("cells")
        img.GetCellData().SetScalars(cells)
        # measured SSIM 0.924, PSNR 26.6 dB (0.954 / 29.3 dB before ferrovol took VTK's
        # first-sample rule, which weighs the rim more): the difference is the rim, VTK
        # stretches cell data to the point bounds, ferrovol renders the grid of cell centres
        # (half a voxel smaller on each side)
        self.check("ref-cell-data", 0.91, 25.5, data=img,
                   prop=lambda: tf_property(interpolation="linear"))

    def test_independent_components(self):
        n = 40
        z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
        r = np.sqrt((x - n / 2) ** 2 + (y - n / 2) ** 2 + (z - n / 2) ** 2)
        a = np.stack([np.clip(20 - r, 0, 20) * 10, x * 5], axis=-1)
        img = fvtest.image_from_array(a.astype(np.float32))

        def prop():
            return fvtest.component_property([(1.0, 0.5, 0.1), (0.1, 0.5, 1.0)], 0.3,
                                             interpolation="linear")
        # measured SSIM 0.9985, PSNR 46.3 dB: where the components overlap both add their
        # premultiplied colours (sum of a_i w_i rgb_i, alpha sum a_i^2 / sum a_i w_i); 0.949 /
        # 23.0 dB when ferrovol took their opacity-weighted mean
        self.check("ref-two-components", 0.99, 42.0, data=img, prop=prop)

    def test_component_materials(self):
        """Shaded independent components, each with its own ambient, diffuse, specular and
        specular power."""
        n = 40
        z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
        r1 = np.sqrt((x - 14) ** 2 + (y - 20) ** 2 + (z - 20) ** 2)
        r2 = np.sqrt((x - 26) ** 2 + (y - 20) ** 2 + (z - 20) ** 2)
        a = np.stack([np.clip(12 - r1, 0, 12) * 16, np.clip(12 - r2, 0, 12) * 16], axis=-1)
        img = fvtest.image_from_array(a.astype(np.float32))

        def prop():
            p = fvtest.component_property([(1.0, 0.5, 0.1), (0.1, 0.5, 1.0)], 0.5,
                                          interpolation="linear")
            p.ShadeOn()
            for c, (ka, kd, ks, power) in enumerate(((0.4, 0.5, 0.0, 1.0),
                                                     (0.05, 0.9, 0.8, 40.0))):
                p.SetAmbient(c, ka)
                p.SetDiffuse(c, kd)
                p.SetSpecular(c, ks)
                p.SetSpecularPower(c, power)
            return p
        # measured SSIM 1.0000, PSNR 67.1 dB (0.9836 / 31.7 dB with component 0's material
        # for both, as ferrovol shaded them before)
        self.check("ref-component-materials", 0.99, 50.0, data=img, prop=prop)

    def test_rgba_mip_minip(self):
        """Dependent RGBA: MIP/MinIP keep the whole sample whose fourth component is largest /
        smallest and draw its RGB with the opacity of that component."""
        n = 40
        z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
        r = np.sqrt((x - n / 2) ** 2 + (y - n / 2) ** 2 + (z - n / 2) ** 2)
        rgb = [x * 6, y * 6, 255 - z * 6]
        peak = np.clip(20 - r, 0, 20) * 12  # MIP: the ray's sample nearest the centre
        well = np.clip(40 + r * 6, 0, 255)  # MinIP: the same sample

        def prop():
            p = tf_property(opacity=[(0, 0.0), (255, 1.0)], interpolation="linear")
            p.IndependentComponentsOff()
            return p
        # measured MIP SSIM 0.9991, PSNR 44.6 dB; MinIP 0.9843, 30.6 dB, the difference on
        # the box's edges, where rays graze the box and the two mappers' first samples differ
        # (before, ferrovol took each component's own extremum and coloured RGBA data with
        # the colour table: another image)
        for mode, name, alpha, s, p in ((1, "mip", peak, 0.99, 40.0),
                                        (2, "minip", well, 0.975, 28.5)):
            img = fvtest.image_from_array(np.round(np.stack(rgb + [alpha], axis=-1))
                                          .astype(np.uint8))
            self.check("ref-rgba-" + name, s, p, data=img, prop=prop,
                       configure=lambda m, mode=mode: m.SetBlendMode(mode))

    def test_opaque_sphere(self):
        def actors():
            return (fvtest.sphere_actor((10, -10, 25), 12, (0.2, 0.9, 0.3), resolution=48),)
        # measured SSIM 0.989, PSNR 35.4 dB
        self.check("ref-sphere-in-volume", 0.95, 27.0, actors_factory=actors,
                   camera=view(0, 0), prop=lambda: tf_property(interpolation="linear"))

    @unittest.skipUnless(os.path.exists(os.path.join(fvtest.DATA, "cranium.vti")),
                         "build/data/cranium.vti missing (scripts/fetch-data.sh)")
    def test_cranium_ct(self):
        reader = vtk.vtkXMLImageDataReader()
        reader.SetFileName(os.path.join(fvtest.DATA, "cranium.vti"))
        reader.Update()
        spacing = reader.GetOutput().GetSpacing()

        def prop():
            p = tf_property(
                color=[(-3024, 0, 0, 0), (-16.4458, 0.729412, 0.254902, 0.301961),
                       (641.385, 0.905882, 0.815686, 0.552941), (3071, 1, 1, 1)],
                opacity=[(-3024, 0), (-16.4458, 0), (641.385, 0.715686), (3071, 0.705882)],
                interpolation="linear")
            p.ShadeOn()
            p.SetScalarOpacityUnitDistance(sum(spacing) / 3.0)
            return p

        def front(cam):
            cam.Elevation(-90.0)
            cam.SetViewUp(0, 0, 1)
            cam.OrthogonalizeViewUp()
            cam.Zoom(1.5)

        def oblique(cam):
            front(cam)
            cam.Azimuth(35.0)
            cam.Elevation(15.0)
            cam.OrthogonalizeViewUp()
        # measured: front SSIM 0.9997, PSNR 58.7 dB; oblique SSIM 0.9996, PSNR 57.5 dB (the
        # opaque bone ends rays within a few samples, where the lattices hardly matter)
        self.check("ref-cranium-ct-front", 0.99, 45.0, data=reader, prop=prop,
                   camera=front, size=(200, 200))
        self.check("ref-cranium-ct-oblique", 0.95, 30.0, data=reader, prop=prop,
                   camera=oblique, size=(200, 200))


if __name__ == "__main__":
    unittest.main(verbosity=2)
