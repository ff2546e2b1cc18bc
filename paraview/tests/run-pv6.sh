#!/usr/bin/env bash
# The ParaView plugin's tests against Debian unstable's ParaView 6.1 (make paraview6-test):
#   paraview/tests/run-pv6.sh [RANKS]     (needs an X display: run it under scripts/with-xvfb.sh)
# 1. scripts/pv6-sdk.sh: unstable's ParaView, its runtime and its CMake package in
#    build/pv6-sdk (kept once made);
# 2. the plugin built against it in build/pv6-paraview with the machine's compiler (unstable's
#    headers, unstable's libraries at link time);
# 3. paraview/tests/run-all.sh with build/pv6-sdk/bin first in PATH: pvbatch, pvpython,
#    paraview and mpiexec there run unstable's programs through unstable's loader. Images and
#    logs: build/pv6-paraview-test.
# FERROVOL_LIBRARY: the libferrovol.so to link (default target/release/libferrovol.so).
set -euo pipefail
cd "$(dirname "$0")/../.."
RANKS="${1:-2}"
t0=$(date +%s)
sdk_env=$(scripts/pv6-sdk.sh)
# shellcheck source=/dev/null
. "$sdk_env"
t1=$(date +%s)
BUILD=build/pv6-paraview
L=$FERROVOL_PV6_ROOT/usr/lib/x86_64-linux-gnu
"$FERROVOL_PV6_CMAKE" -G Ninja -S paraview -B "$BUILD" -Wno-deprecated -Wno-dev \
  -DFERROVOL_PARAVIEW_DIR="$FERROVOL_PV6_DIR" -DParaView_DIR="$FERROVOL_PV6_DIR" \
  -DVTK_DIR="$FERROVOL_PV6_VTK_DIR" \
  -DCMAKE_SHARED_LINKER_FLAGS="-Wl,-rpath-link,$L -Wl,--allow-shlib-undefined" \
  -DFERROVOL_LIBRARY="${FERROVOL_LIBRARY:-$PWD/target/release/libferrovol.so}" \
  >build/pv6-paraview-configure.log 2>&1 || { cat build/pv6-paraview-configure.log; exit 1; }
ninja -C "$BUILD" -j2 | { grep -v '^\[' || true; }
t2=$(date +%s)
echo "== ParaView $PARAVIEW_VERSION (Debian unstable): SDK ready in $((t1 - t0)) s, plugin built in $((t2 - t1)) s"

export PATH="$FERROVOL_PV6_BIN:$PATH"
export FERROVOL_PV_BUILD="$BUILD"
export FERROVOL_PV_PLUGIN_DIR="$PWD/$BUILD/lib/paraview-${PARAVIEW_VERSION%.*}/plugins/Ferrovol"
export FERROVOL_PV_TEST_OUT="${FERROVOL_PV_TEST_OUT:-$PWD/build/pv6-paraview-test}"
exec paraview/tests/run-all.sh "$RANKS"
