#!/usr/bin/env bash
# Installs the real test volumes from Debian packages (../shared/DATA.md) and converts them
# once into build/data/ (never committed). Idempotent.
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p build/data
need=()
dpkg-query -W -f='${Status}' invesalius-examples 2>/dev/null | grep -q "install ok installed" || need+=(invesalius-examples)
dpkg-query -W -f='${Status}' mricron-data 2>/dev/null | grep -q "install ok installed" || need+=(mricron-data)
if [ ${#need[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need[@]}" >/dev/null
fi
[ -f build/data/cranium.vti ] || python3 scripts/convert_inv3.py \
  /usr/share/doc/invesalius-examples/examples/Cranium.inv3 build/data/cranium.vti
[ -f build/data/colin27.nii.gz ] || cp /usr/share/mricron/templates/ch2.nii.gz build/data/colin27.nii.gz
# mayavi2's heart.vti (a small float32 CT volume): taken out of the .deb, not installed.
if [ ! -f build/data/heart.vti ]; then
  tmp=$(mktemp -d)
  if ! (cd "$tmp" && apt-get download mayavi2 >/dev/null 2>&1); then
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
    $SUDO apt-get update -qq && (cd "$tmp" && apt-get download mayavi2 >/dev/null 2>&1)
  fi
  dpkg-deb --fsys-tarfile "$tmp"/mayavi2_*.deb | tar -x -C "$tmp" --wildcards '*/examples/mayavi/data/heart.vti'
  cp "$tmp"/usr/share/doc/mayavi2/examples/mayavi/data/heart.vti build/data/heart.vti
  rm -rf "$tmp"
fi
# pyvista's frog tissue label map (500x470x136 uint8, labels 0-29): taken out of the wheel,
# not installed.
if [ ! -f build/data/frog_tissues.vti ]; then
  tmp=$(mktemp -d)
  if python3 -m pip download --quiet --no-deps --dest "$tmp" pyvista==0.49.2 >/dev/null 2>&1; then
    (cd "$tmp" && python3 -m zipfile -e pyvista-*.whl extracted >/dev/null)
    cp "$tmp"/extracted/pyvista/examples/frog_tissues.vti build/data/frog_tissues.vti
  else
    echo "fetch-data: pip could not download pyvista: no build/data/frog_tissues.vti" >&2
  fi
  rm -rf "$tmp"
fi
ls -la build/data
