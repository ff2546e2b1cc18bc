"""2D transfer functions (vtkVolumeProperty::SetTransferFunctionMode(TF_2D) and
SetTransferFunction2D: RGBA over scalar x gradient magnitude), each scene against
vtkGPUVolumeRayCastMapper: one component, with and without a gradient opacity function (the
table replaces it: VTK 9.2 draws TF_2D without it), shaded; two independent components, each
with its own table, against ferrovol's 1D image (VTK 9.2's shader for them does not compile)."""
import unittest

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

import fvtest
from fvtest import Errors, coverage


def table_2d(rgb_low, rgb_high, bins=(256, 128), top=0.6):
    """A float RGBA image: colour rgb_low at weak gradients turning to rgb_high at strong
    ones, opacity rising with the scalar above its middle and with the gradient."""
    nx, ny = bins
    x = (np.arange(nx) + 0.5) / nx
    y = (np.arange(ny) + 0.5) / ny
    xx, yy = np.meshgrid(x, y)
    rgba = np.zeros((ny, nx, 4), np.float32)
    for k in range(3):
        rgba[..., k] = rgb_low[k] + (rgb_high[k] - rgb_low[k]) * yy
    rgba[..., 3] = np.clip((xx - 0.45) / 0.4, 0, 1) * top * (0.3 + 0.7 * yy)
    img = vtk.vtkImageData()
    img.SetDimensions(nx, ny, 1)
    arr = numpy_to_vtk(rgba.reshape(-1, 4), deep=True, array_type=vtk.VTK_FLOAT)
    img.GetPointData().SetScalars(arr)
    return img


def gradient_ramp(range_max):
    g = vtk.vtkPiecewiseFunction()
    g.AddPoint(0.0, 0.0)
    g.AddPoint(range_max, 1.0)
    return g


def property_2d(image, gradient=True, shade=False, components=1):
    p = vtk.vtkVolumeProperty()
    p.SetInterpolationTypeToLinear()
    for c in range(components):
        p.SetColor(c, fvtest.color_function([(37.0, 0.0, 0.0, 0.0), (277.0, 1.0, 1.0, 1.0)]))
        p.SetScalarOpacity(c, fvtest.opacity_function([(37.0, 0.0), (277.0, 0.5)]))
        p.SetTransferFunction2D(c, image[c] if isinstance(image, list) else image)
        if gradient:
            p.SetGradientOpacity(c, gradient_ramp(30.0))
    p.SetTransferFunctionMode(vtk.vtkVolumeProperty.TF_2D)
    if shade:
        p.ShadeOn()
    return p


def with_unit_distance(prop, unit):
    prop.SetScalarOpacityUnitDistance(unit)
    return prop


def view(cam):
    cam.Azimuth(35.0)
    cam.Elevation(25.0)
    cam.OrthogonalizeViewUp()


class Transfer2D(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.image = fvtest.wavelet_image()
        cls.table = table_2d((0.9, 0.5, 0.1), (0.2, 0.4, 1.0))

    def pair(self, name, data, prop, floor):
        return fvtest.assert_matches_vtk(self, name, data, prop, floor, camera=view)

    def test_one_component(self):
        self.pair("tf2d-gradient", self.image, lambda: property_2d(self.table), (0.98, 35.0))
        self.pair("tf2d-no-gradient-opacity", self.image,
                  lambda: property_2d(self.table, gradient=False), (0.98, 35.0))
        self.pair("tf2d-shaded", self.image, lambda: property_2d(self.table, shade=True),
                  (0.98, 35.0))

    def test_coarse_table(self):
        """A 10 x 8 table of hard-edged boxes (ParaView's editor builds them so): VTK
        resamples it onto its 1024 x 1024 texture (vtkImageResize: Lanczos, corner points
        on corner texels), and so does the mapper before handing it to ferrovol."""
        coarse = table_2d((0.9, 0.2, 0.1), (0.1, 0.4, 1.0), bins=(10, 8), top=0.5)
        a = vtk_to_numpy(coarse.GetPointData().GetScalars())
        a[:, 3] = np.where(a[:, 3] > 0.1, a[:, 3], 0.0)
        coarse.Modified()
        self.pair("tf2d-coarse", self.image, lambda: property_2d(coarse), (0.98, 35.0))

    def test_path_traced(self):
        """The path tracer reads the 2D table as its medium (the opacity per unit distance,
        as it reads the 1D functions'): it draws, and the gradient axis matters."""
        import ferrovol
        images = []
        for table in (self.table, table_2d((0.9, 0.5, 0.1), (0.2, 0.4, 1.0), top=0.0)):
            mapper = ferrovol.vtkFerroVolumeMapper()
            mapper.SetRenderModeToPathTrace()
            mapper.SetSamplesPerPixel(8)
            errors = Errors(mapper)
            images.append(fvtest.Scene(mapper, self.image, property_2d(table),
                                       camera=view).render())
            self.assertEqual(errors.messages, [])
        fvtest.log("  path-traced 2D table: coverage %.3f; a transparent table %.3f"
                    % (coverage(images[0]), coverage(images[1])))
        self.assertGreater(coverage(images[0]), 0.05)
        self.assertEqual(coverage(images[1]), 0.0)

    def test_opacity_is_per_sample(self):
        """VTK 9.2 uploads the 2D table as it is (no correction by the unit distance or the
        sample distance): its opacity is per sample."""
        self.pair("tf2d-unit-distance", self.image,
                  lambda: with_unit_distance(property_2d(self.table), 3.0), (0.98, 35.0))

    def test_independent_components(self):
        """Each component's table holds its 1D functions on every row: the 1D image."""
        import ferrovol
        nx, ny, nz = self.image.GetDimensions()
        a = vtk_to_numpy(self.image.GetPointData().GetScalars()).reshape(nz, ny, nx)
        two = np.stack([a, a[:, :, ::-1]], axis=-1).astype(np.float32)
        img = fvtest.image_from_array(two)
        lo, hi = float(a.min()), float(a.max())
        colors = [(0.9, 0.5, 0.1), (0.1, 0.9, 0.2)]

        def flat(rgb):
            n = 256
            s = lo + (np.arange(n) + 0.5) / n * (hi - lo)
            rgba = np.zeros((4, n, 4), np.float32)
            rgba[..., :3] = rgb
            rgba[..., 3] = np.clip((s - 37.0) / 240.0, 0, 1) * 0.5
            im = vtk.vtkImageData()
            im.SetDimensions(n, 4, 1)
            im.GetPointData().SetScalars(
                numpy_to_vtk(rgba.reshape(-1, 4), deep=True, array_type=vtk.VTK_FLOAT))
            return im

        def prop(two_d):
            p = vtk.vtkVolumeProperty()
            p.SetInterpolationTypeToLinear()
            for c, rgb in enumerate(colors):
                p.SetColor(c, fvtest.color_function([(37.0, *rgb), (277.0, *rgb)]))
                p.SetScalarOpacity(c, fvtest.opacity_function([(37.0, 0.0), (277.0, 0.5)]))
                if two_d:
                    p.SetTransferFunction2D(c, flat(rgb))
            if two_d:
                p.SetTransferFunctionMode(vtk.vtkVolumeProperty.TF_2D)
            return p
        images = []
        for two_d in (False, True):
            mapper = ferrovol.vtkFerroVolumeMapper()
            errors = Errors(mapper)
            images.append(fvtest.Scene(mapper, img, prop(two_d), camera=view).render())
            self.assertEqual(errors.messages, [])
        s, p = fvtest.compare("tf2d-independent-vs-1d", images[1], images[0])
        self.assertGreater(coverage(images[1]), 0.05)
        self.assertGreaterEqual(s, 0.98)
        self.assertGreaterEqual(p, 35.0)

if __name__ == "__main__":
    unittest.main()
