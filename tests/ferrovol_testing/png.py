"""PNG files as numpy arrays (H x W x C, uint8, rows top to bottom), through VTK's PNG reader
and writer (vtkmodules: the same under /usr/bin/python3, pvpython and pvbatch)."""
import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkIOImage import vtkPNGReader, vtkPNGWriter


def read_png(path):
    r = vtkPNGReader()
    r.SetFileName(path)
    r.Update()
    im = r.GetOutput()
    w, h, _ = im.GetDimensions()
    arr = vtk_to_numpy(im.GetPointData().GetScalars())
    comps = arr.shape[1] if arr.ndim == 2 else 1
    return arr.reshape(h, w, comps)[::-1].copy()


def write_png(path, img):
    """Writes an H x W x C image of 8-bit levels (floats are truncated to uint8)."""
    a = np.ascontiguousarray(np.asarray(img)[::-1]).astype(np.uint8)
    h, w, c = a.shape
    data = vtkImageData()
    data.SetDimensions(w, h, 1)
    data.GetPointData().SetScalars(numpy_to_vtk(a.reshape(h * w, c), deep=True))
    wr = vtkPNGWriter()
    wr.SetFileName(path)
    wr.SetInputData(data)
    wr.Write()
    return path

