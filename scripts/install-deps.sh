#!/usr/bin/env bash
# Installs what ferrovol needs on a Debian bookworm machine. Idempotent: when everything
# is present it only checks (a few seconds). VTK comes from ParaView 5.11's packages
# (see docs/ARCHITECTURE.md, Machines): never libvtk9-dev / python3-vtk9.
set -euo pipefail
PKGS=(mesa-vulkan-drivers libvulkan1 xvfb xauth cmake ninja-build pkg-config
      paraview paraview-dev python3-paraview python3-numpy zlib1g-dev
      g++ libegl-dev libgl-dev
      libopenmpi-dev libglew-dev)
# libopenmpi-dev, libglew-dev: ParaView's VTK CMake package needs MPI's and GLEW's headers
# to build a VTK module against it (vtk_plugin/, paraview/).
PKGS+=(libdouble-conversion-dev)
PKGS+=(python3-scipy)
# python3-scipy: image filtering for the FLIP metric of the regression suite
# (tests/ferrovol_testing/flip.py).
# libdouble-conversion-dev: find_package(ParaView COMPONENTS RemotingViews ...) (paraview/)
# pulls in VTK::IOCore, whose CMake package requires double-conversion's headers.
PKGS+=(afl++)
# afl++: afl-fuzz and the runtime (/usr/lib/afl/afl-compiler-rt.o) the readers' fuzz
# targets link (scripts/fuzz.sh, `make fuzz-smoke`); it brings clang-14 with it.
PKGS+=(valgrind)
# valgrind: memcheck over the C ABI demo (scripts/sanitize.sh, `make sanitize`). The
# sanitizer runtimes (libasan8, libubsan1, liblsan0, libtsan2) come with g++.
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
command -v cargo >/dev/null || { echo "install-deps: cargo (Rust toolchain) is required" >&2; exit 1; }
