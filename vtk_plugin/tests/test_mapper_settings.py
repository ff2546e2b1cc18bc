"""Each vtkFerroVolumeMapper / vtkVolumeProperty setting shows its effect in the image (or in
the mapper's state). The images are saved to build/vtk/test-images (settings-*.png)."""
import unittest

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk

import ferrovol
import fvtest
from fvtest import Errors, Scene, coverage, image_from_array, save, ssim, tf_property, wavelet


def view(cam):
    cam.Azimuth(30.0)
    cam.Elevation(20.0)
    cam.OrthogonalizeViewUp()


def mean_diff(a, b):
    return float(np.abs(a - b).mean())


def parallel_camera(focal, distance, scale, clipping):
    """A parallel projection looking down -z at focal from distance, y up."""
    def camera(cam):
        cam.SetFocalPoint(*focal)
        cam.SetPosition(focal[0], focal[1], focal[2] + distance)
        cam.SetViewUp(0, 1, 0)
        cam.ParallelProjectionOn()
        cam.SetParallelScale(scale)
        cam.SetClippingRange(*clipping)
    return camera


def memory_budget(max_bytes, fraction, progress):
    """A render() configure hook: a budget of max_bytes x fraction (MaxMemoryInBytes,
    MaxMemoryFraction), each progress event's value appended to the list progress."""
    def configure(m):
        m.SetMaxMemoryInBytes(max_bytes)
        m.SetMaxMemoryFraction(fraction)
        m.AddObserver(vtk.vtkCommand.ProgressEvent, lambda o, e: progress.append(o.GetProgress()))
    return configure


class Settings(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.src = wavelet(23)

    def render(self, configure=None, prop=None, data=None, size=(120, 120), camera=view,
               scene_hook=None):
        scene, errors = fvtest.ferrovol_scene(
            data if data is not None else self.src, prop if prop is not None else tf_property(),
            configure, size=size, camera=camera)
        mapper = scene.mapper
        if scene_hook:
            scene_hook(scene)
        img = scene.render()
        self.assertEqual(errors.messages, [], "unexpected error")
        self.assertTrue(mapper.GetLastRenderDrew(), "nothing drawn")
        self._keep = scene
        return img, mapper

    # -- vtkVolumeMapper ------------------------------------------------------------------
    def test_blend_modes(self):
        modes = {
            "composite": lambda m: m.SetBlendModeToComposite(),
            "maximum": lambda m: m.SetBlendModeToMaximumIntensity(),
            "minimum": lambda m: m.SetBlendModeToMinimumIntensity(),
            "average": lambda m: m.SetBlendModeToAverageIntensity(),
            "additive": lambda m: m.SetBlendModeToAdditive(),
        }
        prop = lambda: tf_property(opacity=[(37.3531, 0.05), (276.829, 0.6)])  # noqa: E731
        images = {name: self.render(conf, prop())[0] for name, conf in modes.items()}
        save("settings-blend-modes", *images.values())
        names = list(images)
        for i, a in enumerate(names):
            self.assertGreater(coverage(images[a]), 0.1, a)
            for b in names[i + 1:]:
                d = mean_diff(images[a], images[b])
                fvtest.log("  blend %s vs %s: mean |diff| %.1f" % (a, b, d))
                self.assertGreater(d, 2.0, "%s and %s look the same" % (a, b))
        # MIP is at least as bright as MinIP everywhere the volume is
        lum = fvtest.luminance
        self.assertGreater(lum(images["maximum"]).mean(), lum(images["minimum"]).mean())

    def test_average_ip_scalar_range(self):
        def mode(lo, hi):
            def f(m):
                m.SetBlendModeToAverageIntensity()
                m.SetAverageIPScalarRange(lo, hi)
            return f
        full, _ = self.render(mode(-1e30, 1e30))
        high, _ = self.render(mode(200.0, 1e30))
        d = mean_diff(full, high)
        fvtest.log("  average range [200, inf) vs everything: mean |diff| %.1f" % d)
        self.assertGreater(d, 3.0)

    def test_cropping_presets(self):
        planes = (-8, 8, -8, 8, -8, 8)
        images = {"off": self.render()[0]}
        for preset in ("SubVolume", "Fence", "InvertedFence", "Cross", "InvertedCross"):
            def conf(m, preset=preset):
                m.CroppingOn()
                m.SetCroppingRegionPlanes(*planes)
                getattr(m, "SetCroppingRegionFlagsTo" + preset)()
            images[preset], mapper = self.render(conf)
            self.assertEqual(mapper.GetCroppingRegionFlags(),
                             {"SubVolume": 0x2000, "Fence": 0x2ebfeba,
                              "InvertedFence": 0x5140145, "Cross": 0x417410,
                              "InvertedCross": 0x7be8bef}[preset])
        save("settings-cropping", *images.values())
        cov = {k: coverage(v) for k, v in images.items()}
        fvtest.log("  cropping coverage: " + ", ".join("%s %.3f" % kv for kv in cov.items()))
        self.assertLess(cov["SubVolume"], 0.5 * cov["off"])
        names = list(images)
        for i, a in enumerate(names):
            for b in names[i + 1:]:
                self.assertGreater(mean_diff(images[a], images[b]), 1.0, (a, b))
        # cropping planes move with SetCroppingRegionPlanes
        def wide(m):
            m.CroppingOn()
            m.SetCroppingRegionPlanes(-16, 16, -16, 16, -16, 16)
            m.SetCroppingRegionFlagsToSubVolume()
        self.assertGreater(coverage(self.render(wide)[0]), cov["SubVolume"] * 1.5)

    def test_clipping_planes(self):
        full, _ = self.render()

        def clip(normal):
            def f(m):
                p = vtk.vtkPlane()
                p.SetOrigin(0, 0, 0)
                p.SetNormal(*normal)
                m.AddClippingPlane(p)
            return f
        left, _ = self.render(clip((-1, 0, 0)))
        right, _ = self.render(clip((1, 0, 0)))

        def two(m):
            clip((1, 0, 0))(m)
            clip((0, 1, 0))(m)
        quarter, mapper = self.render(two)
        save("settings-clipping", full, left, right, quarter)
        c = [coverage(x) for x in (full, left, right, quarter)]
        fvtest.log("  clipping coverage: all %.3f, x<0 %.3f, x>0 %.3f, x>0 and y>0 %.3f" % tuple(c))
        self.assertLess(c[1], 0.8 * c[0])
        self.assertLess(c[2], 0.8 * c[0])
        self.assertLess(c[3], c[2])
        self.assertGreater(mean_diff(left, right), 5.0)
        self.assertEqual(mapper.GetClippingPlanes().GetNumberOfItems(), 2)

    def test_eight_clipping_planes(self):
        # Eight planes each cut one corner of the cube off (vtkGPUVolumeRayCastMapper takes 8);
        # a ninth plane is beyond what VTK's mapper takes: a warning names the count.
        corners = [((12 * sx, 12 * sy, 12 * sz), (-sx, -sy, -sz))
                   for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]

        def planes(n, extra=()):
            def f(m):
                for origin, normal in corners[:n] + list(extra):
                    p = vtk.vtkPlane()
                    p.SetOrigin(*origin)
                    p.SetNormal(*normal)
                    m.AddClippingPlane(p)
            return f
        images, warnings = {}, {}
        for name, configure in (("7", planes(7)), ("8", planes(8)),
                                ("9", planes(8, [((0, 0, 0), (1, 0, 0))]))):
            scene, errors = fvtest.ferrovol_scene(self.src, tf_property(), configure,
                                                  size=(120, 120), camera=view)
            images[name] = scene.render()
            self.assertEqual(errors.messages, [], name)
            warnings[name] = errors.warnings
        save("settings-clipping-eight", images["7"], images["8"], images["9"])
        d78, d89 = mean_diff(images["7"], images["8"]), mean_diff(images["8"], images["9"])
        fvtest.log("  clipping: 7 vs 8 planes %.2f, 8 vs 9 planes %.2f; warnings %s"
                   % (d78, d89, warnings["9"]))
        self.assertGreater(d78, 0.5)  # the eighth plane cuts its corner
        self.assertEqual(d89, 0.0)    # the ninth is not used
        self.assertEqual(warnings["7"] + warnings["8"], [])
        self.assertEqual(len(warnings["9"]), 1)
        self.assertIn("9 clipping planes", warnings["9"][0])

    def test_normal_from_opacity(self):
        # Composite: normals from the opacity's gradient, silently (an opacity peak turns
        # them over past it); shaded isosurfaces keep the scalar gradient, with a warning.
        peak = [(37.3531, 0.0), (130.0, 0.0), (160.0, 0.8), (190.0, 0.0), (276.829, 0.0)]

        def shaded_peak():
            p = tf_property(opacity=peak, interpolation="linear")
            p.ShadeOn()
            p.GetIsoSurfaceValues().SetValue(0, 160.0)
            return p
        images, warnings = {}, {}
        for name, configure in (
                ("scalar", None),
                ("opacity", lambda m: m.ComputeNormalFromOpacityOn()),
                ("iso-scalar", lambda m: m.SetBlendModeToIsoSurface()),
                ("iso-opacity", lambda m: (m.SetBlendModeToIsoSurface(),
                                           m.ComputeNormalFromOpacityOn()))):
            scene, errors = fvtest.ferrovol_scene(self.src, shaded_peak(), configure,
                                                  size=(120, 120), camera=view)
            images[name] = scene.render()
            self.assertEqual(errors.messages, [], name)
            warnings[name] = errors.warnings
        save("settings-normal-from-opacity", images["scalar"], images["opacity"])
        d, d_iso = (mean_diff(images["scalar"], images["opacity"]),
                    mean_diff(images["iso-scalar"], images["iso-opacity"]))
        fvtest.log("  ComputeNormalFromOpacity: composite changes %.2f, isosurface %.2f; "
                   "warnings %s" % (d, d_iso, warnings["iso-opacity"]))
        self.assertGreater(d, 0.3)
        self.assertEqual(d_iso, 0.0)
        self.assertEqual(warnings["opacity"], [])
        self.assertEqual(len(warnings["iso-opacity"]), 1)
        self.assertIn("ComputeNormalFromOpacity", warnings["iso-opacity"][0])

    def test_ghost_arrays(self):
        # Cells and points the ghost arrays mark (vtkUniformGrid blanking) are left out as
        # vtkGPUVolumeRayCastMapper leaves them out, in ray casting and in the isosurface
        # blend mode; an all-zero ghost array changes nothing.
        base = self.src.GetOutput()
        pd = base.GetDimensions()
        cd = [d - 1 for d in pd]

        def with_ghosts(cells=False, points=False):
            img = vtk.vtkImageData()
            img.DeepCopy(base)
            z, y, x = np.mgrid[0:cd[2], 0:cd[1], 0:cd[0]]
            hide = (x < cd[0] // 2) & (y > cd[1] // 3) if cells else np.zeros_like(x, bool)
            ghosts = numpy_to_vtk((hide * vtk.vtkDataSetAttributes.HIDDENCELL)
                                  .astype(np.uint8).ravel(), deep=True)
            ghosts.SetName(vtk.vtkDataSetAttributes.GhostArrayName())
            img.GetCellData().AddArray(ghosts)
            if points:
                z, y, x = np.mgrid[0:pd[2], 0:pd[1], 0:pd[0]]
                hide = (z > pd[2] // 2) & (x > pd[0] // 3)
                pg = numpy_to_vtk((hide * vtk.vtkDataSetAttributes.HIDDENPOINT)
                                  .astype(np.uint8).ravel(), deep=True)
                pg.SetName(vtk.vtkDataSetAttributes.GhostArrayName())
                img.GetPointData().AddArray(pg)
            return img

        def both(data, configure=None, prop=tf_property):
            ours, warnings = None, None
            images = []
            for mapper in (ferrovol.vtkFerroVolumeMapper(), vtk.vtkGPUVolumeRayCastMapper()):
                errors = Errors(mapper)
                if configure:
                    configure(mapper)
                scene = Scene(mapper, data, prop(), size=(120, 120), camera=view)
                images.append(scene.render())
                if ours is None:
                    ours, warnings = errors.messages, errors.warnings
            self.assertEqual(ours, [])
            return images, warnings
        (plain, _), _ = both(base)
        (clear, clear_vtk), w_clear = both(with_ghosts())
        (cells, cells_vtk), w_cells = both(with_ghosts(cells=True))
        (mixed, mixed_vtk), w_mixed = both(with_ghosts(cells=True, points=True))
        save("settings-ghost-arrays", cells, cells_vtk, mixed, mixed_vtk)
        s_cells, s_mixed = ssim(cells, cells_vtk), ssim(mixed, mixed_vtk)
        fvtest.log("  ghost arrays against vtkGPUVolumeRayCastMapper: hidden cells SSIM %.4f "
                   "(%.1f dB), hidden cells and points %.4f (%.1f dB); hiding moves the image "
                   "%.1f levels" % (s_cells, fvtest.psnr(cells, cells_vtk), s_mixed,
                                    fvtest.psnr(mixed, mixed_vtk), mean_diff(plain, cells)))
        self.assertEqual(mean_diff(plain, clear), 0.0)
        self.assertGreater(mean_diff(plain, cells), 5.0)
        self.assertGreater(mean_diff(cells, mixed), 2.0)
        self.assertGreater(s_cells, 0.98)
        self.assertGreater(s_mixed, 0.98)
        self.assertEqual(w_clear + w_cells + w_mixed, [])

        def iso_property():
            p = tf_property()
            p.GetIsoSurfaceValues().SetValue(0, 160.0)
            return p

        def iso(m):
            m.SetBlendModeToIsoSurface()

        (iso_plain, iso_plain_vtk), _ = both(base, iso, iso_property)
        (iso_cells, iso_vtk), w_iso = both(with_ghosts(cells=True), iso, iso_property)
        save("settings-ghost-arrays-iso", iso_plain, iso_plain_vtk, iso_cells, iso_vtk)
        s_plain, s_iso = ssim(iso_plain, iso_plain_vtk), ssim(iso_cells, iso_vtk)
        fvtest.log("  isosurface against vtkGPUVolumeRayCastMapper: SSIM %.4f (%.1f dB), with "
                   "hidden cells %.4f (%.1f dB); hiding moves the image %.1f levels"
                   % (s_plain, fvtest.psnr(iso_plain, iso_plain_vtk), s_iso,
                      fvtest.psnr(iso_cells, iso_vtk), mean_diff(iso_plain, iso_cells)))
        self.assertEqual(w_iso, [])
        self.assertGreater(mean_diff(iso_plain, iso_cells), 5.0)
        self.assertGreater(s_iso, s_plain - 0.02)

    def test_sample_distance(self):
        def sd(d):
            def f(m):
                m.AutoAdjustSampleDistancesOff()
                m.SetSampleDistance(d)
            return f
        auto, _ = self.render()
        fine, _ = self.render(sd(0.5))
        coarse, _ = self.render(sd(4.0))
        save("settings-sample-distance", auto, fine, coarse)
        d_fine, d_coarse = mean_diff(auto, fine), mean_diff(auto, coarse)
        fvtest.log("  sample distance: auto vs 0.5 %.2f, auto vs 4.0 %.2f" % (d_fine, d_coarse))
        self.assertGreater(d_coarse, 2.0 * d_fine)
        # opacity correction keeps the look: coarse sampling changes detail, not the total
        self.assertGreater(ssim(auto, fine), 0.95)
        # AutoAdjustSampleDistances on ignores SampleDistance
        def ignored(m):
            m.SetSampleDistance(4.0)
        self.assertEqual(mean_diff(auto, self.render(ignored)[0]), 0.0)

    def test_image_sample_distance(self):
        def isd(d, auto=False):
            def f(m):
                m.SetAutoAdjustSampleDistances(1 if auto else 0)
                m.SetSampleDistance(1.0)
                m.SetImageSampleDistance(d)
            return f
        full, m1 = self.render(isd(1.0), size=(160, 160))
        half, m2 = self.render(isd(2.0), size=(160, 160))
        quarter, m4 = self.render(isd(4.0), size=(160, 160))
        # applied with AutoAdjustSampleDistances on too, as VTK 9.2 applies it
        auto, ma = self.render(isd(4.0, auto=True), size=(160, 160))
        save("settings-image-sample-distance", full, half, quarter, auto)
        sizes = [tuple(m.GetLastRenderSize()) for m in (m1, m2, m4, ma)]
        fvtest.log("  image sample distance 1/2/4/4 with auto adjust: rendered %s; SSIM to "
                   "full 1/2: %.3f, 1/4: %.3f" % (sizes, ssim(full, half), ssim(full, quarter)))
        self.assertEqual(sizes, [(160, 160), (80, 80), (40, 40), (40, 40)])
        self.assertGreater(ssim(full, half), 0.85)
        self.assertLess(ssim(full, quarter), ssim(full, half))
        self.assertGreater(coverage(quarter), 0.8 * coverage(full))

    def test_jittering(self):
        plain, _ = self.render()
        jittered, mapper = self.render(lambda m: m.UseJitteringOn())
        self.assertTrue(mapper.GetUseJittering())
        d, s = mean_diff(plain, jittered), ssim(plain, jittered)
        save("settings-jitter", plain, jittered)
        fvtest.log("  jitter: mean |diff| %.2f, SSIM %.3f" % (d, s))
        self.assertGreater(d, 0.2)
        self.assertGreater(s, 0.8)

    def test_a_piece_classifies_as_the_whole(self):
        # A piece of the wavelet away from its centre (z >= 8, a smaller data range than the
        # whole's) with the whole's range (WholeScalarRange), in the additive blend mode,
        # against the whole wavelet cropped to the same box (the rays enter both at z = 24,
        # so they sample alike): the additive sums normalise the scalars by the whole's
        # range, which the piece alone does not have.
        whole = self.src.GetOutput()
        ext = whole.GetExtent()
        lo, hi = whole.GetPointData().GetScalars().GetRange()
        voi = vtk.vtkExtractVOI()
        voi.SetInputData(whole)
        voi.SetVOI(ext[0], ext[1], ext[2], ext[3], 8, ext[5])
        voi.Update()
        piece = voi.GetOutput()
        self.assertLess(piece.GetPointData().GetScalars().GetRange()[1], hi - 10.0)
        prop = lambda: tf_property(opacity=[(37.3531, 0.0), (276.829, 0.1)])  # noqa: E731
        camera = parallel_camera((0.0, 0.0, 0.0), 100.0, 26.0, (1.0, 200.0))

        def cropped(m):
            m.SetBlendModeToAdditive()
            m.CroppingOn()
            m.SetCroppingRegionPlanes(ext[0], ext[1], ext[2], ext[3], 8, ext[5])
            m.SetCroppingRegionFlagsToSubVolume()

        def as_piece(whole_range):
            def conf(m):
                m.SetBlendModeToAdditive()
                if whole_range:
                    m.SetWholeScalarRange(0, lo, hi)
            return conf

        ref, _ = self.render(cropped, prop(), camera=camera)
        alone, _ = self.render(as_piece(False), prop(), data=piece, camera=camera)
        piece_img, mapper = self.render(as_piece(True), prop(), data=piece, camera=camera)
        save("settings-piece-whole-range", ref, piece_img, alone)
        s_piece, s_alone = ssim(piece_img, ref), ssim(alone, ref)
        d_piece, d_alone = mean_diff(piece_img, ref), mean_diff(alone, ref)
        fvtest.log("  piece against the cropped whole: with the whole's range SSIM %.4f, mean "
                   "|diff| %.2f; with its own SSIM %.4f, %.2f" % (s_piece, d_piece, s_alone,
                                                                  d_alone))
        self.assertGreater(coverage(ref), 0.1)
        self.assertGreater(d_alone, 2.0)
        self.assertLess(d_piece, 0.2)
        mapper.RemoveAllWholeScalarRanges()
        self.assertLess(mean_diff(self._keep.render(), alone), 0.1 * d_alone)
        errors = Errors(mapper)
        mapper.SetWholeScalarRange(4, 0.0, 1.0)
        self.assertTrue(any("component from 0 to 3" in m for m in errors.messages),
                        errors.messages)

    def test_empty_space_skipping_changes_nothing(self):
        on, _ = self.render()
        off, _ = self.render(lambda m: m.EmptySpaceSkippingOff())
        self.assertLessEqual(mean_diff(on, off), 0.05)

    def test_midpoint_quadrature_is_closer_at_twice_the_step(self):
        """MidpointQuadrature against VTK's lattice on the wavelet, each against its own
        converged image (1/16 voxel): at twice the sample distance midpoints are closer than
        the lattice at the default one; AdaptiveSampling (a step per block) at the default
        one too. UseJittering is not applied with it (one warning). One mapper throughout
        (its pipelines are built once)."""
        scene, errors = fvtest.ferrovol_scene(self.src, tf_property(), None, size=(120, 120),
                                              camera=view)
        m = scene.mapper
        m.AutoAdjustSampleDistancesOff()

        def render(d, midpoint, jitter=False, adaptive=False):
            m.SetSampleDistance(d)
            m.SetMidpointQuadrature(midpoint)
            m.SetAdaptiveSampling(adaptive)
            m.SetUseJittering(jitter)
            return scene.render()

        self.assertEqual(m.GetMidpointQuadrature(), 0)
        self.assertEqual(m.GetAdaptiveSampling(), 0)
        lattice_ref, midpoint_ref = render(1.0 / 16, 0), render(1.0 / 16, 1)
        lattice, midpoints = render(1.0, 0), render(2.0, 1)
        adaptive = render(1.0, 0, adaptive=True)
        save("settings-midpoint-quadrature", lattice_ref, lattice, midpoints, adaptive)
        p_lattice, p_mid = fvtest.psnr(lattice, lattice_ref), fvtest.psnr(midpoints, midpoint_ref)
        p_adaptive = fvtest.psnr(adaptive, midpoint_ref)
        print("against converged images: VTK's lattice at step 1 %.1f dB, midpoints at step 2 "
              "%.1f dB, adaptive at step 1 %.1f dB (the converged images %.1f dB apart)"
              % (p_lattice, p_mid, p_adaptive, fvtest.psnr(midpoint_ref, lattice_ref)))
        self.assertGreater(coverage(midpoints), 0.2)
        self.assertGreater(p_mid, p_lattice + 2.0)
        self.assertGreater(p_adaptive, p_lattice + 2.0)
        self.assertEqual(errors.warnings, [])
        plain, jittered = render(1.0, 1), render(1.0, 1, True)
        self.assertEqual(errors.messages, [])
        self.assertEqual(len(errors.warnings), 1)
        self.assertIn("UseJittering is not applied", errors.warnings[0])
        self.assertEqual(float(np.abs(jittered - plain).max()), 0.0)

    def test_preintegration_draws_thin_peaks_at_the_default_step(self):
        # Opacity peaks 3 scalar units wide: at one sample per voxel the rays step over
        # them; pre-integrated, the default step comes near the 1/16-voxel image.
        peaks = [(37.35, 0.0)]
        for centre in (110.0, 150.0, 190.0, 230.0):
            peaks += [(centre - 1.5, 0.0), (centre, 0.8), (centre + 1.5, 0.0)]
        peaks.append((276.83, 0.0))
        prop = lambda: tf_property(opacity=peaks, interpolation="linear")  # noqa: E731

        def fine(m):
            m.AutoAdjustSampleDistancesOff()
            m.SetSampleDistance(1.0 / 16)

        reference, _ = self.render(fine, prop())
        plain, mapper = self.render(None, prop())
        self.assertEqual(mapper.GetPreIntegration(), 0, "off by default")
        pre, _ = self.render(lambda m: m.PreIntegrationOn(), prop())
        off, _ = self.render(lambda m: m.SetPreIntegration(0), prop())
        save("settings-preintegration", reference, plain, pre)
        err_plain, err_pre = mean_diff(plain, reference), mean_diff(pre, reference)
        print("thin peaks against 1/16-voxel steps: mean |difference| %.2f levels sampled, "
              "%.2f pre-integrated" % (err_plain, err_pre))
        self.assertGreater(coverage(reference), 0.2)
        self.assertEqual(float(np.abs(off - plain).max()), 0.0)
        self.assertLess(err_pre, 0.5 * err_plain)

    def test_cubic_interpolation_smooths_and_is_for_ray_casting(self):
        # the B-spline changes the linear image a little (it smooths at the voxel scale);
        # off again gives the linear image back exactly; isosurfaces keep trilinear
        linear, mapper = self.render(None, tf_property(interpolation="linear"))
        self.assertEqual(mapper.GetCubicInterpolation(), 0, "off by default")
        cubic, _ = self.render(lambda m: m.CubicInterpolationOn(),
                               tf_property(interpolation="linear"))
        off, _ = self.render(lambda m: m.SetCubicInterpolation(0),
                             tf_property(interpolation="linear"))
        save("settings-cubic", linear, cubic)
        d = mean_diff(linear, cubic)
        print("cubic B-spline vs trilinear: mean |difference| %.2f levels" % d)
        self.assertGreater(coverage(cubic), 0.2)
        self.assertGreater(d, 0.2)
        self.assertEqual(float(np.abs(off - linear).max()), 0.0)

    def test_memory_budget_streams_the_same_image(self):
        # wavelet(23): 48^3 float32, 432 KiB; a budget of a quarter of it (MaxMemoryInBytes x
        # MaxMemoryFraction) bricks the volume and streams the bricks in several passes
        full, _ = self.render()
        progress = []
        streamed, mapper = self.render(memory_budget(48 ** 3 * 4 // 2, 0.5, progress))
        save("settings-memory-budget", full, streamed)
        d = float(np.abs(streamed - full).max())
        print("memory budget 108 KiB: max |difference| to unlimited %.1f levels; progress "
              "reported %d times, last %.2f" % (d, len(progress), progress[-1] if progress else -1))
        self.assertEqual(mapper.GetMaxMemoryFraction(), 0.5)
        self.assertGreater(len(progress), 1, "each streamed pass reports progress")
        self.assertEqual(progress[-1], 1.0)
        self.assertLessEqual(d, 2.0)
        self.assertGreater(coverage(streamed), 0.2)

    def test_interactive_render_over_the_budget_draws_a_coarser_level(self):
        # A quarter budget, the window rendering interactively (DesiredUpdateRate above 1 s⁻¹,
        # as an interactor sets it while the camera moves): one pass, a coarser level's bricks
        # where fine ones are missing, no pass reported between 0 and 1 (the pipeline's own
        # update reports those two); the still render after it streams the volume itself.
        full, _ = self.render()
        progress = []
        preview, _ = self.render(memory_budget(48 ** 3 * 4 // 4, 1.0, progress),
                                 scene_hook=lambda s: s.window.SetDesiredUpdateRate(15.0))
        passes = [p for p in progress if 0.0 < p < 1.0]
        progress.clear()
        self._keep.window.SetDesiredUpdateRate(0.0001)
        still = self._keep.render()
        still_passes = [p for p in progress if 0.0 < p < 1.0]
        save("settings-interactive-level", full, preview, still)
        print("interactive render under a quarter budget: %d passes reported, mean |difference| "
              "to unlimited %.2f levels; still render: %d, max %.1f" % (
                  len(passes), mean_diff(preview, full), len(still_passes),
                  float(np.abs(still - full).max())))
        self.assertEqual(passes, [], "the interactive render does not stream")
        self.assertGreater(coverage(preview), 0.2)
        self.assertGreater(mean_diff(preview, full), 0.0, "a coarser level")
        self.assertLess(mean_diff(preview, full), 4.0)
        self.assertGreater(len(still_passes), 0, "the still render streams")
        self.assertLessEqual(float(np.abs(still - full).max()), 2.0)

    def test_volume_matrix(self):
        # Parallel projection: moving the volume by 10 world units moves its image by
        # 10 / (2 * parallel scale) of the window height.
        camera = parallel_camera((0, 0, 0), 200, 50.0, (50, 400))

        def centroid(img):
            m = img.max(axis=2) > 8
            ys, xs = np.nonzero(m)
            return xs.mean(), ys.mean()

        base, _ = self.render(camera=camera, size=(200, 200))
        moved, _ = self.render(camera=camera, size=(200, 200),
                               scene_hook=lambda s: s.volume.SetPosition(10.0, 5.0, 0.0))
        scaled, _ = self.render(camera=camera, size=(200, 200),
                                scene_hook=lambda s: s.volume.SetScale(1.5, 1.0, 1.0))
        rotated, _ = self.render(camera=camera, size=(200, 200),
                                 scene_hook=lambda s: s.volume.RotateZ(45.0))
        save("settings-volume-matrix", base, moved, scaled, rotated)
        (bx, by), (mx, my) = centroid(base), centroid(moved)
        fvtest.log("  volume matrix: position (10, 5) moved the image by (%.1f, %.1f) px, "
                   "expected (20, -10)" % (mx - bx, my - by))
        self.assertAlmostEqual(mx - bx, 20.0, delta=1.0)
        self.assertAlmostEqual(my - by, -10.0, delta=1.0)  # image rows run downwards
        wb = np.nonzero((base.max(axis=2) > 8).any(axis=0))[0]
        ws = np.nonzero((scaled.max(axis=2) > 8).any(axis=0))[0]
        ratio = (ws[-1] - ws[0] + 1) / (wb[-1] - wb[0] + 1)
        fvtest.log("  volume matrix: scale 1.5 along x widened the image %.2fx" % ratio)
        self.assertAlmostEqual(ratio, 1.5, delta=0.05)
        wr = np.nonzero((rotated.max(axis=2) > 8).any(axis=0))[0]
        self.assertAlmostEqual((wr[-1] - wr[0] + 1) / (wb[-1] - wb[0] + 1), 2 ** 0.5, delta=0.05)

    # -- input ------------------------------------------------------------------------------
    def test_cell_vs_point_data(self):
        n = 24
        z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
        values = (x * 4 + y * 3 + z * 2).astype(np.float32)
        prop = lambda: tf_property(color=[(0, 1, 0.5, 0.2), (200, 0.2, 0.5, 1)],  # noqa: E731
                                   opacity=[(0, 0.05), (200, 0.5)], interpolation="linear")
        point, _ = self.render(data=image_from_array(values), prop=prop(), camera=self.front)
        # the cell grid moved back half a voxel: its cell centres sit on the points above
        cells, _ = self.render(data=image_from_array(values, cells=True,
                                                     origin=(-0.5, -0.5, -0.5)),
                               prop=prop(), camera=self.front)
        shifted, _ = self.render(data=image_from_array(values, cells=True), prop=prop(),
                                 camera=self.front)
        save("settings-cell-vs-point", point, cells, shifted)
        s_same, s_shift = ssim(point, cells), ssim(point, shifted)
        fvtest.log("  cell data: SSIM to the same values on points %.4f (cell centres on the "
                   "points), %.4f (grid at the points' origin: centres half a voxel off)"
                   % (s_same, s_shift))
        self.assertGreater(s_same, 0.99)
        self.assertLess(s_shift, s_same - 0.02)
        # half a voxel up and right: 1.5 px at 3 px per unit
        lit = lambda im: np.nonzero((im.max(axis=2) > 8).any(axis=0))[0][0]  # noqa: E731
        self.assertAlmostEqual(lit(shifted) - lit(point), 1.5, delta=1.0)

    front = staticmethod(parallel_camera((11.5, 11.5, 11.5), 138.5, 20.0, (50, 300)))

    def test_scalar_types(self):
        n = 20
        z, y, x = np.mgrid[0:n, 0:n, 0:n]
        values = ((x * 3 + y * 2 + z) % 100).astype(np.float64)
        prop = lambda: tf_property(color=[(0, 0.1, 0.2, 1), (100, 1, 0.4, 0.1)],  # noqa: E731
                                   opacity=[(0, 0.0), (100, 0.8)])
        ref, _ = self.render(data=image_from_array(values.astype(np.float32)), prop=prop())
        types = {
            "char": vtk.VTK_CHAR, "signed char": vtk.VTK_SIGNED_CHAR,
            "unsigned char": vtk.VTK_UNSIGNED_CHAR, "short": vtk.VTK_SHORT,
            "unsigned short": vtk.VTK_UNSIGNED_SHORT, "int": vtk.VTK_INT,
            "unsigned int": vtk.VTK_UNSIGNED_INT, "long": vtk.VTK_LONG,
            "unsigned long": vtk.VTK_UNSIGNED_LONG, "long long": vtk.VTK_LONG_LONG,
            "unsigned long long": vtk.VTK_UNSIGNED_LONG_LONG, "float": vtk.VTK_FLOAT,
            "double": vtk.VTK_DOUBLE, "vtkIdType": vtk.VTK_ID_TYPE,
        }
        worst = 0.0
        for name, t in types.items():
            arr = vtk.vtkDataArray.CreateDataArray(t)
            arr.SetNumberOfTuples(values.size)
            for i, v in enumerate(values.reshape(-1)):
                arr.SetTuple1(i, v)
            arr.SetName(name)
            img = vtk.vtkImageData()
            img.SetDimensions(n, n, n)
            img.GetPointData().SetScalars(arr)
            out, _ = self.render(data=img, prop=prop())
            d = float(np.abs(out - ref).max())
            worst = max(worst, d)
            self.assertEqual(arr.GetDataType(), t)
            self.assertLessEqual(d, 3.0, "%s renders differently (max |diff| %.0f)" % (name, d))
        fvtest.log("  %d scalar types render like float32: max |diff| %.0f / 255"
                   % (len(types), worst))
        # a bit array (0/1) renders too
        bits = vtk.vtkBitArray()
        bits.SetNumberOfTuples(values.size)
        for i, v in enumerate(values.reshape(-1)):
            bits.SetValue(i, int(v) % 2)
        img = vtk.vtkImageData()
        img.SetDimensions(n, n, n)
        img.GetPointData().SetScalars(bits)
        out, _ = self.render(data=img, prop=tf_property(color=[(0, 1, 1, 1), (1, 1, 0, 0)],
                                                         opacity=[(0, 0), (1, 0.5)]))
        self.assertGreater(coverage(out), 0.1)

    def test_scalar_mode_and_selected_array(self):
        n = 20
        z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
        img = image_from_array(x * 10, name="along-x")
        second = vtk.vtkFloatArray()
        second.DeepCopy(image_from_array(y * 10).GetPointData().GetScalars())
        second.SetName("along-y")
        img.GetPointData().AddArray(second)
        cell = image_from_array((z[:-1, :-1, :-1] * 10), cells=True).GetCellData().GetScalars()
        cell.SetName("cells-along-z")
        img.GetCellData().AddArray(cell)
        prop = lambda: tf_property(color=[(0, 0, 0, 1), (190, 1, 0, 0)],  # noqa: E731
                                   opacity=[(0, 0.3), (190, 0.3)])
        default, _ = self.render(data=img, prop=prop(), camera=self.front)

        def select(mode, name):
            def f(m):
                getattr(m, "SetScalarModeTo" + mode)()
                m.SelectScalarArray(name)
            return f
        by_name, _ = self.render(select("UsePointFieldData", "along-y"), data=img, prop=prop(),
                                 camera=self.front)
        by_index, _ = self.render(select("UsePointFieldData", 1), data=img, prop=prop(),
                                  camera=self.front)
        cells, _ = self.render(select("UseCellFieldData", "cells-along-z"), data=img,
                               prop=prop(), camera=self.front)
        save("settings-selected-array", default, by_name, cells)
        # x ramp: red grows to the right; y ramp: red grows upwards (rows top to bottom)
        red = lambda im: im[..., 0] - im[..., 2]  # noqa: E731
        self.assertGreater(red(default)[:, 60:].mean(), red(default)[:, :40].mean() + 20)
        self.assertGreater(red(by_name)[:40].mean(), red(by_name)[60:].mean() + 20)
        self.assertEqual(mean_diff(by_name, by_index), 0.0)
        # the z ramp seen along z: uniform across the image
        self.assertLess(abs(red(cells)[:, 60:].mean() - red(cells)[:, :40].mean()), 10)

    def test_direction_matrix_and_negative_spacing(self):
        n = 16
        z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
        values = x * 10 + y * 3
        prop = lambda: tf_property(color=[(0, 0, 0.3, 1), (200, 1, 0.5, 0)],  # noqa: E731
                                   opacity=[(0, 0.1), (200, 0.6)])
        # a direction matrix D places the data as the vtkVolume's rotation D would
        t = vtk.vtkTransform()
        t.RotateZ(35.0)
        t.RotateY(-20.0)
        d = vtk.vtkMatrix3x3()
        for r in range(3):
            for c in range(3):
                d.SetElement(r, c, t.GetMatrix().GetElement(r, c))
        directed = image_from_array(values)
        directed.SetDirectionMatrix(d)

        def camera(cam):
            cam.SetFocalPoint(0, 0, 0)
            cam.SetPosition(20, -60, 40)
            cam.SetViewUp(0, 0, 1)
            cam.SetClippingRange(10, 200)
        a, _ = self.render(data=directed, prop=prop(), camera=camera)
        b, _ = self.render(data=image_from_array(values), prop=prop(), camera=camera,
                           scene_hook=lambda s: s.volume.SetUserTransform(t))
        # a negative spacing along x walks the data backwards from the origin: the mirrored
        # array with positive spacing is the same volume
        neg = image_from_array(values, spacing=(-1.0, 1.0, 1.0), origin=(n - 1.0, 0.0, 0.0))
        c, _ = self.render(data=neg, prop=prop())
        e, _ = self.render(data=image_from_array(values[:, :, ::-1].copy()), prop=prop())
        save("settings-direction-negative-spacing", a, b, c, e)
        fvtest.log("  direction matrix vs the same rotation on the vtkVolume: max |diff| %.0f; "
                   "spacing -1 vs mirrored data: max |diff| %.0f"
                   % (np.abs(a - b).max(), np.abs(c - e).max()))
        self.assertGreater(mean_diff(a, self.render(data=image_from_array(values), prop=prop(),
                                                    camera=camera)[0]), 3.0)
        self.assertLessEqual(np.abs(a - b).max(), 3.0)
        self.assertLessEqual(np.abs(c - e).max(), 3.0)

    # -- vtkVolumeProperty -------------------------------------------------------------------
    def test_shading(self):
        def shaded(**kw):
            p = tf_property(interpolation="linear")
            p.ShadeOn()
            for k, v in kw.items():
                getattr(p, "Set" + k)(v)
            return p
        off, _ = self.render(prop=tf_property(interpolation="linear"))
        on, _ = self.render(prop=shaded())
        bright, _ = self.render(prop=shaded(Diffuse=1.0, Ambient=0.4))
        dark, _ = self.render(prop=shaded(Diffuse=0.2, Ambient=0.0, Specular=0.0))
        shiny, _ = self.render(prop=shaded(Specular=1.0, SpecularPower=5.0))
        save("settings-shading", off, on, bright, dark, shiny)
        lum = lambda im: fvtest.luminance(im).mean()  # noqa: E731
        fvtest.log("  shading: mean luminance off %.1f, on %.1f, bright %.1f, dark %.1f, "
                   "specular %.1f" % (lum(off), lum(on), lum(bright), lum(dark), lum(shiny)))
        self.assertGreater(mean_diff(off, on), 5.0)
        self.assertGreater(lum(bright), lum(on) + 3)
        self.assertLess(lum(dark), lum(on) - 3)
        self.assertGreater(lum(shiny), lum(on) + 1)

    def test_interpolation(self):
        rng = np.random.default_rng(7)
        values = rng.uniform(0, 100, size=(6, 6, 6)).astype(np.float32)
        prop = lambda interp: tf_property(  # noqa: E731
            color=[(0, 0, 0.3, 1), (100, 1, 0.8, 0.1)], opacity=[(0, 0.2), (100, 0.9)],
            interpolation=interp)
        near, _ = self.render(data=image_from_array(values, spacing=(4, 4, 4)),
                              prop=prop("nearest"))
        lin, _ = self.render(data=image_from_array(values, spacing=(4, 4, 4)),
                             prop=prop("linear"))
        save("settings-interpolation", near, lin)

        def edges(im):  # mean absolute neighbour difference: blocky images have sharp steps
            g = fvtest.luminance(im)
            return float(np.abs(np.diff(g, axis=1)).mean() + np.abs(np.diff(g, axis=0)).mean())
        fvtest.log("  interpolation: edge energy nearest %.2f, linear %.2f"
                   % (edges(near), edges(lin)))
        self.assertGreater(mean_diff(near, lin), 3.0)
        self.assertGreater(edges(near), edges(lin) * 1.2)

    def test_gradient_opacity(self):
        def with_go(disable=False):
            p = tf_property(interpolation="linear")
            g = vtk.vtkPiecewiseFunction()
            g.AddPoint(0.0, 1.0)  # VTK's units (mean spacing x central-difference magnitude)
            g.AddPoint(10.0, 0.0)
            p.SetGradientOpacity(g)
            if disable:
                p.DisableGradientOpacityOn()
            return p
        plain, _ = self.render(prop=tf_property(interpolation="linear"))
        go, _ = self.render(prop=with_go())
        disabled, _ = self.render(prop=with_go(disable=True))
        save("settings-gradient-opacity", plain, go, disabled)
        lum = lambda im: fvtest.luminance(im).mean()  # noqa: E731
        fvtest.log("  gradient opacity: luminance without %.1f, with %.1f, disabled %.1f"
                   % (lum(plain), lum(go), lum(disabled)))
        self.assertLess(lum(go), lum(plain) - 10)
        self.assertLessEqual(mean_diff(plain, disabled), 0.05)

    def test_scalar_opacity_unit_distance(self):
        def unit(d):
            p = tf_property()
            p.SetScalarOpacityUnitDistance(d)
            return p
        thin, _ = self.render(prop=unit(4.0))
        thick, _ = self.render(prop=unit(0.25))
        lum = lambda im: fvtest.luminance(im).mean()  # noqa: E731
        self.assertGreater(lum(thick), lum(thin) + 5)

    def test_gray_transfer_function(self):
        p = vtk.vtkVolumeProperty()
        p.SetColor(fvtest.opacity_function([(37.0, 0.0), (277.0, 1.0)]))
        p.SetScalarOpacity(fvtest.opacity_function([(37.0, 0.0), (277.0, 0.8)]))
        self.assertEqual(p.GetColorChannels(), 1)
        img, _ = self.render(prop=p)
        lit = img.max(axis=2) > 8
        self.assertGreater(lit.mean(), 0.1)
        self.assertLessEqual(np.abs(img[..., 0] - img[..., 2])[lit].max(), 1.0)

    def test_multiple_components(self):
        n = 24
        z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
        a = np.stack([x * 8, y * 8], axis=-1).astype(np.float32)

        def two(weight1=1.0, independent=True):
            p = fvtest.component_property([(1.0, 0.3, 0.1), (0.1, 0.3, 1.0)], 0.4)
            p.SetIndependentComponents(independent)
            p.SetComponentWeight(1, weight1)
            return p
        both, _ = self.render(data=image_from_array(a), prop=two(), camera=self.front)
        only0, _ = self.render(data=image_from_array(a), prop=two(weight1=0.0),
                               camera=self.front)
        single = two()
        single.SetComponentWeight(1, 1.0)
        ref0, _ = self.render(data=image_from_array(a[..., 0].copy()), prop=single,
                              camera=self.front)
        dependent, _ = self.render(data=image_from_array(a), prop=two(independent=False),
                                   camera=self.front)
        # RGBA (4 dependent components): colour straight from the data
        rgba = np.zeros((n, n, n, 4), np.uint8)
        rgba[..., 0] = 255
        rgba[..., 3] = 200
        p4 = tf_property(color=[(0, 1, 1, 1), (255, 1, 1, 1)], opacity=[(0, 0), (255, 0.5)])
        p4.IndependentComponentsOff()
        red, _ = self.render(data=image_from_array(rgba), prop=p4, camera=self.front)
        save("settings-components", both, only0, ref0, dependent, red)
        fvtest.log("  components: weight 0 on component 1 vs component 0 alone: max |diff| %.0f"
                   % np.abs(only0 - ref0).max())
        self.assertGreater(mean_diff(both, only0), 5.0)
        self.assertLessEqual(np.abs(only0 - ref0).max(), 2.0)
        self.assertGreater(mean_diff(both, dependent), 5.0)
        lit = red.max(axis=2) > 8
        self.assertGreater(lit.mean(), 0.3)
        self.assertGreater(red[..., 0][lit].mean(), 100)
        self.assertLess(red[..., 1][lit].max() + red[..., 2][lit].max(), 2)

    def test_lights(self):
        def shaded():
            p = tf_property(interpolation="linear")
            p.ShadeOn()
            p.SetAmbient(0.1)
            p.SetDiffuse(0.9)
            return p

        def lights(*specs):
            def hook(scene):
                ren = scene.renderer
                ren.AutomaticLightCreationOff()
                ren.RemoveAllLights()
                for spec in specs:
                    light = vtk.vtkLight()
                    kind, on, intensity = spec[:3]
                    if kind == "head":
                        light.SetLightTypeToHeadlight()
                    elif kind == "scene":
                        light.SetLightTypeToSceneLight()
                        light.SetPosition(*spec[3])
                        light.SetFocalPoint(0, 0, 0)
                    light.SetSwitch(on)
                    light.SetIntensity(intensity)
                    ren.AddLight(light)
            return hook
        head, _ = self.render(prop=shaded(), scene_hook=lights(("head", 1, 1.0)))
        dim, _ = self.render(prop=shaded(), scene_hook=lights(("head", 1, 0.4)))
        off, _ = self.render(prop=shaded(), scene_hook=lights(("head", 0, 1.0)))
        side, _ = self.render(prop=shaded(),
                              scene_hook=lights(("scene", 1, 1.0, (100, 0, 0))))
        other, _ = self.render(prop=shaded(),
                               scene_hook=lights(("scene", 1, 1.0, (0, 100, 0))))

        def one_sided(scene):
            lights(("scene", 1, 1.0, (100, 0, 0)))(scene)
            scene.renderer.TwoSidedLightingOff()
        single, _ = self.render(prop=shaded(), scene_hook=one_sided)
        nine = [("scene", 1, 0.2, (100, 10 * i, 0)) for i in range(9)]
        mapper = ferrovol.vtkFerroVolumeMapper()
        errors = Errors(mapper)
        scene = Scene(mapper, self.src, shaded(), size=(120, 120), camera=view)
        lights(*nine)(scene)
        many = scene.render()
        save("settings-lights", head, dim, off, side, other, single, many)
        lum = lambda im: fvtest.luminance(im).mean()  # noqa: E731
        fvtest.log("  lights: luminance headlight %.1f, intensity 0.4 %.1f, switched off %.1f, "
                   "from +x %.1f, from +y %.1f, from +x one-sided %.1f"
                   % (lum(head), lum(dim), lum(off), lum(side), lum(other), lum(single)))
        self.assertLess(lum(dim), lum(head) - 5)
        self.assertLess(lum(off), lum(dim))  # no light on: ambient only
        self.assertGreater(mean_diff(side, other), 5.0)
        self.assertLess(lum(single), lum(side) - 3)  # back faces no longer lit
        self.assertTrue(any("lights are on" in w for w in errors.warnings), errors.warnings)
        self.assertTrue(mapper.GetLastRenderDrew())


if __name__ == "__main__":
    unittest.main(verbosity=2)
