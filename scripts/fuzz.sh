#!/usr/bin/env bash
# Fuzzing of ferrovol-io's readers with AFL++ (docs/FUZZING.md).
#   scripts/fuzz.sh build                 build the targets (fuzz/) with coverage
#   scripts/fuzz.sh run TARGET [SECONDS]  fuzz TARGET into build/fuzz/TARGET, resuming
#                                         what is there; until stopped, or SECONDS
#   scripts/fuzz.sh smoke [SECONDS]       every target on its committed corpus for
#                                         SECONDS (default 20) each; fails on a crash or hang
#   scripts/fuzz.sh stats                 executions, paths and findings per target
# Targets: vti vtu nifti metaimage nrrd transfer. A finding replays with the target's binary:
#   $CARGO_TARGET_DIR/fuzz/release/TARGET build/fuzz/TARGET/default/crashes/id:...
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
TARGETS=(vti vtu nifti metaimage nrrd transfer)
# Its own target folder: the coverage flags would otherwise rebuild the main workspace's.
FUZZ_TARGET=${CARGO_TARGET_DIR:-$ROOT/target}/fuzz
BIN=$FUZZ_TARGET/release
AFL_RT=/usr/lib/afl/afl-compiler-rt.o
OUT=$ROOT/build/fuzz

# afl-fuzz in a container or on a shared machine: no CPU frequency governor to check, a
# core_pattern it cannot change, no core of its own to bind to.
export AFL_SKIP_CPUFREQ=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 AFL_NO_AFFINITY=1

build() {
  [ -f "$AFL_RT" ] || { echo "fuzz: $AFL_RT is missing; install afl++ (scripts/install-deps.sh)" >&2; exit 1; }
  # rustc's own SanitizerCoverage (stable flags, rustc's LLVM) with trace-pc-guard
  # callbacks and compare tracing, which AFL++'s runtime implements; the runtime object
  # is linked as is.
  local flags=(
    -C passes=sancov-module
    -C llvm-args=-sanitizer-coverage-level=3
    -C llvm-args=-sanitizer-coverage-trace-pc-guard
    -C llvm-args=-sanitizer-coverage-prune-blocks=0
    -C llvm-args=-sanitizer-coverage-trace-compares
    -C link-arg="$AFL_RT"
  )
  # Under make (fuzz-smoke is one of the Makefile's LINTED targets), clippy-driver compiles
  # the fuzz targets themselves, lints denied, so this build is also their lint.
  CARGO_TARGET_DIR=$FUZZ_TARGET RUSTFLAGS="${flags[*]}" \
    cargo build --release --locked --manifest-path "$ROOT/fuzz/Cargo.toml"
}

known() {
  [[ " ${TARGETS[*]} " == *" $1 "* ]] || { echo "fuzz: unknown target '$1'; targets: ${TARGETS[*]}" >&2; exit 1; }
}

# afl-fuzz TARGET OUTDIR [afl-fuzz options…]: the target's corpus, dictionary and binary.
# -t 5000: an input that runs 5 s is a hang (the corpus runs in well under a millisecond
# each). The binary itself is the CmpLog binary (-c 0): its compare tracing feeds
# AFL++'s input-to-state stage.
# The MetaImage and NRRD targets write the files they read back into $TMPDIR, which also
# marks this run's processes: afl-fuzz 4.04c leaves the CmpLog fork server's last child
# stopped when it exits (holding the output folder's lock), so those are ended after it.
fuzz() {
  local t=$1 out=$2 rc=0 env pid
  shift 2
  rm -rf "$out.tmp"
  mkdir -p "$out.tmp"
  TMPDIR=$out.tmp nice -n 10 afl-fuzz -i "$ROOT/fuzz/corpus/$t" -o "$out" -x "$ROOT/fuzz/dict/$t.dict" \
    -t 5000 -c 0 "$@" -- "$BIN/$t" || rc=$?
  for env in /proc/[0-9]*/environ; do
    pid=${env#/proc/}
    pid=${pid%/environ}
    if grep -qzxF "TMPDIR=$out.tmp" "$env" 2>/dev/null; then
      kill -KILL "$pid" 2>/dev/null || true
    fi
  done
  return $rc
}

findings() {  # findings OUTDIR: crashes and hangs saved there
  find "$1"/default/crashes "$1"/default/hangs -type f -name 'id:*' 2>/dev/null | wc -l
}

case "${1:-}" in
  build) build ;;
  run)
    known "${2:?scripts/fuzz.sh run TARGET [SECONDS]}"
    build
    mkdir -p "$OUT"
    limit=()
    [ -n "${3:-}" ] && limit=(-V "$3")
    AFL_AUTORESUME=1 fuzz "$2" "$OUT/$2" "${limit[@]}"
    ;;
  smoke)
    seconds=${2:-20}
    build
    tmp=$(mktemp -d)
    trap 'rm -rf "$tmp"' EXIT
    failed=0
    for t in "${TARGETS[@]}"; do
      # The corpus must replay without a finding before fuzzing starts from it.
      TMPDIR=$tmp "$BIN/$t" "$ROOT"/fuzz/corpus/"$t"/* >/dev/null
      AFL_NO_UI=1 AFL_FAST_CAL=1 fuzz "$t" "$tmp/$t" -V "$seconds" >"$tmp/$t.log" 2>&1 || {
        tail -20 "$tmp/$t.log" >&2
        echo "fuzz-smoke: afl-fuzz failed on $t" >&2
        exit 1
      }
      n=$(findings "$tmp/$t")
      execs=$(sed -n 's/^execs_done *: //p' "$tmp/$t/default/fuzzer_stats")
      echo "fuzz-smoke: $t: $execs executions in ${seconds} s, $n crashes or hangs"
      if [ "$n" -gt 0 ]; then
        failed=1
        mkdir -p "$OUT/smoke-findings/$t"
        cp "$tmp/$t"/default/crashes/id:* "$tmp/$t"/default/hangs/id:* "$OUT/smoke-findings/$t/" 2>/dev/null || true
        echo "fuzz-smoke: $t: inputs in $OUT/smoke-findings/$t; replay: $BIN/$t FILE" >&2
      fi
    done
    exit $failed
    ;;
  stats)
    for t in "${TARGETS[@]}"; do
      s=$OUT/$t/default/fuzzer_stats
      [ -f "$s" ] || { echo "$t: not run (scripts/fuzz.sh run $t)"; continue; }
      get() { sed -n "s/^$1 *: //p" "$s"; }
      echo "$t: $(get execs_done) executions, $(get corpus_count) inputs in the queue," \
        "$(get saved_crashes) crashes, $(get saved_hangs) hangs, run time $(get run_time) s"
    done
    ;;
  *) sed -n '2,10p' "$0" >&2; exit 2 ;;
esac
