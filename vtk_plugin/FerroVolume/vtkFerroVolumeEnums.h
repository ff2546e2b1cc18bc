/**
 * @class   vtkFerroVolumeEnums
 * @brief   The constants of vtkFerroVolumeMapper's mode settings, in a header of their own.
 *
 * vtkFerroVolumeMapper's modes (SetSpecularSampling, SetIsosurfaceScattering, SetRenderMode,
 * SetProgressiveMode, SetScatterRegions, SetOutputPath) are members of the mapper, read as
 * vtkFerroVolumeMapper::RENDER_MODE_PATH_TRACE in C++ and vtkFerroVolumeMapper.
 * RENDER_MODE_PATH_TRACE in Python. The mapper's units that need only these constants read
 * them from vtkFerroVolumeEnums (the same names and values) and include this header instead
 * of the mapper's.
 *
 * One list, vtkFerroVolumeEnumsMacro, declares them in both classes: VTK's Python wrapping
 * exposes a class's own enums only (not those of a second base class), and it expands the
 * macro as the compiler does.
 */

#ifndef vtkFerroVolumeEnums_h
#define vtkFerroVolumeEnums_h

#include "vtkWrappingHints.h" // For VTK_WRAPEXCLUDE

#define vtkFerroVolumeEnumsMacro                                                            \
  /* SetSpecularSampling: how isosurfaces sample the specular environment light */          \
  enum SpecularSamplingModes                                                                \
  {                                                                                         \
    SPECULAR_CONE = 0,                                                                      \
    SPECULAR_IMPORTANCE = 1                                                                 \
  };                                                                                        \
  /* SetIsosurfaceScattering: light scattered between isosurface layers */                  \
  enum IsosurfaceScatteringModes                                                            \
  {                                                                                         \
    ISOSURFACE_SCATTERING_OFF = 0,                                                          \
    ISOSURFACE_SCATTERING_PREVIEW = 1,                                                      \
    ISOSURFACE_SCATTERING_TRACED = 2                                                        \
  };                                                                                        \
  /* SetRenderMode: ray casting in the blend mode, or path tracing */                       \
  enum RenderModes                                                                          \
  {                                                                                         \
    RENDER_MODE_RAY_CAST = 0,                                                               \
    RENDER_MODE_PATH_TRACE = 1                                                              \
  };                                                                                        \
  /* SetProgressiveMode: whether path tracing refines over several renders */               \
  enum ProgressiveModes                                                                     \
  {                                                                                         \
    PROGRESSIVE_AUTOMATIC = 0,                                                              \
    PROGRESSIVE_ON = 1,                                                                     \
    PROGRESSIVE_OFF = 2                                                                     \
  };                                                                                        \
  /* SetScatterRegions: where path-traced collisions scatter */                             \
  enum ScatterRegionModes                                                                   \
  {                                                                                         \
    SCATTER_NOWHERE = 0,                                                                    \
    SCATTER_SURFACES = 1,                                                                   \
    SCATTER_BETWEEN = 2,                                                                    \
    SCATTER_EVERYWHERE = 3                                                                  \
  };                                                                                        \
  /* SetOutputPath: how frames travel from ferrovol to OpenGL */                            \
  enum OutputPaths                                                                          \
  {                                                                                         \
    OUTPUT_PATH_AUTOMATIC = 0,                                                              \
    OUTPUT_PATH_READBACK = 1,                                                               \
    OUTPUT_PATH_SHARED = 2                                                                  \
  }

// (not wrapped: Python reads the constants from vtkFerroVolumeMapper)
class VTK_WRAPEXCLUDE vtkFerroVolumeEnums
{
public:
  vtkFerroVolumeEnumsMacro;
};

#endif
