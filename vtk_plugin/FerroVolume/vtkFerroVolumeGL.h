// vtkFerroVolumeGL.h: VTK's OpenGL function loader, whichever this VTK has (GLEW up to VTK
// 9.2, glad from 9.3: VTK_MODULE_ENABLE_VTK_glad comes from vtk.module's OPTIONAL_DEPENDS),
// and the one extension query the module makes. Internal to the FerroVolume module.
#ifndef vtkFerroVolumeGL_h
#define vtkFerroVolumeGL_h

#if VTK_MODULE_ENABLE_VTK_glad
#include "vtk_glad.h"
// Whether the current context has GL_EXT_memory_object_fd (zero-copy output).
#define vtkFerroVolumeGLHasMemoryObjectFd() (GLAD_GL_EXT_memory_object_fd != 0)
#else
#include "vtk_glew.h"
#define vtkFerroVolumeGLHasMemoryObjectFd() (GLEW_EXT_memory_object_fd != 0)
#endif

#endif
