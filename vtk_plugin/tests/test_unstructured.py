"""vtkFerroUnstructuredVolumeMapper against VTK's exact unstructured ray caster
(vtkUnstructuredGridVolumeRayCastMapper, one ray per pixel, its linear integrator: the
quantity ferrovol integrates) on tests/regression/meshes.py's tetrahedralised wavelet,
mixed mesh and prism honeycomb (VTK gets the mixed and prism meshes split into tetrahedra,
ferrovol gets them as they are and the mixed mesh also as VTK's split), point and cell
scalars, opaque geometry; the blend modes VTK's mappers lack draw; isosurfaces against
vtkGPUVolumeRayCastMapper's on the image the mesh came from, and their settings; path tracing
(a still render, and a view that refines itself); Shade and a gradient opacity apply to the mesh as vtkGPUVolumeRayCastMapper applies them to the image it came
from; clipping planes and the array selection apply; bad input (an empty grid, unsupported
cells, two components, no scalars) is an ErrorEvent naming why, not a crash, and a good
input renders again after it."""
import os
import sys
import unittest

import numpy as np
import vtk

import ferrovol
import fvtest
from fvtest import Errors, Scene, compare, coverage, tf_property

sys.path.insert(0, os.path.join(fvtest.ROOT, "tests", "regression"))
import meshes  # noqa: E402  (tests/regression/meshes.py)

# SSIM / PSNR floors against the ray caster: the goal (measured at 300 x 300:
# 0.991-0.994, 38.4-40.5 dB; at 160 x 160 the silhouette's pixels, where the two cast rays
# through a pixel differently, weigh more and the mixed mesh falls to 0.977 / 33 dB).
FLOOR_SSIM, FLOOR_PSNR = 0.98, 35.0
# Isosurfaces against vtkGPUVolumeRayCastMapper's of the image the mesh was split from
# (measured 0.837 / 23.3 dB shaded, 0.861 / 21.3 dB flat at 300 x 300: the wavelet's thin
# ridges, where the linear tetrahedra's surface and the trilinear field's part by a fraction
# of a voxel, and VTK's sample-spaced steps along them).
ISO_FLOOR = (0.8, 20.0)
# Volumetric shadows against vtkGPUVolumeRayCastMapper's (test_volumetric_shadows).
VOLUMETRIC_FLOOR = (0.9, 27.0)


def wavelet_property(unit_distance=1.0):
    p = tf_property(interpolation="linear")
    p.SetScalarOpacityUnitDistance(unit_distance)
    return p


def view(cam):
    cam.Azimuth(35.0)
    cam.Elevation(25.0)
    cam.OrthogonalizeViewUp()


def bunyk():
    m = vtk.vtkUnstructuredGridVolumeRayCastMapper()
    m.AutoAdjustSampleDistancesOff()
    m.SetImageSampleDistance(1.0)
    m.SetRayIntegrator(vtk.vtkUnstructuredGridLinearRayIntegrator())
    return m


def render(mapper, grid, prop=None, size=(300, 300), actors=()):
    errors = Errors(mapper)
    scene = Scene(mapper, grid, prop or wavelet_property(), size=size, camera=view,
                  actors=actors)
    return scene.render(), errors


def cell_scalars(grid):
    f = vtk.vtkPointDataToCellData()
    f.SetInputData(grid)
    f.Update()
    out = vtk.vtkUnstructuredGrid()
    out.ShallowCopy(f.GetOutput())
    out.GetPointData().Initialize()
    return out


class AgainstVtk(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.wavelet = meshes.tet_wavelet(10)
        cls.mixed = meshes.mixed()
        cls.mixed_tets = meshes.tetrahedralised(cls.mixed)
        cls.prisms = meshes.prisms()

    def check(self, name, ours_grid, vtk_grid, floor=(FLOOR_SSIM, FLOOR_PSNR), actors=None):
        mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()
        ours, errors = render(mapper, ours_grid, actors=actors() if actors else ())
        self.assertEqual(errors.messages, [])
        self.assertTrue(mapper.GetLastRenderDrew())
        theirs, _ = render(bunyk(), vtk_grid, actors=actors() if actors else ())
        self.assertGreater(coverage(ours), 0.2, "ferrovol's image is (nearly) empty")
        self.assertGreater(coverage(theirs), 0.2, "VTK's image is (nearly) empty")
        s, p = compare("unstructured-" + name, ours, theirs)
        self.assertGreaterEqual(s, floor[0])
        self.assertGreaterEqual(p, floor[1])

    def test_wavelet_points(self):
        self.check("wavelet", self.wavelet, self.wavelet)

    def test_wavelet_cells(self):
        cells = cell_scalars(self.wavelet)
        self.check("wavelet-cells", cells, cells)

    def test_mixed_split_alike(self):
        self.check("mixed-tets", self.mixed_tets, self.mixed_tets)

    def test_mixed_as_is(self):
        # ferrovol's own split (hexahedra into 12 about their centroid) against
        # vtkDataSetTriangleFilter's: the interpolants differ inside the cells
        self.check("mixed", self.mixed, self.mixed_tets)

    def test_prisms_as_is(self):
        # pentagonal and hexagonal prisms (and wedges) split by ferrovol about their
        # centroids, against vtkDataSetTriangleFilter's split drawn by the ray caster
        self.check("prisms", self.prisms, meshes.tetrahedralised(self.prisms))

    def test_opaque_geometry(self):
        """An opaque sphere half inside the mesh: the rays stop at its depth, as the ray
        caster's (IntermixIntersectingGeometry, on by default) do."""
        self.check("wavelet-sphere", self.wavelet, self.wavelet,
                   actors=lambda: [fvtest.sphere_actor((4.0, 4.0, 8.0), 5.0, (0.9, 0.8, 0.2))])

    def test_clipping_plane(self):
        """A clipping plane through the middle: half the mesh is drawn."""
        plane = vtk.vtkPlane()
        plane.SetOrigin(0.0, 0.0, 0.0)
        plane.SetNormal(1.0, 0.0, 0.0)
        mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()
        mapper.AddClippingPlane(plane)
        clipped, errors = render(mapper, self.wavelet, size=(80, 80))
        whole, _ = render(ferrovol.vtkFerroUnstructuredVolumeMapper(), self.wavelet,
                          size=(80, 80))
        self.assertEqual(errors.messages, [])
        self.assertLess(coverage(clipped), 0.8 * coverage(whole))
        self.assertGreater(coverage(clipped), 0.3 * coverage(whole))

    def test_blend_modes(self):
        """The modes VTK's unstructured mappers ignore: each draws, MIP differs from
        composite."""
        images = {}
        for mode in ("Composite", "MaximumIntensity", "MinimumIntensity", "AverageIntensity",
                     "Additive"):
            mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()
            getattr(mapper, "SetBlendModeTo" + mode)()
            images[mode], errors = render(mapper, self.wavelet, size=(80, 80))
            self.assertEqual(errors.messages, [], mode)
            self.assertGreater(coverage(images[mode]), 0.2, mode)
        self.assertGreater(np.abs(images["Composite"] - images["MaximumIntensity"]).mean(), 1.0)


    def test_shading(self):
        """Shade on (VTK's unstructured mappers ignore it): the mesh is lit as
        vtkGPUVolumeRayCastMapper lights the image it was split from. The two integrate
        differently (samples of the trilinear field against exact linear segments), so the
        floor is the unshaded pair's own agreement, less 0.05 SSIM and 4 dB for the
        gradients (VTK's central differences at its samples against the points' gradients
        interpolated; measured 0.924 / 31.0 dB shaded, 0.957 / 33.7 dB unshaded); and the
        light shows (shaded differs from unshaded)."""
        src = vtk.vtkRTAnalyticSource()
        src.SetWholeExtent(-10, 10, -10, 10, -10, 10)
        src.Update()
        image = src.GetOutput()
        figures = {}
        for shade in (False, True):
            prop = wavelet_property()
            prop.SetShade(shade)
            mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()
            ours, errors = render(mapper, self.wavelet, prop)
            self.assertEqual(errors.messages, [])
            self.assertTrue(mapper.GetLastRenderDrew())
            theirs, _ = render(vtk.vtkGPUVolumeRayCastMapper(), image, prop)
            figures[shade] = ours, compare("unstructured-shade-%d" % shade, ours, theirs)
        (flat, (s0, p0)), (lit, (s1, p1)) = figures[False], figures[True]
        fvtest.log("shaded mesh against vtkGPUVolumeRayCastMapper on the image: SSIM %.4f, "
                   "%.1f dB (unshaded pair %.4f, %.1f dB); shaded against unshaded mesh: "
                   "mean difference %.1f levels" % (s1, p1, s0, p0, np.abs(lit.astype(float) - flat).mean()))
        self.assertGreaterEqual(s1, s0 - 0.05)
        self.assertGreaterEqual(p1, p0 - 4.0)
        self.assertGreater(np.abs(lit.astype(float) - flat).mean(), 2.0)

    def test_volumetric_shadows(self):
        """VolumetricScatteringBlending and GlobalIlluminationReach (vtkGPUVolumeRayCastMapper's
        settings, which VTK's unstructured mappers lack): the mesh's volumetric shadows
        against vtkGPUVolumeRayCastMapper's on the image it was split from, a thin medium
        lit by the headlight (measured 0.961 / 30.8 dB; the same pair shaded without shadows
        0.976 / 39.5 dB: each ray segment's shadow is taken at its middle, constant along
        it, where VTK samples every step), and the shadows show (38 levels)."""
        src = vtk.vtkRTAnalyticSource()
        src.SetWholeExtent(-10, 10, -10, 10, -10, 10)
        src.Update()
        # (thin: the mesh reads opacity as attenuation, the image as opacity per unit slab;
        # both extinctions agree where the opacity is small)
        prop = tf_property(opacity=[(37.3531, 0.0), (276.829, 0.3)], interpolation="linear")
        prop.ShadeOn()
        prop.SetScatteringAnisotropy(-0.3)
        images = {}
        for blending in (0.0, 1.0):
            mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()
            mapper.SetVolumetricScatteringBlending(blending)
            mapper.SetGlobalIlluminationReach(0.5)
            images[blending], errors = render(mapper, self.wavelet, prop)
            self.assertEqual(errors.messages, [])
            self.assertTrue(mapper.GetLastRenderDrew())
        theirs_mapper = vtk.vtkGPUVolumeRayCastMapper()
        theirs_mapper.SetVolumetricScatteringBlending(1.0)
        theirs_mapper.SetGlobalIlluminationReach(0.5)
        theirs, _ = render(theirs_mapper, src.GetOutput(), prop)
        s, p = compare("unstructured-volumetric", images[1.0], theirs)
        shows = np.abs(images[1.0].astype(float) - images[0.0]).mean()
        fvtest.log("mesh volumetric shadows against vtkGPUVolumeRayCastMapper's on the image: "
                   "SSIM %.4f, %.1f dB; against the mesh without them: mean difference %.1f "
                   "levels" % (s, p, shows))
        self.assertGreaterEqual(s, VOLUMETRIC_FLOOR[0])
        self.assertGreaterEqual(p, VOLUMETRIC_FLOOR[1])
        self.assertGreater(shows, 10.0)

    def test_gradient_opacity(self):
        """A gradient opacity (which VTK's unstructured mappers ignore) scales the mesh's
        opacity as vtkGPUVolumeRayCastMapper's scales the image's it was split from: each
        segment by the function at its middle's gradient magnitude. The floor is the pair's
        own agreement without it, less 0.05 SSIM and 4 dB for the gradients (as Shade's;
        measured 0.969 / 34.3 dB with it, 0.957 / 33.7 dB without), and it shows (the image
        differs from the one without it: 9.6 levels on average)."""
        src = vtk.vtkRTAnalyticSource()
        src.SetWholeExtent(-10, 10, -10, 10, -10, 10)
        src.Update()
        image = src.GetOutput()
        g = vtk.vtkPiecewiseFunction()
        g.AddPoint(0.0, 0.0)
        g.AddPoint(30.0, 1.0)
        figures = {}
        for graded in (False, True):
            prop = wavelet_property()
            if graded:
                prop.SetGradientOpacity(g)
            mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()
            ours, errors = render(mapper, self.wavelet, prop)
            self.assertEqual(errors.messages, [])
            self.assertTrue(mapper.GetLastRenderDrew())
            theirs, _ = render(vtk.vtkGPUVolumeRayCastMapper(), image, prop)
            figures[graded] = ours, compare("unstructured-gradient-opacity-%d" % graded, ours,
                                            theirs)
        (plain, (s0, p0)), (go, (s1, p1)) = figures[False], figures[True]
        fvtest.log("mesh with gradient opacity against vtkGPUVolumeRayCastMapper on the image: "
                   "SSIM %.4f, %.1f dB (without it %.4f, %.1f dB); against the mesh without "
                   "it: mean difference %.1f levels"
                   % (s1, p1, s0, p0, np.abs(go.astype(float) - plain).mean()))
        self.assertGreaterEqual(s1, s0 - 0.05)
        self.assertGreaterEqual(p1, p0 - 4.0)
        self.assertGreater(np.abs(go.astype(float) - plain).mean(), 2.0)

    def test_isosurfaces(self):
        """Isosurfaces (which VTK's unstructured mappers do not draw): the mesh's iso-values
        150 (translucent) and 220, shaded, against vtkGPUVolumeRayCastMapper's isosurfaces of
        the image the mesh was split from (exact crossings of the linear tetrahedra against
        crossings of the trilinear field: the surfaces differ by a fraction of a voxel);
        flat colours with Shade off."""
        src = vtk.vtkRTAnalyticSource()
        src.SetWholeExtent(-10, 10, -10, 10, -10, 10)
        src.Update()
        figures = {}
        for shade in (True, False):
            prop = tf_property(opacity=[(37.3531, 0.4), (276.829, 1.0)], interpolation="linear")
            prop.SetShade(shade)
            prop.GetIsoSurfaceValues().SetValue(0, 150.0)
            prop.GetIsoSurfaceValues().SetValue(1, 220.0)
            mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()
            mapper.SetBlendModeToIsoSurface()
            ours, errors = render(mapper, self.wavelet, prop)
            self.assertEqual(errors.messages, [])
            self.assertTrue(mapper.GetLastRenderDrew())
            theirs_mapper = vtk.vtkGPUVolumeRayCastMapper()
            theirs_mapper.SetBlendModeToIsoSurface()
            theirs, _ = render(theirs_mapper, src.GetOutput(), prop)
            self.assertGreater(coverage(ours), 0.2, "ferrovol's image is (nearly) empty")
            figures[shade] = ours, compare("unstructured-iso-shade-%d" % shade, ours, theirs)
        (lit, (s1, p1)), (flat, (s0, p0)) = figures[True], figures[False]
        fvtest.log("mesh isosurfaces against vtkGPUVolumeRayCastMapper's on the image: shaded "
                   "SSIM %.4f, %.1f dB; flat SSIM %.4f, %.1f dB" % (s1, p1, s0, p0))
        self.assertGreaterEqual(min(s0, s1), ISO_FLOOR[0])
        self.assertGreaterEqual(min(p0, p1), ISO_FLOOR[1])
        self.assertGreater(np.abs(lit.astype(float) - flat).mean(), 2.0)

    def test_selected_array(self):
        """SelectScalarArray with ScalarMode UsePointFieldData draws the array named, not the
        active scalars: a constant 37.35 (transparent in the property) draws nothing."""
        g = vtk.vtkUnstructuredGrid()
        g.ShallowCopy(self.wavelet)
        flat = vtk.vtkFloatArray()
        flat.SetName("flat")
        flat.SetNumberOfTuples(g.GetNumberOfPoints())
        flat.Fill(37.3531)
        g.GetPointData().AddArray(flat)
        mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()
        mapper.SetScalarModeToUsePointFieldData()
        mapper.SelectScalarArray("flat")
        image, errors = render(mapper, g, size=(80, 80))
        self.assertEqual(errors.messages, [])
        self.assertTrue(mapper.GetLastRenderDrew())
        self.assertLess(coverage(image), 0.01)
        mapper.SelectScalarArray("RTData")
        self.assertGreater(coverage(render(mapper, g, size=(80, 80))[0]), 0.2)


class Uploads(unittest.TestCase):
    def test_unchanged_input_uploads_once(self):
        """Renders that change only the camera upload nothing; new scalar values upload the
        mesh again, a new colour function the tables."""
        grid = meshes.tet_wavelet(4)
        mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()
        scene = Scene(mapper, grid, wavelet_property(), size=(64, 64), camera=view)
        for _ in range(3):
            scene.render()
            scene.renderer.GetActiveCamera().Azimuth(20.0)
        self.assertTrue(mapper.GetLastRenderDrew())
        self.assertEqual((mapper.GetMeshUploadCount(), mapper.GetTableUploadCount()), (1, 1))
        grid.GetPointData().GetScalars().Modified()
        scene.render()
        self.assertEqual(mapper.GetMeshUploadCount(), 2)
        scene.volume.GetProperty().GetRGBTransferFunction().AddRGBPoint(100.0, 1.0, 0.0, 0.0)
        scene.render()
        self.assertEqual((mapper.GetMeshUploadCount(), mapper.GetTableUploadCount()), (2, 2))


class PathTraced(unittest.TestCase):
    """SetRenderModeToPathTrace: the mesh as a scattering medium, with vtkFerroVolumeMapper's
    path tracing settings. Images: build/vtk/test-images/unstructured-pathtrace-*.png."""
    @classmethod
    def setUpClass(cls):
        cls.grid = meshes.tet_wavelet(6)

    def scene(self, spp, mode):
        mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()
        mapper.SetRenderModeToPathTrace()
        mapper.SetSamplesPerPixel(spp)
        getattr(mapper, "SetProgressiveModeTo" + mode)()
        errors = Errors(mapper)
        return Scene(mapper, self.grid, wavelet_property(), size=(64, 64), camera=view), errors

    def test_still_render_traces_every_path(self):
        """Not progressive: one render traces SamplesPerPixel paths; the medium scatters the
        sky and the headlight (lit, and not the ray-cast image); changing the camera starts
        over."""
        s, errors = self.scene(16, "Off")
        traced = s.render()
        self.assertEqual(errors.messages, [])
        self.assertTrue(s.mapper.GetLastRenderDrew())
        self.assertFalse(s.mapper.GetLastRenderProgressive())
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 16)
        cast, _ = render(ferrovol.vtkFerroUnstructuredVolumeMapper(), self.grid, size=(64, 64))
        fvtest.save("unstructured-pathtrace-still", traced, cast)
        fvtest.log("path-traced mesh: coverage %.2f, mean %.1f levels where drawn; ray cast "
                   "%.2f" % (coverage(traced), traced[traced.max(axis=2) > 4].mean(),
                             coverage(cast)))
        self.assertGreater(coverage(traced), 0.2)
        self.assertGreater(traced[traced.max(axis=2) > 4].mean(), 10.0)
        self.assertGreater(np.abs(traced - cast).mean(), 2.0)
        s.renderer.GetActiveCamera().Azimuth(10.0)
        s.render()
        self.assertEqual(s.mapper.GetAccumulatedSamples(), 16)

    def test_view_refines_itself(self):
        """Progressive, in a window whose application runs the interactor's timers: each
        render traces within its budget, and the timers render again until the accumulation
        holds SamplesPerPixel, then stop."""
        s, errors = self.scene(3, "On")
        s.mapper.SetPathTracingTimeBudget(0.05)
        iren, live = fvtest.timer_interactor(s.window)
        counts = []
        s.window.AddObserver("EndEvent",
                             lambda *_: counts.append(s.mapper.GetAccumulatedSamples()))
        s.window.Render()
        fvtest.fire_timers(iren, live, lambda: len(counts) >= 1000)
        fvtest.log("a path-traced mesh refining itself: paths per pixel after each render %s"
                   % counts)
        self.assertEqual(errors.messages, [])
        self.assertTrue(s.mapper.GetLastRenderProgressive())
        self.assertEqual(counts[-1], 3)
        self.assertGreater(len(counts), 1)
        self.assertTrue(all(b >= a for a, b in zip(counts, counts[1:])))
        self.assertEqual(live, set())


class Isosurfaces(unittest.TestCase):
    def test_settings_and_no_values(self):
        """The isosurface settings reach the mesh (ambient occlusion, environment light,
        gradient shininess: each changes the image) and print; without iso-values nothing is
        drawn, silently, as vtkGPUVolumeRayCastMapper draws nothing."""
        prop = wavelet_property()
        prop.ShadeOn()
        prop.GetIsoSurfaceValues().SetValue(0, 150.0)
        mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()
        mapper.SetBlendModeToIsoSurface()
        errors = Errors(mapper)
        scene = Scene(mapper, meshes.tet_wavelet(6), prop, size=(64, 64), camera=view)
        plain = scene.render().astype(float)
        self.assertGreater(coverage(plain), 0.2)
        settings = [
            lambda: mapper.SetAmbientOcclusionSamples(16),
            lambda: mapper.SetEnvironmentLighting(1.0),
            lambda: mapper.ShininessFromGradientOn(),
        ]
        last = plain
        for change in settings:
            change()
            image = scene.render().astype(float)
            self.assertGreater(np.abs(image - last).mean(), 0.05)
            last = image
        self.assertEqual(errors.messages, [])
        self.assertIn("AmbientOcclusionSamples: 16", str(mapper))
        prop.GetIsoSurfaceValues().SetNumberOfContours(0)
        self.assertLess(coverage(scene.render()), 0.01)
        self.assertFalse(mapper.GetLastRenderDrew())
        self.assertEqual(errors.messages, [])


class BadInput(unittest.TestCase):
    def setUp(self):
        self.mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()
        self.errors = Errors(self.mapper)
        self.good = meshes.tet_wavelet(4)
        self.scene = Scene(self.mapper, self.good, wavelet_property(), size=(64, 64),
                           camera=view)
        self.assertGreater(coverage(self.scene.render()), 0.1)
        self.assertEqual(self.errors.messages, [])

    def refused(self, grid, words):
        self.mapper.SetInputData(grid)
        image = self.scene.render()
        self.assertFalse(self.mapper.GetLastRenderDrew())
        self.assertTrue(self.errors.messages, "no ErrorEvent")
        for w in words:
            self.assertIn(w, self.errors.last())
        self.assertLess(coverage(image), 0.01)
        # the good input renders again
        self.mapper.SetInputData(self.good)
        self.assertGreater(coverage(self.scene.render()), 0.1)
        self.assertTrue(self.mapper.GetLastRenderDrew())

    def test_empty_grid(self):
        empty = vtk.vtkUnstructuredGrid()
        empty.SetPoints(vtk.vtkPoints())
        empty.GetPointData().SetScalars(vtk.vtkFloatArray())
        self.refused(empty, ["no cells"])

    def test_unsupported_cells(self):
        # a grid of triangles (2D cells) with point scalars
        g = vtk.vtkUnstructuredGrid()
        pts = vtk.vtkPoints()
        for p in ((0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)):
            pts.InsertNextPoint(p)
        g.SetPoints(pts)
        for ids in ((0, 1, 2), (1, 3, 2)):
            g.InsertNextCell(vtk.VTK_TRIANGLE, 3, ids)
        s = vtk.vtkFloatArray()
        for v in range(4):
            s.InsertNextValue(100.0 * v)
        g.GetPointData().SetScalars(s)
        self.refused(g, ["ferrovol could not upload the mesh"])

    def test_two_components(self):
        g = vtk.vtkUnstructuredGrid()
        g.DeepCopy(self.good)
        two = vtk.vtkFloatArray()
        two.SetName("two")
        two.SetNumberOfComponents(2)
        two.SetNumberOfTuples(g.GetNumberOfPoints())
        two.Fill(100.0)
        g.GetPointData().SetScalars(two)
        self.refused(g, ["2 components", "one"])

    def test_no_scalars(self):
        g = vtk.vtkUnstructuredGrid()
        g.DeepCopy(self.good)
        g.GetPointData().Initialize()
        self.refused(g, ["no scalars"])


if __name__ == "__main__":
    unittest.main()
