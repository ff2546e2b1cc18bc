#!/usr/bin/env bash
# `make test`: every check CI runs, timed suite by suite (README.md, "Tests").
#
# First the builds, one after another, each using both cores (cargo, ninja -j2; the Rust
# test build is also clippy's lint, Makefile: LINTED), with the downloads beside them (the
# real volumes, pip VTK's SDK). Then the
# suites in two lanes side by side: most of a suite's time is one process (a Python or
# pvbatch test, afl-fuzz, valgrind), so two lanes keep both cores busy. Last, alone, the
# tests that time renders. Each suite's output
# goes to build/test-logs/NAME.log and is printed whole when the suite ends, under a line
# with its wall and CPU time; a suite whose build failed is not run. The last line counts them.
#
#   scripts/test.sh            everything (what `make test` runs)
#   scripts/test.sh NAME...    only those suites (and the builds they need)
set -uo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
LOGS=$ROOT/build/test-logs
mkdir -p "$LOGS"
rm -f "$LOGS"/*.log "$LOGS"/*.status "$LOGS"/*.seconds "$LOGS"/*.cpu
MAKE=${MAKE:-make}
START=$SECONDS
# Mesa's shader cache and ferrovol's pipeline cache in this tree: what the first suites
# compile, the later ones reuse, and a fresh clone starts cold whatever this machine ran
# before.
export MESA_SHADER_CACHE_DIR=$ROOT/build/mesa-shader-cache
export FERROVOL_CACHE_DIR=$ROOT/build/ferrovol-cache

# The suites, in the order their results are listed; build-* suites are builds.
SUITES=(data vtk-sdk lint build-rust build-vtk
        rust-tests crates sanitize fuzz-smoke build-paraview paraview
        vtk build-vtk-asan vtk-asan regression-quick build-vtk-pip regression-quick-pip wheel
        vtk-pip timing)
# What each suite needs to have passed first.
declare -A NEEDS=(
  [build-vtk]=build-rust
  [rust-tests]=build-rust [sanitize]=build-rust
  [build-paraview]=build-rust [paraview]=build-paraview
  [vtk]=build-vtk [build-vtk-asan]=build-rust [vtk-asan]=build-vtk-asan
  [regression-quick]=build-vtk
  [build-vtk-pip]="build-rust vtk-sdk" [vtk-pip]=build-vtk-pip [regression-quick-pip]=build-vtk-pip
  [wheel]=build-vtk-pip
  [timing]="build-vtk build-vtk-pip"
)
# What each suite runs: a make target (Makefile), without the builds it depends on.
declare -A CMD=(
  [data]=test-data
  [vtk-sdk]=test-vtk-sdk
  [lint]=lint-static
  [crates]=test-crates
  [build-rust]=test-build-rust
  [build-vtk]=test-build-vtk
  [rust-tests]=test-rust
  [sanitize]=test-sanitize
  [fuzz-smoke]=fuzz-smoke
  [build-paraview]=test-build-paraview
  [paraview]=test-paraview
  [vtk]=test-vtk
  [build-vtk-asan]=test-build-vtk-asan
  [vtk-asan]=test-vtk-asan
  [regression-quick]=test-regression-quick
  [build-vtk-pip]=test-build-vtk-pip
  [vtk-pip]=test-vtk-pip
  [regression-quick-pip]=test-regression-quick-pip
  [wheel]=test-wheel
  [timing]=test-timing
)

declare -A WANTED=()
if [ $# -gt 0 ]; then
  add() {
    [ -n "${CMD[$1]:-}" ] || { echo "test.sh: unknown suite '$1'; suites: ${SUITES[*]}" >&2; exit 2; }
    WANTED[$1]=1
    local d
    for d in ${NEEDS[$1]:-}; do add "$d"; done
    # The suites after the Rust build read the real volumes (those without them skip).
    [ "$1" != build-rust ] || WANTED[data]=1
  }
  for s in "$@"; do add "$s"; done
else
  for s in "${SUITES[@]}"; do WANTED[$s]=1; done
fi

# suite NAME: runs it unless unwanted; its result goes to NAME.status (ok, FAILED, skipped).
suite() {
  local name=$1 log=$LOGS/$1.log t0=$SECONDS rc=0 d
  [ -n "${WANTED[$name]:-}" ] || return 0
  for d in ${NEEDS[$name]:-}; do
    if [ "$(cat "$LOGS/$d.status" 2>/dev/null)" != ok ]; then
      echo skipped >"$LOGS/$name.status"
      report "$name" "skipped ($d did not pass)" ""
      return 0
    fi
  done
  # The subshell's `times` (a builtin: in a pipe or $(...) it would run in a new process,
  # which has waited for nothing): the CPU time, user and system, of make and all it waited
  # for.
  (
    $MAKE --no-print-directory "${CMD[$name]}" >"$log" 2>&1 </dev/null
    r=$?
    times >"$LOGS/$name.cpu"
    awk 'NR == 2 { t = 0; for (i = 1; i <= 2; i++) { split($i, a, /[ms]/); t += a[1] * 60 + a[2] }; printf "%d\n", t }' \
      "$LOGS/$name.cpu" >"$LOGS/$name.cpu.tmp" && mv "$LOGS/$name.cpu.tmp" "$LOGS/$name.cpu"
    exit $r
  ) || rc=$?
  local took=$((SECONDS - t0)) cpu
  cpu=$(cat "$LOGS/$name.cpu")
  if [ $rc -eq 0 ]; then
    echo ok >"$LOGS/$name.status"
    report "$name" "ok in ${took} s, CPU ${cpu} s" "$log"
  else
    echo FAILED >"$LOGS/$name.status"
    report "$name" "FAILED (exit $rc) after ${took} s; log: build/test-logs/$name.log" "$log"
  fi
  echo "$took" >"$LOGS/$name.seconds"
}

# report NAME RESULT LOG: the suite's log then its result line, printed in one piece even
# when the other lane finishes at the same moment.
report() {
  {
    flock 9
    if [ -n "$3" ]; then
      printf '\n======== %s\n' "$1"
      cat "$3"
    fi
    printf -- '-------- %s: %s (at %d s)\n' "$1" "$2" $((SECONDS - START))
  } 9>"$LOGS/.print.lock"
}

echo "make test: logs in build/test-logs; the builds first, then two lanes of suites"
# The real volumes and pip VTK's SDK are mostly downloads: they go on beside the builds.
suite data &
data=$!
suite vtk-sdk &
sdk=$!
suite lint
suite build-rust
suite build-vtk
wait $data $sdk
# Lane 1: the Rust tests, the crates' documentation and packages, the C ABI under
# sanitizers, fuzzing (its build is the fuzz targets' lint), the ParaView plugin.
(
  suite rust-tests
  suite crates
  suite sanitize
  suite fuzz-smoke
  suite build-paraview
  suite paraview
) &
lane1=$!
# Lane 2: the VTK module's suite, its ASan build and suite, the quick regression, the
# module built against PyPI's VTK (its SDK fetched beside the builds) and its quick
# regression, the wheel in a new venv, its suites on pip's VTK (the lanes' lengths
# balanced by the suites' times).
(
  suite vtk
  suite build-vtk-asan
  suite vtk-asan
  suite regression-quick
  suite build-vtk-pip
  suite regression-quick-pip
  suite wheel
  suite vtk-pip
) &
lane2=$!
wait $lane1 $lane2
# Last, alone: the tests that time renders (their bounds are for a machine not building).
suite timing

passed=0 failed=0 total_cpu=0 names=()
echo
echo "make test: wall and CPU time (user + system) per suite"
for s in "${SUITES[@]}"; do
  [ -n "${WANTED[$s]:-}" ] || continue
  st=$(cat "$LOGS/$s.status" 2>/dev/null || echo "not run")
  secs=$(cat "$LOGS/$s.seconds" 2>/dev/null || echo -)
  cpu=$(cat "$LOGS/$s.cpu" 2>/dev/null || echo -)
  [ "$cpu" = - ] || total_cpu=$((total_cpu + cpu))
  printf '  %-20s %-8s %6s s %8s s CPU\n' "$s" "$st" "$secs" "$cpu"
  if [ "$st" = ok ]; then passed=$((passed + 1)); else failed=$((failed + 1)); names+=("$s"); fi
done
total=$((SECONDS - START))
printf '  %-20s %-8s %6s s %8s s CPU (%d min %02d s)\n' total "" "$total" "$total_cpu" \
  $((total / 60)) $((total % 60))
[ $failed -eq 0 ] || echo "make test: not passed: ${names[*]}"
echo "suites: $passed passed, $failed failed"
[ $failed -eq 0 ]
