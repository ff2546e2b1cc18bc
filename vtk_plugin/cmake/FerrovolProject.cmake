# Project settings shared by the VTK module build (vtk_plugin/CMakeLists.txt) and the ParaView
# plugin build (paraview/CMakeLists.txt), included right after project(): C++17 without
# extensions, a Release build unless one is asked for, shared libraries.
set(CMAKE_CXX_STANDARD 17)
set(CMAKE_CXX_STANDARD_REQUIRED ON)
set(CMAKE_CXX_EXTENSIONS OFF)
if (NOT CMAKE_BUILD_TYPE AND NOT CMAKE_CONFIGURATION_TYPES)
  set(CMAKE_BUILD_TYPE Release CACHE STRING "Build type" FORCE)
endif ()
include(GNUInstallDirs)
set(BUILD_SHARED_LIBS ON)
