# ferrovol::ferrovol — the Rust library's C ABI (ffi/, `cargo build --release --locked
# -p ferrovol-ffi`) as an IMPORTED target. Included by vtk_plugin/CMakeLists.txt and, through
# FerroVolume/CMakeLists.txt, by any other project that builds the FerroVolume module (the
# ParaView plugin). Override FERROVOL_LIBRARY / FERROVOL_INCLUDE_DIR to use another build.
if (TARGET ferrovol::ferrovol)
  return()
endif ()

get_filename_component(_ferrovol_root "${CMAKE_CURRENT_LIST_DIR}/../.." ABSOLUTE)
set(FERROVOL_LIBRARY "${_ferrovol_root}/target/release/libferrovol.so"
  CACHE FILEPATH "ferrovol's shared library (cargo build --release --locked -p ferrovol-ffi)")
set(FERROVOL_INCLUDE_DIR "${_ferrovol_root}/ffi/include"
  CACHE PATH "Directory holding ferrovol.h")

if (NOT EXISTS "${FERROVOL_INCLUDE_DIR}/ferrovol.h")
  message(FATAL_ERROR
    "ferrovol.h not found in FERROVOL_INCLUDE_DIR=${FERROVOL_INCLUDE_DIR}; "
    "point it at ferrovol's ffi/include.")
endif ()
if (NOT EXISTS "${FERROVOL_LIBRARY}")
  message(FATAL_ERROR
    "ferrovol's library not found at FERROVOL_LIBRARY=${FERROVOL_LIBRARY}. Build it first "
    "(in ${_ferrovol_root}: cargo build --release --locked -p ferrovol-ffi) or set "
    "-DFERROVOL_LIBRARY=/path/to/libferrovol.so.")
endif ()

# The zero-copy output path (fv_renderer_shared_image & co.) is compiled in when the header
# declares it; otherwise the mapper reads frames back through the CPU.
file(STRINGS "${FERROVOL_INCLUDE_DIR}/ferrovol.h" _ferrovol_shared REGEX "fv_renderer_shared_image")
if (_ferrovol_shared)
  set(FERROVOL_HAVE_SHARED_OUTPUT 1)
else ()
  set(FERROVOL_HAVE_SHARED_OUTPUT 0)
endif ()
message(STATUS "ferrovol: ${FERROVOL_LIBRARY} (shared output path: ${FERROVOL_HAVE_SHARED_OUTPUT})")

add_library(ferrovol::ferrovol SHARED IMPORTED GLOBAL)
set_target_properties(ferrovol::ferrovol PROPERTIES
  IMPORTED_LOCATION "${FERROVOL_LIBRARY}"
  # cargo's cdylib has no SONAME: link as -lferrovol so the binaries record "libferrovol.so"
  IMPORTED_NO_SONAME TRUE
  INTERFACE_INCLUDE_DIRECTORIES "${FERROVOL_INCLUDE_DIR}"
  INTERFACE_COMPILE_DEFINITIONS "FERROVOL_HAVE_SHARED_OUTPUT=${FERROVOL_HAVE_SHARED_OUTPUT}")
get_filename_component(FERROVOL_LIBRARY_DIR "${FERROVOL_LIBRARY}" DIRECTORY)
