#!/usr/bin/env bash
# The wheel as a pip user gets it (make test's `wheel` suite): packs build/vtk-pip with the
# given libferrovol into build/wheel-test/dist, installs it and PyVista into a new venv
# (pip pulls the vtk it requires), and runs tests/wheel/test_wheel.py there, with nothing
# of the build tree on any path. Images in build/wheel-test/images.
#   tests/wheel/run.sh LIBFERROVOL
set -euo pipefail
cd "$(dirname "$0")/../.."
lib=$1
out=build/wheel-test
. build/vtk-sdk/sdk.env
rm -rf "$out"
wheel=$("$FERROVOL_SDK_PYTHON" scripts/wheel.py build/vtk-pip "$lib" "$out/dist")
echo "wheel: $wheel ($(du -h "$wheel" | cut -f1))"
python3 -m venv "$out/venv"
"$out/venv/bin/pip" install -q --no-compile "$wheel" pyvista
"$out/venv/bin/pip" list 2>/dev/null | grep -iE "^(ferrovol|vtk|pyvista) "
cd tests
env -u PYTHONPATH -u LD_LIBRARY_PATH FERROVOL_TEST_OUTPUT="$PWD/../$out/images" \
  ../scripts/with-xvfb.sh ../vtk_plugin/tests/retry-on-x-failure.sh \
  "../$out/venv/bin/python" -m unittest -v wheel/test_wheel.py
