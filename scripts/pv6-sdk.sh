#!/usr/bin/env bash
# Builds the SDK that compiles and runs the ParaView plugin against Debian unstable's ParaView
# 6.1 (make paraview6-test), installing nothing on the machine:
#   - Debian unstable's paraview, python3-paraview and python3-numpy with their whole runtime
#     closure (glibc, libstdc++, Python 3.14, VTK 9.6, Open MPI 5, HDF5, Mesa, Qt 6 ...),
#     resolved by apt against an empty dpkg status under a private apt configuration, plus
#     paraview-dev (headers and CMake package, without its -dev dependencies), all unpacked
#     with dpkg-deb -x into build/pv6-sdk/root;
#   - the CMake package patched (inside root/ only) so that find_package(ParaView) looks for
#     Threads and MPI only: every other package it wants (Qt, GDAL, ...) is skipped and every
#     imported target it names from them is an empty stand-in;
#   - bin/: pvbatch, pvpython, paraview, mpiexec (and the programs they start) that run
#     unstable's programs through unstable's dynamic loader and libraries (they need its
#     glibc 2.43): the machine's own ParaView 5.11 stays what /usr/bin has.
# CMake >= 3.27 comes from build/vtk-sdk/venv (scripts/vtk-sdk.sh) or, lacking it, a venv here.
# Writes build/pv6-sdk/sdk.env (PARAVIEW_VERSION, FERROVOL_PV6_ROOT, FERROVOL_PV6_DIR,
# FERROVOL_PV6_BIN, FERROVOL_PV6_CMAKE, FERROVOL_PV6_LIBPATH) and prints its path.
# Idempotent: a complete SDK of the version Debian serves is kept.
#   scripts/pv6-sdk.sh
set -euo pipefail
cd "$(dirname "$0")/.."
SDK=$PWD/build/pv6-sdk
ARCH=x86_64-linux-gnu
. scripts/sdk/sid-apt.sh
# An empty dpkg status: apt resolves the whole closure, as for an empty system.
sid_apt_init "$SDK/apt" closure
PV_VERSION=$(sid_version paraview-dev)
mm=${PV_VERSION%.*}
if [ -f "$SDK/sdk.env" ] && grep -qx "PARAVIEW_VERSION=$PV_VERSION" "$SDK/sdk.env"; then
  echo "$SDK/sdk.env"
  exit 0
fi
rm -rf "$SDK/root" "$SDK/bin" "$SDK/debs" "$SDK/sdk.env"
t0=$(date +%s)

# CMake >= 3.27 (Debian unstable's VTK package needs it; bookworm has 3.25).
cmake_ok() { "$1" -P /dev/stdin <<<'if (CMAKE_VERSION VERSION_LESS 3.27)
  message(FATAL_ERROR old)
endif ()' >/dev/null 2>&1; }
CMAKE=
for c in "$PWD/build/vtk-sdk/venv/bin/cmake" "$SDK/venv/bin/cmake" "$(command -v cmake || true)"; do
  if [ -x "$c" ] && cmake_ok "$c"; then CMAKE=$c; break; fi
done
if [ -z "$CMAKE" ]; then
  python3 -m venv "$SDK/venv"
  "$SDK/venv/bin/pip" install -q "cmake>=3.27"
  CMAKE=$SDK/venv/bin/cmake
fi

# The runtime closure (no recommends; mesa-vulkan-drivers: lavapipe, the Vulkan device of
# ferrovol beside Mesa's OpenGL, of the same Mesa) and paraview-dev alone (its dependencies are -dev
# packages of GDAL and Eigen, which a plugin that uses neither does not need).
mkdir -p "$SDK/debs/partial"
sid_apt -qq -o "Dir::Cache::archives=$SDK/debs" install --download-only \
  --no-install-recommends paraview python3-paraview python3-numpy mpi-default-bin \
  mesa-vulkan-drivers
sid_download "$SDK/debs" paraview-dev
ndebs=$(find "$SDK/debs" -maxdepth 1 -name '*.deb' | wc -l)
mb=$(du -sm "$SDK/debs" | cut -f1)
t1=$(date +%s)
sid_unpack "$SDK/root" "$SDK"/debs/*.deb
rm -rf "$SDK/debs"
t2=$(date +%s)
echo "pv6-sdk: $ndebs packages, $mb MB downloaded in $((t1 - t0)) s, unpacked in $((t2 - t1)) s" \
  "($(du -sm "$SDK/root" | cut -f1) MB)" >&2

# Headers and CMake package of VTK 9.6 (ParaView's CMake package finds VTK as an external
# package) and VTK's wrapping tools (vtk9: vtkWrapHierarchy); alone, like paraview-dev.
sid_download "$SDK/debs" libvtk9-dev vtk9
sid_unpack "$SDK/root" "$SDK"/debs/*.deb
rm -rf "$SDK/debs"

R=$SDK/root
L=$R/usr/lib/$ARCH
# Where unstable's loader finds unstable's libraries (Debian's alternatives would put BLAS
# and LAPACK into the multiarch directory; armadillo installs into /usr/lib).
LIBPATH="$L:$L/blas:$L/lapack:$L/libproxy:$R/usr/lib"

# Programs: each unstable program the tests or the build run gets a script of the same name
# in bin/ that runs it through unstable's loader. The wrapping tools the CMake packages name
# (root/usr/bin/vtkWrap*, vtkProcessXML-*, ...) are replaced in place by such scripts (the
# programs move to root/usr/libexec/ferrovol-sdk/).
mkdir -p "$SDK/bin" "$R/usr/libexec/ferrovol-sdk"
sed "s|\"library_path\": *\"[^\"]*libvulkan_lvp.so\"|\"library_path\": \"$L/libvulkan_lvp.so\"|" \
  "$R"/usr/share/vulkan/icd.d/lvp_icd.json >"$R/usr/share/vulkan/icd.d/ferrovol-sdk-lvp.json"
grep -q "$L/libvulkan_lvp.so" "$R/usr/share/vulkan/icd.d/ferrovol-sdk-lvp.json"
# Besides: unstable's Python (PYTHONHOME), Qt's plugins (QT_PLUGIN_PATH: the GUI's xcb
# platform), Open MPI's relocation (OPAL_PREFIX; OMPI_PRTERUN: mpirun runs root/usr/bin/prterun,
# a script too; PMIx's plugins, not bookworm's in /usr/lib/x86_64-linux-gnu/pmix2), unstable's
# lavapipe as the only Vulkan driver (VK_ICD_FILENAMES: the machine's lists bookworm's), and a
# Mesa shader cache of its own: Mesa 26 reading the cache bookworm's Mesa 22 wrote in
# ~/.cache/mesa_shader_cache dies with SIGBUS (measured: in VTK's volume shader).
# ARGV0 (optional): what the program sees as its name, e.g. '"$0"' for prte, which acts as
# prterun when called by that name (the default is the program's own path: ParaView finds its
# files from it).
wrap() {  # wrap SCRIPT PROGRAM [ARGV0]
  local argv0=${3:-\"$2\"}
  cat >"$1" <<EOF
#!/bin/sh
# scripts/pv6-sdk.sh: Debian unstable's $(basename "$2"), through unstable's loader and libraries.
export PYTHONHOME="$R/usr" QT_PLUGIN_PATH="$L/qt6/plugins" OPAL_PREFIX="$R/usr"
export OMPI_PRTERUN="$R/usr/bin/prterun" PMIX_MCA_mca_base_component_path="$L/pmix2/lib/pmix"
export VK_ICD_FILENAMES="$R/usr/share/vulkan/icd.d/ferrovol-sdk-lvp.json"
export MESA_SHADER_CACHE_DIR="\${FERROVOL_PV6_MESA_CACHE:-$SDK/mesa-shader-cache}"
exec "$L/ld-linux-x86-64.so.2" --library-path "$LIBPATH" --argv0 $argv0 "$2" "\$@"
EOF
  chmod +x "$1"
}
for tool in "$R"/usr/bin/vtkWrap*-9.* "$R"/usr/bin/vtkParse*-9.* \
    "$R"/usr/bin/vtkProcessXML-pv* "$R"/usr/bin/vtkprotoc-pv* "$R"/usr/bin/vtkWrapClientServer-pv* \
    "$R"/usr/bin/prte "$R"/usr/bin/prted; do
  [ -f "$tool" ] && [ ! -L "$tool" ] || continue
  case $(head -c 4 "$tool") in $'\x7fELF') ;; *) continue ;; esac
  mv "$tool" "$R/usr/libexec/ferrovol-sdk/"
  wrap "$tool" "$R/usr/libexec/ferrovol-sdk/$(basename "$tool")" '"$0"'
done
for prog in pvbatch pvpython paraview pvserver mpiexec.openmpi ompi_info; do
  [ -e "$R/usr/bin/$prog" ] && wrap "$SDK/bin/$prog" "$(readlink -f "$R/usr/bin/$prog")"
done
ln -sf mpiexec.openmpi "$SDK/bin/mpiexec"
ln -sf mpiexec.openmpi "$SDK/bin/mpirun"
"$SDK/bin/pvbatch" --version >/dev/null

# CMake packages (scripts/sdk/cmake_package.py): of the packages VTK's and ParaView's modules
# look for only Threads and MPI are looked for (the machine's; unstable's libmpi.so.40 is what
# runs), the rest are stand-ins.
python3 scripts/sdk/cmake_package.py "$R/usr" "$(ls -d "$L"/cmake/vtk-9.*)" \
  "$L/cmake/paraview-$mm" --find Threads --find MPI

cat >"$SDK/sdk.env" <<EOF
PARAVIEW_VERSION=$PV_VERSION
FERROVOL_PV6_ROOT=$R
FERROVOL_PV6_DIR=$L/cmake/paraview-$mm
FERROVOL_PV6_VTK_DIR=$(ls -d "$L"/cmake/vtk-9.*)
FERROVOL_PV6_BIN=$SDK/bin
FERROVOL_PV6_LIBPATH=$LIBPATH
FERROVOL_PV6_CMAKE=$CMAKE
EOF
echo "pv6-sdk: done in $(($(date +%s) - t0)) s ($(du -sm "$SDK" | cut -f1) MB)" >&2
echo "$SDK/sdk.env"
