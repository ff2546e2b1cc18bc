"""Bad input and unsupported settings: each raises one vtkErrorMacro (an ErrorEvent on the
mapper) that names the problem, draws nothing (no stale image from an earlier frame) and
does not crash; fixing the input makes the next frame render again. Degenerate but valid
volumes (1x1x1, 1xNxM) render as slabs."""
import math
import unittest

import numpy as np
import vtk

import ferrovol
import fvtest
from fvtest import Errors, Scene, coverage, image_from_array, tf_property


def ramp(n=12, dtype=np.float32):
    z, y, x = np.mgrid[0:n, 0:n, 0:n]
    return ((x + y + z) * 10).astype(dtype)


def ramp_property():
    return tf_property(color=[(0, 0.2, 0.4, 1.0), (330, 1.0, 0.6, 0.2)],
                       opacity=[(0, 0.3), (330, 0.9)])


def view(cam):
    cam.Azimuth(30.0)
    cam.Elevation(20.0)
    cam.OrthogonalizeViewUp()


class ErrorCases(unittest.TestCase):
    def setUp(self):
        self.mapper = ferrovol.vtkFerroVolumeMapper()
        self.errors = Errors(self.mapper)
        self.good = image_from_array(ramp())
        self.scene = Scene(self.mapper, self.good, ramp_property(), size=(80, 80), camera=view)
        first = self.scene.render()
        self.assertTrue(self.mapper.GetLastRenderDrew())
        self.assertGreater(coverage(first), 0.1)
        self.assertEqual(self.errors.messages, [])

    def expect_error(self, keywords, data=None, configure=None):
        """Renders with the change applied; expects an error naming `keywords` and an empty
        image (the good frame before must not linger); then restores and renders again."""
        if data is not None:
            self.mapper.SetInputData(data)
        if configure:
            configure(self.mapper)
        img = self.scene.render()
        msg = self.errors.last()
        fvtest.log("  %-26s -> %s" % (self._testMethodName[5:],
                                       msg.strip().splitlines()[-1] if msg else "(no error)"))
        self.assertTrue(self.errors.messages, "no error was raised")
        for k in keywords:
            self.assertIn(k.lower(), msg.lower())
        self.assertFalse(self.mapper.GetLastRenderDrew())
        self.assertEqual(coverage(img), 0.0, "something was drawn after the error")
        return img

    def recover(self, configure=None):
        self.errors.messages.clear()
        self.mapper.SetInputData(self.good)
        if configure:
            configure(self.mapper)
        img = self.scene.render()
        self.assertEqual(self.errors.messages, [])
        self.assertTrue(self.mapper.GetLastRenderDrew())
        self.assertGreater(coverage(img), 0.1)

    # -- missing or unusable input -----------------------------------------------------------
    def test_no_input(self):
        mapper = ferrovol.vtkFerroVolumeMapper()
        errors = Errors(mapper)
        scene = Scene(mapper, None, ramp_property(), size=(60, 60))
        # In a window render VTK's pipeline reports the missing connection itself (through
        # the output window, captured here); called directly, the mapper says it.
        out = vtk.vtkStringOutputWindow()
        previous = vtk.vtkOutputWindow.GetInstance()
        vtk.vtkOutputWindow.SetInstance(out)
        try:
            img = scene.render()
        finally:
            vtk.vtkOutputWindow.SetInstance(previous)
        self.assertIn("0 connections", out.GetOutput())
        self.assertEqual(coverage(img), 0.0)
        self.assertFalse(mapper.GetLastRenderDrew())
        mapper.Render(scene.renderer, scene.volume)
        fvtest.log("  no input                   -> " + errors.last().strip().splitlines()[-1])
        self.assertTrue(any("no input" in m for m in errors.messages))
        self.assertFalse(mapper.GetLastRenderDrew())

    def test_no_scalars(self):
        img = vtk.vtkImageData()
        img.SetDimensions(8, 8, 8)
        self.expect_error(["no scalars"], data=img)
        self.recover()

    def test_string_array(self):
        img = vtk.vtkImageData()
        img.SetDimensions(4, 4, 4)
        s = vtk.vtkStringArray()
        s.SetName("labels")
        s.SetNumberOfValues(64)
        for i in range(64):
            s.SetValue(i, "v%d" % i)
        img.GetPointData().AddArray(s)

        def select(m):
            m.SetScalarModeToUsePointFieldData()
            m.SelectScalarArray("labels")
        self.expect_error(["labels", "not numeric"], data=img, configure=select)
        self.recover(lambda m: m.SetScalarModeToDefault())

    def test_missing_named_array(self):
        def select(m):
            m.SetScalarModeToUseCellFieldData()
            m.SelectScalarArray("nothing-here")
        self.expect_error(["nothing-here", "cell"], configure=select)
        self.recover(lambda m: m.SetScalarModeToDefault())

    def test_rectilinear_coordinates_not_increasing(self):
        grid = vtk.vtkRectilinearGrid()
        grid.SetDimensions(4, 4, 4)
        for setter, values in ((grid.SetXCoordinates, (0, 1, 2, 3)),
                               (grid.SetYCoordinates, (0, 1, 3, 2)),
                               (grid.SetZCoordinates, (0, 1, 2, 3))):
            c = vtk.vtkDoubleArray()
            for v in values:
                c.InsertNextValue(v)
            setter(c)
        a = vtk.vtkFloatArray()
        a.SetNumberOfTuples(64)
        a.Fill(1.0)
        grid.GetPointData().SetScalars(a)
        self.expect_error(["y coordinates 2 and 3", "strictly increasing"], data=grid)
        self.recover()

    def test_zero_spacing(self):
        self.expect_error(["spacing", "zero along y"],
                          data=image_from_array(ramp(), spacing=(1.0, 0.0, 1.0)))
        self.recover()

    def test_nan_scalars(self):
        a = ramp()
        a[3, 4, 5] = math.nan
        self.expect_error(["nan", "(5, 4, 3)"], data=image_from_array(a))
        self.recover()

    def test_infinite_scalars(self):
        a = ramp(dtype=np.float64)
        a[0, 0, 1] = math.inf
        self.expect_error(["inf"], data=image_from_array(a))
        self.recover()

    def test_five_components(self):
        a = np.stack([ramp()] * 5, axis=-1)
        self.expect_error(["5 components", "1 to 4"], data=image_from_array(a))
        self.recover()

    def test_dependent_three_components(self):
        a = np.stack([ramp()] * 3, axis=-1)

        def dependent(m):
            self.scene.volume.GetProperty().IndependentComponentsOff()
        self.expect_error(["dependent", "3 components"], data=image_from_array(a),
                          configure=dependent)
        self.scene.volume.GetProperty().IndependentComponentsOn()
        self.recover()

    # -- unsupported settings ------------------------------------------------------------------
    def test_slice_blend_mode_without_a_plane(self):
        def sphere(m):
            m.SetBlendModeToSlice()
            self.scene.volume.GetProperty().SetSliceFunction(vtk.vtkSphere())
        self.expect_error(["SliceFunction", "vtkPlane", "vtkSphere"], configure=sphere)
        self.scene.volume.GetProperty().SetSliceFunction(None)
        self.errors.messages.clear()
        self.expect_error(["SliceFunction", "vtkPlane", "none"],
                          configure=lambda m: m.SetBlendModeToSlice())
        self.recover(lambda m: m.SetBlendModeToComposite())

    def test_non_positive_sample_distance(self):
        def bad(m):
            m.AutoAdjustSampleDistancesOff()
            m.SetSampleDistance(0.0)
        self.expect_error(["SampleDistance"], configure=bad)
        self.recover(lambda m: m.SetSampleDistance(0.5))

    def test_singular_volume_matrix(self):
        self.scene.volume.SetScale(1.0, 0.0, 1.0)
        self.expect_error(["singular"])
        self.scene.volume.SetScale(1.0, 1.0, 1.0)
        self.recover()

    def test_bad_cropping_planes(self):
        def bad(m):
            m.CroppingOn()
            m.SetCroppingRegionPlanes(5, 2, 0, 10, 0, 10)  # xmin > xmax
        self.expect_error(["cropping planes"], configure=bad)
        self.recover(lambda m: m.CroppingOff())

    def test_empty_extent(self):
        img = vtk.vtkImageData()
        img.SetExtent(0, -1, 0, -1, 0, -1)
        s = vtk.vtkFloatArray()
        s.SetName("scalars")
        img.GetPointData().SetScalars(s)
        self.expect_error(["empty"], data=img)
        self.recover()

    def test_mask_of_the_wrong_size(self):
        small = image_from_array(np.ones((6, 12, 12), np.uint8))
        self.expect_error(["mask", "12x12x6", "12x12x12", "extent"],
                          configure=lambda m: m.SetMaskInput(small))
        self.recover(lambda m: m.SetMaskInput(None))

    def test_label_out_of_range(self):
        labels = image_from_array(np.full((12, 12, 12), 300, np.int16))

        def label_map(m):
            m.SetMaskInput(labels)
            m.SetMaskTypeToLabelMap()
        self.expect_error(["label map holds 300", "0 to 255"], configure=label_map)
        self.recover(lambda m: m.SetMaskInput(None))

    # -- device faults ---------------------------------------------------------------------------
    def test_device_loss(self):
        before = self.scene.render()
        ferrovol.vtkFerroVolumeMapper.LoseDevice()
        self.expect_error(["device lost", "opens a new device"])
        self.recover()
        after = self.scene.render()
        fvtest.log("  device loss -> redrawn on a new device, max difference %d levels"
                   % np.abs(after.astype(int) - before.astype(int)).max())
        np.testing.assert_array_equal(after, before)

    def test_out_of_memory(self):
        before = self.scene.render()
        held = ferrovol.vtkFerroVolumeMapper.GetDeviceMemoryInUse()
        self.assertGreater(held, 0)
        ferrovol.vtkFerroVolumeMapper.LimitDeviceMemory(held + 1024)
        try:
            self.scene.window.SetSize(400, 400)
            self.expect_error(["out of GPU memory", "limited to", "make the window"])
        finally:
            ferrovol.vtkFerroVolumeMapper.LimitDeviceMemory(0)
            self.scene.window.SetSize(80, 80)
        self.recover()
        after = self.scene.render()
        fvtest.log("  out of memory -> drawn again without the cap, max difference %d levels"
                   % np.abs(after.astype(int) - before.astype(int)).max())
        np.testing.assert_array_equal(after, before)

    # -- degenerate volumes that do render ------------------------------------------------------
    def test_single_voxel(self):
        self.mapper.SetInputData(image_from_array(np.full((1, 1, 1), 200.0, np.float32),
                                                  spacing=(10, 10, 10)))
        self.scene.renderer.ResetCamera()
        img = self.scene.render()
        fvtest.log("  1x1x1 volume               -> a cube one spacing wide, coverage %.2f"
                   % coverage(img))
        self.assertEqual(self.errors.messages, [])
        self.assertTrue(self.mapper.GetLastRenderDrew())
        self.assertGreater(coverage(img), 0.05)

    def test_slab_1xNxM(self):
        z, y = np.mgrid[0:16, 0:16]
        a = ((y + z) * 10).astype(np.float32).reshape(16, 16, 1)
        self.mapper.SetInputData(image_from_array(a))
        self.scene.renderer.ResetCamera()
        cam = self.scene.renderer.GetActiveCamera()
        cam.Azimuth(60)  # look at the slab's face (the x axis is the flat one)
        self.scene.renderer.ResetCameraClippingRange()
        img = self.scene.render()
        fvtest.log("  1x16x16 slab               -> rendered one spacing thick, coverage %.2f"
                   % coverage(img))
        self.assertEqual(self.errors.messages, [])
        self.assertGreater(coverage(img), 0.1)
        fvtest.save("errors-slab-1x16x16", img)

    # -- the input changing between renders --------------------------------------------------
    def test_input_changes_between_renders(self):
        src = vtk.vtkImageData()
        src.DeepCopy(self.good)
        self.mapper.SetInputData(src)
        self.scene.render()
        uploads = self.mapper.GetVolumeUploadCount()
        # resize in place
        src.SetDimensions(20, 10, 6)
        src.AllocateScalars(vtk.VTK_UNSIGNED_SHORT, 1)
        arr = src.GetPointData().GetScalars()
        for i in range(arr.GetNumberOfTuples()):
            arr.SetTuple1(i, (i * 7) % 300)
        src.Modified()
        a = self.scene.render()
        self.assertTrue(self.mapper.GetLastRenderDrew())
        self.assertEqual(self.mapper.GetVolumeUploadCount(), uploads + 1)
        # type and component change (2 independent components)
        src.AllocateScalars(vtk.VTK_DOUBLE, 2)
        src.GetPointData().GetScalars().Fill(100.0)
        src.Modified()
        self.scene.render()
        self.assertTrue(self.mapper.GetLastRenderDrew())
        self.assertEqual(self.mapper.GetVolumeUploadCount(), uploads + 2)
        # modifying the array alone (not the image) is seen too
        src.AllocateScalars(vtk.VTK_FLOAT, 1)
        src.GetPointData().GetScalars().Fill(50.0)
        self.scene.render()
        n = self.mapper.GetVolumeUploadCount()
        src.GetPointData().GetScalars().SetTuple1(0, 300.0)
        src.GetPointData().GetScalars().Modified()
        self.scene.render()
        self.assertEqual(self.mapper.GetVolumeUploadCount(), n + 1)
        self.assertEqual(self.errors.messages, [])
        self.assertGreater(coverage(a), 0.05)


if __name__ == "__main__":
    unittest.main(verbosity=2)
