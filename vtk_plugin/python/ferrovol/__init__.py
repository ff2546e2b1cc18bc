"""ferrovol for VTK: vtkFerroVolumeMapper, a vtkVolumeMapper that renders with ferrovol, and
vtkFerroUnstructuredVolumeMapper, a vtkUnstructuredGridVolumeMapper for vtkUnstructuredGrid.

    import vtk, ferrovol
    mapper = ferrovol.vtkFerroVolumeMapper()
    mesh_mapper = ferrovol.vtkFerroUnstructuredVolumeMapper()

PyVista (or any vtkVolume drawn by another mapper): one call puts ferrovol under it,

    actor = plotter.add_volume(grid, cmap="bone")
    ferrovol.use(actor, path_trace=True)

C and C++ programs of the C ABI (wheel only): get_include(), get_cmake_dir().
"""
import os

# VTK's own modules first, so the wrapped base classes are registered.
import vtkmodules.vtkRenderingCore  # noqa: F401
import vtkmodules.vtkRenderingVolume  # noqa: F401
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

from .vtkFerroVolume import *  # noqa: F401,F403
from .vtkFerroVolume import vtkFerroVolumeMapper

# What use() carries over from the mapper it replaces: vtkVolumeMapper's settings and, from a
# vtkGPUVolumeRayCastMapper (PyVista's 'gpu', 'open_gl' and 'smart' mappers are ones or hold
# one), those vtkFerroVolumeMapper shares with it. Each is a Get/Set pair.
_CARRIED = (
    "BlendMode", "ScalarMode", "ArrayAccessMode", "Cropping", "CroppingRegionPlanes",
    "CroppingRegionFlags", "ClippingPlanes", "AverageIPScalarRange",
    "SampleDistance", "AutoAdjustSampleDistances", "LockSampleDistanceToInputSpacing",
    "ImageSampleDistance", "MinimumImageSampleDistance", "MaximumImageSampleDistance",
    "UseJittering", "FinalColorWindow", "FinalColorLevel", "MaskType", "MaskBlendFactor",
    "ColorRangeType", "ScalarOpacityRangeType", "GradientOpacityRangeType",
    "GlobalIlluminationReach", "VolumetricScatteringBlending", "ComputeNormalFromOpacity")


def use(volume, path_trace=False, **settings):
    """Draws `volume` (a vtkVolume, such as the actor PyVista's Plotter.add_volume returns)
    with a new vtkFerroVolumeMapper and returns that mapper.

    The new mapper takes the old one's input (its connection, or its data), the scalar array
    it selected, its settings (blend mode, cropping, clipping planes, sample distances …) and,
    from a vtkGPUVolumeRayCastMapper, its mask input; the volume keeps its property. With
    `path_trace`, the volume is path traced (SetRenderModeToPathTrace): in an interactive
    window the image refines by itself while the camera rests. Other keyword arguments are
    mapper settings by name, as `Set<Name>(value)`: use(actor, SamplesPerPixel=256).
    """
    old = volume.GetMapper()
    mapper = vtkFerroVolumeMapper()
    if old is not None:
        # PyVista's 'smart' mapper draws through a vtkGPUVolumeRayCastMapper it holds.
        source = old.GetGPUMapper() if hasattr(old, "GetGPUMapper") else old
        if old.GetNumberOfInputConnections(0) > 0:
            mapper.SetInputConnection(old.GetInputConnection(0, 0))
        elif old.GetInputDataObject(0, 0) is not None:
            mapper.SetInputDataObject(old.GetInputDataObject(0, 0))
        if old.GetArrayAccessMode() == 1:  # VTK_GET_ARRAY_BY_NAME
            mapper.SelectScalarArray(old.GetArrayName())
        else:
            mapper.SelectScalarArray(old.GetArrayId())
        for name in _CARRIED:
            for origin in (old, source):
                getter = getattr(origin, "Get" + name, None)
                if getter is not None and hasattr(mapper, "Set" + name):
                    value = getter()
                    if name == "SampleDistance" and value is not None and value <= 0:
                        # vtkSmartVolumeMapper's "from the spacing": half the mean spacing
                        data = old.GetInputDataObject(0, 0)
                        spacing = data.GetSpacing() if hasattr(data, "GetSpacing") else None
                        value = sum(spacing) / 6.0 if spacing else None
                    if value is not None:
                        setter = getattr(mapper, "Set" + name)
                        setter(*value) if isinstance(value, tuple) else setter(value)
                    break
        mask = getattr(source, "GetMaskInput", lambda: None)()
        if mask is not None:
            mapper.SetMaskInput(mask)
    if path_trace:
        mapper.SetRenderModeToPathTrace()
    for name, value in settings.items():
        setter = getattr(mapper, "Set" + name, None)
        if setter is None:
            raise AttributeError(f"vtkFerroVolumeMapper has no setting {name} (Set{name})")
        setter(*value) if isinstance(value, tuple) else setter(value)
    volume.SetMapper(mapper)
    return mapper


def _packaged(name, what):
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), name)
    if not os.path.isdir(path):
        raise FileNotFoundError(
            f"{path}: this ferrovol was not installed from its wheel, which holds {what}; in "
            "a source tree the C ABI's headers are ffi/include, its library "
            "target/release/libferrovol.so")
    return path


def get_include():
    """The folder of the C and C++ headers (ferrovol.h, ferrovol.hpp, vtkFerroVolumeMapper.h)
    in the wheel."""
    return _packaged("include", "the headers")


def get_cmake_dir():
    """The folder of the wheel's CMake package for C and C++ programs of the C ABI:
    cmake -Dferrovol_DIR=$(python -c 'import ferrovol; print(ferrovol.get_cmake_dir())'),
    then find_package(ferrovol) and target_link_libraries(app PRIVATE ferrovol::ferrovol)."""
    return _packaged("cmake", "the CMake package")
