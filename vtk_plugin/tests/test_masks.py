"""Masks (vtkGPUVolumeRayCastMapper's MaskInput, MaskType, MaskBlendFactor and
vtkVolumeProperty's label functions), each scene against vtkGPUVolumeRayCastMapper: a binary
mask in composite, MIP and the isosurface mode, a label map of three labels (colour, opacity
and gradient opacity of their own), the blend factor."""
import unittest

import numpy as np
import vtk

import fvtest
from fvtest import coverage, image_from_array, render_pair, tf_property


def wavelet_image(start=(0, 0, 0)):
    """The wavelet with its extent starting at `start`. VTK 9.2 places a mask wrongly (mirrored)
    on an image whose extent does not start at 0: its scenes are compared at (0, 0, 0)."""
    return fvtest.wavelet_image(start=start)


def mask_like(image, values):
    """A mask image with `image`'s geometry holding `values` ([z, y, x] uint8)."""
    m = image_from_array(values, spacing=image.GetSpacing(), origin=image.GetOrigin(),
                         name="mask")
    m.SetExtent(image.GetExtent())
    return m


def grid(image):
    """Point index arrays (z, y, x) of `image`, each in [-1, 1] from edge to edge."""
    nx, ny, nz = image.GetDimensions()
    z, y, x = np.mgrid[0:nz, 0:ny, 0:nx].astype(np.float64)
    return 2 * z / (nz - 1) - 1, 2 * y / (ny - 1) - 1, 2 * x / (nx - 1) - 1


def view(cam):
    cam.Azimuth(35.0)
    cam.Elevation(25.0)
    cam.OrthogonalizeViewUp()


def label_property():
    """The wavelet's property, label 1 red, label 2 green and half as opaque, label 3 blue
    and visible only where the gradient is steep."""
    p = tf_property(opacity=[(37.3531, 0.0), (276.829, 0.6)])
    flat = {1: (1.0, 0.1, 0.1), 2: (0.1, 0.9, 0.2), 3: (0.2, 0.3, 1.0)}
    for label, rgb in flat.items():
        ctf = vtk.vtkColorTransferFunction()
        ctf.AddRGBPoint(37.3531, *rgb)
        ctf.AddRGBPoint(276.829, *rgb)
        p.SetLabelColor(label, ctf)
    half = vtk.vtkPiecewiseFunction()
    half.AddPoint(37.3531, 0.0)
    half.AddPoint(276.829, 0.3)
    p.SetLabelScalarOpacity(2, half)
    steep = vtk.vtkPiecewiseFunction()
    steep.AddPoint(0.0, 0.0)
    steep.AddPoint(10.0, 1.0)
    p.SetLabelGradientOpacity(3, steep)
    return p


class Masks(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.image = wavelet_image()
        z, y, x = grid(cls.image)
        cls.ball = mask_like(cls.image, (x * x + y * y + z * z < 0.7).astype(np.uint8) * 255)
        labels = np.zeros(x.shape, np.uint8)
        labels[x > 0.2] = 1
        labels[(x <= 0.2) & (y > 0.0)] = 2
        labels[(x <= 0.2) & (y <= 0.0) & (z > 0.3)] = 3
        cls.labels = mask_like(cls.image, labels)

    def pair(self, name, prop, configure, floor):
        return fvtest.assert_matches_vtk(self, name, self.image, prop, floor, camera=view,
                                         configure=configure)

    def test_binary_mask(self):
        def binary(blend):
            def configure(m):
                m.SetMaskInput(self.ball)
                m.SetMaskTypeToBinary()
                m.SetBlendMode(blend)
            return configure
        plain, _, _ = render_pair(self.image, tf_property, camera=view)
        masked = self.pair("mask-binary-composite", tf_property,
                           binary(vtk.vtkVolumeMapper.COMPOSITE_BLEND), (0.98, 35.0))
        self.assertGreater(np.abs(plain - masked).mean(), 1.0, "the mask changes the image")
        self.pair("mask-binary-mip", tf_property,
                  binary(vtk.vtkVolumeMapper.MAXIMUM_INTENSITY_BLEND), (0.98, 35.0))

    def test_label_map(self):
        def labelled(factor):
            def configure(m):
                m.SetMaskInput(self.labels)
                m.SetMaskTypeToLabelMap()
                m.SetMaskBlendFactor(factor)
            return configure
        ours = self.pair("mask-labels", label_property, labelled(1.0), (0.98, 35.0))
        red = (ours[..., 0] > 1.5 * ours[..., 1]) & (ours[..., 0] > 40)
        green = (ours[..., 1] > 1.5 * ours[..., 0]) & (ours[..., 1] > 40)
        fvtest.log("  label map: %d red, %d green pixels" % (red.sum(), green.sum()))
        self.assertGreater(red.sum(), 200)
        self.assertGreater(green.sum(), 200)
        self.pair("mask-labels-half", label_property, labelled(0.5), (0.98, 35.0))
        self.pair("mask-labels-shaded", lambda: shaded(label_property()), labelled(1.0),
                  (0.98, 35.0))

    def test_extent_start_does_not_move_the_mask(self):
        """ferrovol: the same mask on the same wavelet, its extent from -31 instead of 0 (the
        scene moved by 31 along each axis with its camera), draws the same image."""
        import ferrovol
        moved = wavelet_image(start=(-31, -31, -31))
        images = []
        for img in (self.image, moved):
            z, y, x = grid(img)
            mask = mask_like(img, (x > 0.2).astype(np.uint8))
            mapper = ferrovol.vtkFerroVolumeMapper()
            mapper.SetMaskInput(mask)
            mapper.SetMaskTypeToBinary()
            images.append(fvtest.Scene(mapper, img, tf_property(), camera=view).render())
        diff = np.abs(images[0] - images[1]).max()
        fvtest.log("  extent from -31 vs 0: max difference %d levels" % diff)
        self.assertLessEqual(diff, 1)
        self.assertGreater(coverage(images[0]), 0.05)

    def test_binary_mask_isosurface(self):
        def configure(m):
            m.SetMaskInput(self.ball)
            m.SetMaskTypeToBinary()
            m.SetBlendModeToIsoSurface()

        def prop():
            p = shaded(tf_property(opacity=[(37.3531, 1.0), (276.829, 1.0)]))
            p.GetIsoSurfaceValues().SetValue(0, 150.0)
            return p
        self.pair("mask-binary-isosurface", prop, configure, (0.95, 28.0))


def shaded(prop):
    prop.ShadeOn()
    return prop


if __name__ == "__main__":
    unittest.main()
