#!/usr/bin/env bash
# Runs a command with an X display for VTK/ParaView: the caller's DISPLAY if it works,
# otherwise a private Xvfb started here and stopped afterwards.
set -euo pipefail
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/ferrovol-xdg-$(id -u)}"
mkdir -p -m 700 "$XDG_RUNTIME_DIR"
if [ -n "${DISPLAY:-}" ] && [ -e "/tmp/.X11-unix/X${DISPLAY#*:}" ]; then
  exec "$@"
fi
for n in $(seq 90 140); do
  [ -e "/tmp/.X${n}-lock" ] || [ -e "/tmp/.X11-unix/X${n}" ] || { disp=$n; break; }
done
Xvfb ":${disp}" -screen 0 1920x1080x24 -nolisten tcp >/dev/null 2>&1 &
xpid=$!
trap 'kill $xpid 2>/dev/null || true' EXIT
for _ in $(seq 50); do [ -e "/tmp/.X11-unix/X${disp}" ] && break; sleep 0.1; done
DISPLAY=":${disp}" "$@"
