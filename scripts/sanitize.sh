#!/usr/bin/env bash
# The C ABI's test programs (ffi/tests/c) under sanitizers and valgrind (`make sanitize`,
# docs/RELIABILITY.md):
#   asan      render_demo.c, raii_demo.cpp, thread_stress.c and shared_gl.c built with
#             -fsanitize=address,undefined (LeakSanitizer on), run to a clean exit
#   tsan      thread_stress.c built with -fsanitize=thread, 4 threads x 64 frames
#   valgrind  render_demo.c (32x32 image of an 8^3 volume) under memcheck, leaks included
# Usage: scripts/sanitize.sh [asan|tsan|valgrind]...   (all three without arguments)
# libferrovol.so is the test build (`cargo build --workspace --all-targets`, as `make test`
# builds it, with the tests' features, so that nothing is compiled twice): Rust code is not
# instrumented (stable rustc has no -Zsanitizer); ASan/LSan still replace the allocator
# the Rust side uses, so leaked handles and heap misuse from C are seen.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
LIB="${CARGO_TARGET_DIR:-$ROOT/target}/debug"
OUT=$ROOT/build/sanitize
SRC=$ROOT/ffi/tests/c
SUPP=$ROOT/ffi/tests/sanitize
mkdir -p "$OUT"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp/ferrovol-xdg-$(id -u)}"
mkdir -p -m 700 "$XDG_RUNTIME_DIR"

# Mesa's drivers (lavapipe for Vulkan, Mesa's EGL/llvmpipe for GL) on every machine, GPU
# or not: the suppressions and results hold for them, and a GPU driver's own leaks or
# uninitialised reads are not ferrovol's. Set VK_DRIVER_FILES / __EGL_VENDOR_LIBRARY_FILENAMES
# to check another driver.
export VK_DRIVER_FILES="${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}"
export __EGL_VENDOR_LIBRARY_FILENAMES="${__EGL_VENDOR_LIBRARY_FILENAMES:-/usr/share/glvnd/egl_vendor.d/50_mesa.json}"

${CARGO:-cargo} build --locked --workspace --all-targets
[ -f "$LIB/libferrovol.so" ] || { echo "sanitize: $LIB/libferrovol.so is missing" >&2; exit 1; }

WARN=(-Wall -Wextra -Werror -pedantic -g -O1 -fno-omit-frame-pointer -I "$ROOT/ffi/include")
LINK=(-L"$LIB" -lferrovol -Wl,-rpath,"$LIB")

# compile NAME COMPILER STD SANITIZER-FLAGS... -- EXTRA-LIBS...
compile() {
  local name=$1 cc=$2 std=$3
  shift 3
  local flags=() libs=()
  while [ $# -gt 0 ] && [ "$1" != -- ]; do flags+=("$1"); shift; done
  [ $# -gt 0 ] && shift
  libs=("$@")
  "$cc" -std="$std" "${WARN[@]}" "${flags[@]}" "$SRC/$name" -o "$OUT/${name%.*}${TAG}" \
    "${LINK[@]}" "${libs[@]}"
}

# run LABEL COMMAND...: runs it with its output in build/sanitize/LABEL.log; fails on a
# non-zero exit, printing the log's end. Exit 77 (shared_gl: no GL interop here) is a skip.
run() {
  local label=$1
  shift
  local start=$SECONDS code=0
  "$@" >"$OUT/$label.log" 2>&1 || code=$?
  if [ "$code" -eq 77 ]; then
    echo "sanitize: $label skipped: no EGL/GL interop on this machine (exit 77)"
    return 0
  fi
  if [ "$code" -ne 0 ]; then
    tail -n 60 "$OUT/$label.log" >&2
    echo "sanitize: $label FAILED (exit $code), log: $OUT/$label.log" >&2
    exit 1
  fi
  echo "sanitize: $label clean in $((SECONDS - start)) s ($(tail -n 1 "$OUT/$label.log"))"
}

asan() {
  local TAG=-asan
  local san=(-fsanitize=address,undefined -fno-sanitize-recover=all)
  compile render_demo.c cc c11 "${san[@]}" -- -lm
  compile raii_demo.cpp c++ c++17 "${san[@]}"
  compile thread_stress.c cc c11 "${san[@]}" -pthread
  compile shared_gl.c cc c11 "${san[@]}" -- -lEGL -lGL
  export ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:detect_stack_use_after_return=1:strict_string_checks=1:check_initialization_order=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  # The Vulkan loader dlcloses the driver at exit, before LeakSanitizer scans: what the
  # driver still holds in its globals (LLVM's caches) then has no root and reads as a leak
  # from "<unknown module>". Preloading the driver keeps it mapped, so LSan sees those roots
  # and names its frames; the ASan runtime has to come first in the preload list.
  local driver
  driver=$(sed -n 's/.*"library_path": *"\([^"]*\)".*/\1/p' "$VK_DRIVER_FILES")
  [ -n "$driver" ] || { echo "sanitize: no library_path in $VK_DRIVER_FILES" >&2; exit 1; }
  export LD_PRELOAD="$(cc -print-file-name=libasan.so) $driver"
  run render_demo-asan "$OUT/render_demo-asan" "$OUT/render_demo-asan.png"
  run raii_demo-asan "$OUT/raii_demo-asan" "$OUT/raii_demo-asan.png"
  run thread_stress-asan "$OUT/thread_stress-asan" 32
  run shared_gl-asan "$OUT/shared_gl-asan"
  unset ASAN_OPTIONS UBSAN_OPTIONS LD_PRELOAD
}

# ThreadSanitizer sees the C program's own memory accesses and every pthread call; the
# Rust library, Mesa and LLVM are not instrumented, so their accesses are invisible and
# their lock-free or futex-based synchronisation (parking_lot, Mesa's simple_mtx) is too.
# ignore_noninstrumented_modules=1 therefore keeps TSan from judging the allocator calls
# made from those libraries (it would report malloc/free pairs ordered by locks it cannot
# see) and leaves it checking the test program itself.
tsan() {
  local TAG=-tsan
  compile thread_stress.c cc c11 -fsanitize=thread -pthread
  TSAN_OPTIONS=halt_on_error=1:ignore_noninstrumented_modules=1:second_deadlock_stack=1 \
    run thread_stress-tsan "$OUT/thread_stress-tsan" 64
}

# Memcheck at a tiny size (valgrind emulates every instruction of lavapipe's shaders);
# Mesa's shader cache is off so that shader compilation runs under memcheck every time.
valgrind_demo() {
  command -v valgrind >/dev/null || { echo "sanitize: valgrind is missing (scripts/install-deps.sh installs it)" >&2; exit 1; }
  local TAG=-plain
  compile render_demo.c cc c11 -- -lm
  MESA_SHADER_CACHE_DISABLE=true run render_demo-valgrind valgrind --tool=memcheck \
    --leak-check=full --show-leak-kinds=definite,indirect,possible \
    --errors-for-leak-kinds=definite,indirect,possible --error-exitcode=99 \
    --num-callers=40 --suppressions="$SUPP/valgrind.supp" \
    "$OUT/render_demo-plain" "$OUT/render_demo-valgrind.png" 32 8
  grep -E "ERROR SUMMARY|definitely lost|possibly lost|suppressed:" "$OUT/render_demo-valgrind.log" |
    sed 's/^==[0-9]*== */  valgrind: /'
}

steps=("$@")
[ ${#steps[@]} -gt 0 ] || steps=(asan tsan valgrind)
for step in "${steps[@]}"; do
  case $step in
    asan) asan ;;
    tsan) tsan ;;
    valgrind) valgrind_demo ;;
    *) echo "usage: $0 [asan|tsan|valgrind]..." >&2; exit 2 ;;
  esac
done
