#!/usr/bin/env bash
# Runs a test command; if it failed because the X server refused a connection (on these
# machines XOpenDisplay fails now and then, ~2% of calls under load, and VTK then aborts
# the process: "bad X server connection"), runs it again, at most twice more. Any other
# failure is reported as is.
out=$(mktemp)
trap 'rm -f "$out"' EXIT
for attempt in 1 2 3; do
  "$@" 2>&1 | tee "$out"
  rc=${PIPESTATUS[0]}
  if [ "$rc" -eq 0 ] || ! grep -q "bad X server connection" "$out"; then
    exit "$rc"
  fi
  echo "retry-on-x-failure: the X server refused a connection (attempt $attempt); running again" >&2
done
exit "$rc"
