"""The VTK set-up the Python examples share: a vtkVolumeProperty from transfer-function
points, an off-screen window and its PNG. The examples import it from their own folder
(Python puts a script's folder on its path), so run them where they stand:

    /usr/bin/python3 vtk_plugin/examples/cranium.py --out cranium.png

bench/multi_volume.py and the VTK module's tests (vtk_plugin/tests/fvtest.py) use it too.
"""
import vtk


def volume_property(colors, opacities):
    """A vtkVolumeProperty from (value, r, g, b) colour points and (value, opacity) points."""
    color = vtk.vtkColorTransferFunction()
    for x, r, g, b in colors:
        color.AddRGBPoint(x, r, g, b)
    opacity = vtk.vtkPiecewiseFunction()
    for x, a in opacities:
        opacity.AddPoint(x, a)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
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
