#!/usr/bin/env bash
# The figures a real GPU gives: one prepared run of the release `ferrovol` command on a GPU
# machine that has neither Rust nor VTK (the README's GPU table and docs/PERFORMANCE.md take
# its output). Two steps:
#
#   scripts/gpu-check.sh prepare      here: build the release command and copy it, with the
#                                     Vulkan loader's Debian packages, into .gpu/ (.gitignore;
#                                     carry it to the GPU machine)
#   scripts/gpu-check.sh run OUT      there (or here, on lavapipe, as a check): unpack the
#                                     loader if the machine has none, then write ferrovol
#                                     info, every figure and the last frames into OUT
#
# `run --quick OUT` uses small sizes, for a CPU device. Figures: ms per frame (the first
# frame, which builds pipelines and tables, is not counted) of VTK's benchmark scene (wavelet
# 256³, 900²) unshaded and shaded; a 1024³ uint16 wavelet (2 GiB) streamed through memory
# budgets, with the bricks uploaded per frame along a camera orbit; composite with and without
# pre-integrated classification; isosurfaces; path tracing.
set -euo pipefail
cd "$(dirname "$0")/.."

prepare() {
    cargo build --release --locked -p ferrovol-cli
    mkdir -p .gpu/deb
    cp target/release/ferrovol .gpu/ferrovol
    local lists=/tmp/ferrovol-apt-amd64
    mkdir -p "$lists/partial"
    local o=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 "-oDir::State::Lists=$lists")
    apt-get "${o[@]}" update >/dev/null
    (cd .gpu/deb && apt-get "${o[@]}" download libvulkan1 >/dev/null)
    ls -l .gpu .gpu/deb
}

run() {
    local quick=0
    if [ "${1:-}" = "--quick" ]; then
        quick=1
        shift
    fi
    local out=${1:?usage: scripts/gpu-check.sh run [--quick] OUT}
    mkdir -p "$out"
    local fv=.gpu/ferrovol
    if [ ! -x "$fv" ] || [ target/release/ferrovol -nt "$fv" ]; then
        fv=target/release/ferrovol
    fi
    if ! ldconfig -p | grep -q libvulkan.so.1 && [ -d .gpu/deb ]; then
        for f in .gpu/deb/*.deb; do dpkg -x "$f" /; done
        ldconfig
    fi
    if [ -d /usr/local/nvidia/share/vulkan/icd.d ] && [ -z "${VK_DRIVER_FILES:-}" ]; then
        export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
    fi
    local log=$out/gpu-check.log
    : >"$log"
    step() { # step NAME ARGS...: runs ferrovol ARGS, keeping its output in the log
        local name=$1
        shift
        echo "== $name: ferrovol $*" | tee -a "$log"
        "$fv" "$@" 2>&1 | tee -a "$log" | grep -E 'ms/frame|frame|MiB|paths' || true
    }
    "$fv" info 2>&1 | tee "$out/info.txt" | tee -a "$log"
    local frames=20 big=1024 budgets="512 1024" spp=64 size=900x900 render=1024x1024
    if [ $quick = 1 ]; then
        frames=3 big=192 budgets="4 8" spp=4 size=300x300 render=256x256
    fi
    if [ $quick = 1 ]; then
        step bench bench --frames "$frames" --size "$size" --extent 63 --png-dir "$out"
    else
        step bench bench --frames "$frames" --size "$size" --png-dir "$out"
    fi
    local repeat=$((frames / 2 + 2))
    for mib in $budgets; do
        step "streamed $big³ uint16, budget $mib MiB" render --demo-size "$big" \
            --demo-type uint16 --gpu-memory "$mib" --size "$render" --zoom 1.5 \
            --repeat "$repeat" --orbit 2 -o "$out/streamed-$mib.png"
    done
    step "in core $big³ uint16" render --demo-size "$big" --demo-type uint16 --size "$render" \
        --zoom 1.5 --repeat "$repeat" --orbit 2 -o "$out/in-core.png"
    for rule in "" --preintegration --midpoint --adaptive; do
        step "wavelet 256³ composite ${rule:-sampled}" render --demo-size 256 $rule \
            --size "$render" --repeat "$repeat" -o "$out/composite${rule:+-${rule#--}}.png"
    done
    step isosurfaces render --demo-size 256 --mode iso --iso 180 --size "$render" \
        --repeat "$repeat" -o "$out/iso.png"
    step "path tracing, $spp paths per pixel" render --demo-size 256 --mode pathtrace \
        --spp "$spp" --size "$render" --repeat 3 -o "$out/pathtrace.png"
    echo "figures: $log"
}

case "${1:-}" in
    prepare) prepare ;;
    run) shift; run "$@" ;;
    *) echo "usage: scripts/gpu-check.sh prepare | run [--quick] OUT" >&2; exit 2 ;;
esac
