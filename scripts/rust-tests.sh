#!/usr/bin/env bash
# The Rust tests of the workspace, as `cargo test --workspace` runs them, but the test
# binaries side by side (JOBS at a time, 2 by default): each binary's tests take turns on
# one renderer, so one binary keeps about one core busy. Every binary runs in its package's
# folder, as cargo runs it; its output is printed whole when it ends, with its wall time.
# The slowest binaries of the last run (target/rust-tests.seconds; on a fresh tree
# scripts/rust-tests.seconds, a make test run's figures) start first. Then the doc tests.
# Extra arguments go to every test binary (a filter, --nocapture...).
#   scripts/rust-tests.sh [TEST ARGUMENTS...]        (`make check`, `make test`)
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS=${JOBS:-2}
CARGO=${CARGO:-cargo}
SECONDS_FILE=${CARGO_TARGET_DIR:-target}/rust-tests.seconds
ORDER_FILE=$SECONDS_FILE
[ -f "$ORDER_FILE" ] || ORDER_FILE=scripts/rust-tests.seconds
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The binaries cargo test would run: their paths and package folders, from cargo's own
# build messages (the build is the one `cargo build --workspace --all-targets` makes).
$CARGO test --locked --workspace --no-run --message-format=json-render-diagnostics \
  >"$tmp/build.json"
python3 - "$tmp/build.json" "$ORDER_FILE" >"$tmp/binaries" <<'EOF'
import json, os, sys
took = {}
if os.path.exists(sys.argv[2]):
    for line in open(sys.argv[2]):
        label, _, secs = line.rstrip("\n").rpartition("\t")
        took[label] = float(secs)
rows = []
for line in open(sys.argv[1]):
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("profile", {}).get("test") \
            and m.get("executable"):
        t = m["target"]
        folder = os.path.dirname(m["manifest_path"])
        rows.append((m["executable"], folder, "%s/%s" % (os.path.basename(folder), t["name"])))
# unknown binaries (new, or no earlier run) first, then the slowest
rows.sort(key=lambda r: -took.get(r[2], float("inf")))
for r in rows:
    print("\t".join(r))
EOF

# run_one EXECUTABLE DIR LABEL ARGS...: one binary; its output and result kept in $tmp.
run_one() {
  local exe=$1 dir=$2 label=$3 log t0 took rc=0
  shift 3
  log="$tmp/$(basename "$exe").log"
  t0=$(date +%s.%N)
  (cd "$dir" && "$exe" "$@") >"$log" 2>&1 || rc=$?
  took=$(awk "BEGIN { printf \"%.1f\", $(date +%s.%N) - $t0 }")
  {
    flock 9
    printf '\n==== %s\n' "$label"
    cat "$log"
    printf -- '---- %s: %s in %s s\n' "$label" "$([ $rc -eq 0 ] && echo ok || echo "FAILED (exit $rc)")" "$took"
    printf '%s\t%s\n' "$label" "$took" >>"$tmp/seconds"
  } 9>"$tmp/print.lock"
  [ $rc -eq 0 ] || echo "$label" >>"$tmp/failed"
}
export -f run_one
export tmp

# The binaries, slowest of the last run first, JOBS at a time.
tr '\n' '\0' <"$tmp/binaries" |
  xargs -0 -P "$JOBS" -I{} bash -c 'IFS=$'"'\t'"' read -r exe dir label <<<"$1"; shift; run_one "$exe" "$dir" "$label" "$@"' _ {} "$@"

$CARGO test --locked --workspace --doc -- "$@"
[ $# -gt 0 ] || cp "$tmp/seconds" "$SECONDS_FILE"

if [ -s "$tmp/failed" ]; then
  echo "rust-tests: failed: $(tr '\n' ' ' <"$tmp/failed")" >&2
  exit 1
fi
echo "rust-tests: $(wc -l <"$tmp/binaries") test binaries and the doc tests passed"
