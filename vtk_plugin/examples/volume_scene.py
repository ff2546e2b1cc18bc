"""The VTK set-up the Python examples share: transfer functions and a vtkVolumeProperty from
points, an off-screen window and its PNG. The examples import it from their own folder
(Python puts a script's folder on its path), so run them where they stand:

    /usr/bin/python3 vtk_plugin/examples/cranium.py --out cranium.png

bench/multi_volume.py and the VTK module's tests (vtk_plugin/tests/fvtest.py) use it too.
"""
import vtk

# VTK's TestGPURayCastMapperBenchmark transfer function for the wavelet.
WAVELET_COLOR = [(37.3531, 0.2, 0.29, 1.0), (157.091, 0.87, 0.87, 0.87),
                 (276.829, 0.7, 0.015, 0.15)]
WAVELET_OPACITY = [(37.3531, 0.0), (276.829, 1.0)]


def color_function(points):
    """A vtkColorTransferFunction through (value, r, g, b) points."""
    color = vtk.vtkColorTransferFunction()
    for x, r, g, b in points:
        color.AddRGBPoint(x, r, g, b)
    return color


def opacity_function(points):
    """A vtkPiecewiseFunction through (value, y) points."""
    function = vtk.vtkPiecewiseFunction()
    for x, y in points:
        function.AddPoint(x, y)
    return function


def volume_property(colors, opacities):
    """A vtkVolumeProperty from (value, r, g, b) colour points and (value, opacity) points."""
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(color_function(colors))
    prop.SetScalarOpacity(opacity_function(opacities))
    return prop


def offscreen_window(renderer, size):
    """An off-screen render window, size pixels square, drawing renderer."""
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(size, size)
    win.AddRenderer(renderer)
    return win


def write_png(win, path):
    """Writes what win drew (its back buffer) to the PNG at path."""
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.ReadFrontBufferOff()
    grab.Update()
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
