#!/usr/bin/env bash
# Runs a command with an X display for VTK/ParaView: the caller's DISPLAY if it works,
# otherwise a private Xvfb started here and stopped afterwards. Xvfb picks a free display
# number itself (-displayfd), so several of these can start at the same moment.
set -euo pipefail
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/ferrovol-xdg-$(id -u)}"
mkdir -p -m 700 "$XDG_RUNTIME_DIR"
if [ -n "${DISPLAY:-}" ] && [ -e "/tmp/.X11-unix/X${DISPLAY#*:}" ]; then
  exec "$@"
fi
fifo=$(mktemp -u)
mkfifo "$fifo"
Xvfb -displayfd 3 -screen 0 1920x1080x24 -nolisten tcp 3>"$fifo" >/dev/null 2>&1 &
xpid=$!
trap 'kill $xpid 2>/dev/null || true; rm -f "$fifo"' EXIT
disp=
read -r -t 20 disp <"$fifo" || true
[ -n "$disp" ] || { echo "with-xvfb: Xvfb did not start" >&2; exit 1; }
DISPLAY=":${disp}" "$@"
