"""ferrovol for VTK: vtkFerroVolumeMapper, a vtkVolumeMapper that renders with ferrovol.

    import vtk, ferrovol
    mapper = ferrovol.vtkFerroVolumeMapper()
"""
# VTK's own modules first, so the wrapped base classes are registered.
import vtkmodules.vtkRenderingCore  # noqa: F401
import vtkmodules.vtkRenderingVolume  # noqa: F401
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

from .vtkFerroVolume import *  # noqa: F401,F403
