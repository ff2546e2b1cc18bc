# ferrovol — GPU volume ray casting on wgpu.
#   make demo   render the built-in demo volume to build/demo.png
#   make test   everything CI runs (installs what is missing first): lint, the builds, then
#               every suite in two lanes, each suite's wall time and a total (scripts/test.sh)
#   make check  for contributors: rustfmt, clippy and the Rust tests (a few minutes when warm)
#   make bench  VTK's GPU ray cast benchmark scene, ferrovol vs vtkGPUVolumeRayCastMapper,
#               then the equal-fidelity table (time and error against converged references)
#   make bench-vtk  the same scene in a VTK window: vtkFerroVolumeMapper vs vtkGPUVolumeRayCastMapper,
#               and the equal-fidelity table (time and error against converged references)
#   make build  release build of the `ferrovol` command and the VTK module (make vtk)
#   make vtk    vtkFerroVolumeMapper (C++ + Python package `ferrovol`) in build/vtk;
#               writes build/env.sh: `. build/env.sh; /usr/bin/python3 -c "import vtk, ferrovol"`
#   make vtk-test  the VTK module's tests (CTest: C++ and Python) under Xvfb
#   make paraview  the ParaView plugin (representation "Ferrovol Volume") in build/paraview;
#               `. build/env.sh && pvpython` then has it loaded (PV_PLUGIN_PATH)
#   make paraview-test  the plugin's pvbatch tests, serial and `mpiexec -n 2`, under Xvfb
#   make paraview-regression  the same with 4 MPI ranks
#   make regression  ferrovol against VTK's own volume rendering, scene by scene
#               (tests/regression/); report: build/regression/index.html; then the
#               ParaView tests with 4 MPI ranks
#   make regression-quick  the subset of it that `make test` runs
#   make fuzz-smoke  every fuzz target of the readers 20 s on its corpus (docs/FUZZING.md);
#               `make test` runs it
#   make soak   10 000 renders of vtkFerroVolumeMapper while everything changes: memory flat
#               (4 periods of 200 renders are in make vtk-test); plot: docs/img/soak-memory.svg
#   make sanitize  the C ABI's C/C++ test programs under ASan+UBSan+LSan and TSan, the C
#               demo under valgrind (docs/RELIABILITY.md); `make test` runs it
#   make vtk-asan  the VTK module built with ASan+UBSan (build/vtk-asan) and the tests of its
#               CTest suite that only ASan adds to (label asan); `make test` runs it
SHELL := /bin/bash
CARGO ?= cargo
export XDG_RUNTIME_DIR ?= /tmp/ferrovol-xdg-$(shell id -u)
FERROVOL := target/release/ferrovol

.PHONY: deps build demo test check lint lint-workspace lint-fuzz lint-publish bench bench-vtk pictures vtk vtk-test paraview paraview-test paraview-regression \
        regression regression-quick fuzz-smoke soak sanitize vtk-asan vtk-pip wheel \
        test-build-vtk-pip test-vtk-pip test-wheel test-regression-quick-pip test-build-rust test-rust test-sanitize test-build-vtk test-vtk test-build-vtk-asan \
        test-vtk-asan lint-static test-crates test-data test-vtk-sdk test-build-paraview test-paraview test-regression-quick

deps:
	@bash scripts/install-deps.sh
	@mkdir -p -m 700 $(XDG_RUNTIME_DIR) build

build: deps
	$(MAKE) vtk

# The C ABI library the VTK module and the ParaView plugin link. `make vtk` and `make
# paraview` link the release build; `make test` links the test build instead (target/debug:
# the crates as the Rust tests compile them, debug assertions on, with the test-only
# fv_test_panic export), so that one Rust build serves every suite. FFI_TEST builds the
# workspace's tests with it: the library alone (-p ferrovol-ffi) would resolve its
# dependencies' features without the tests' and compile them all a second time; for the
# same reason FFI_RELEASE builds the `ferrovol` command with the release library. `make
# vtk-asan` always uses the test build. VTK 9.2 is ParaView's (docs/ARCHITECTURE.md,
# Machines). 2 cores: -j2.
RELEASE_LIB := target/release/libferrovol.so
TEST_LIB := target/debug/libferrovol.so
FFI_RELEASE := $(CARGO) build --release --locked -p ferrovol-ffi -p ferrovol-cli
FFI_TEST := $(CARGO) build --locked --workspace --all-targets
# $(call cmake_build,SOURCE,BUILD-DIR,LIBRARY,EXTRA CMAKE ARGUMENTS)
cmake_build = cmake -G Ninja -S $(1) -B $(2) -DFERROVOL_LIBRARY=$(CURDIR)/$(3) $(4) >/dev/null && \
  ninja -C $(2) -j2

VTK_BUILD := build/vtk
define VTK_MODULE
$(call cmake_build,vtk_plugin,$(VTK_BUILD),$(1),-DPython3_EXECUTABLE=/usr/bin/python3)
cp $(VTK_BUILD)/env.sh build/env.sh
$(PV_ENV_HOOK)
endef
vtk: deps
	$(FFI_RELEASE)
	$(call VTK_MODULE,$(RELEASE_LIB))
	@echo "VTK module built: . build/env.sh && /usr/bin/python3 -c 'import vtk, ferrovol'"
test-build-vtk:
	$(call VTK_MODULE,$(TEST_LIB))

# C++ and Python tests of vtkFerroVolumeMapper in a private Xvfb (images and measured
# figures land in build/vtk/test-images).
VTK_CTEST = env -u DISPLAY scripts/with-xvfb.sh ctest --test-dir $(1) --output-on-failure -j1
vtk-test: vtk
	@scripts/fetch-data.sh >/dev/null || echo "vtk-test: no build/data/cranium.vti; the examples render a synthetic volume"
	$(call VTK_CTEST,$(VTK_BUILD))
test-vtk:
	$(call VTK_CTEST,$(VTK_BUILD)) -LE timing

# The VTK module, its wrapping, examples and C++ tests built with AddressSanitizer and UBSan
# (FERROVOL_SANITIZE, vtk_plugin/CMakeLists.txt), and the tests only ASan can add to
# `make vtk-test` run on them (the label `asan` in vtk_plugin/tests/CMakeLists.txt: the C++
# units, every C ABI call the mapper makes, resource release, bad input); the Python tests
# preload the runtimes.
VTK_ASAN_BUILD := build/vtk-asan
VTK_ASAN = $(call cmake_build,vtk_plugin,$(VTK_ASAN_BUILD),$(TEST_LIB),-DPython3_EXECUTABLE=/usr/bin/python3 -DFERROVOL_SANITIZE=ON)
VTK_ASAN_CTEST = $(call VTK_CTEST,$(VTK_ASAN_BUILD)) -L asan
vtk-asan: deps
	$(FFI_TEST)
	$(VTK_ASAN)
	$(VTK_ASAN_CTEST)
test-build-vtk-asan:
	$(VTK_ASAN)
test-vtk-asan:
	$(VTK_ASAN_CTEST)

# The VTK module against PyPI's `vtk` wheel (the version Debian unstable's VTK headers have):
# scripts/vtk-sdk.sh assembles the SDK (build/vtk-sdk: those headers and wrapping tools, a
# venv with that wheel, CMake from PyPI), then build/vtk-pip. `make wheel` packs it.
PIP_SDK := build/vtk-sdk/sdk.env
PIP_BUILD := build/vtk-pip
define VTK_PIP_MODULE
scripts/vtk-sdk.sh >/dev/null
. $(PIP_SDK) && $$FERROVOL_SDK_CMAKE -G Ninja -S vtk_plugin -B $(PIP_BUILD) \
  -DFERROVOL_LIBRARY=$(CURDIR)/$(1) -DFERROVOL_VTK_DIR=$$FERROVOL_SDK_VTK_DIR \
  -DPython3_EXECUTABLE=$$FERROVOL_SDK_PYTHON -DFERROVOL_VTK_WHEEL=ON >/dev/null && \
  ninja -C $(PIP_BUILD) -j2
endef
vtk-pip: deps
	$(FFI_RELEASE)
	$(call VTK_PIP_MODULE,$(RELEASE_LIB))
wheel: vtk-pip
	. $(PIP_SDK) && $$FERROVOL_SDK_PYTHON scripts/wheel.py $(PIP_BUILD) $(RELEASE_LIB) dist
test-vtk-sdk:
	scripts/vtk-sdk.sh
test-build-vtk-pip:
	$(call VTK_PIP_MODULE,$(TEST_LIB))
# The VTK module's suites on pip's VTK (CTest label pip): the comparisons with that VTK's own
# mapper, bad input and a short soak.
test-vtk-pip:
	$(call VTK_CTEST,$(PIP_BUILD)) -L pip
# The timed tests (CTest label timing: how long progressive renders take) on both VTKs; `make
# test` runs them last, alone, as CPU time taken by the other lane's builds is not theirs.
test-timing:
	$(call VTK_CTEST,$(VTK_BUILD)) -L timing
	$(call VTK_CTEST,$(PIP_BUILD)) -L timing
# The wheel as a pip user gets it: packed from build/vtk-pip, installed with PyPI's vtk and
# PyVista into a new venv, tested there (tests/wheel/run.sh).
test-wheel:
	tests/wheel/run.sh $(CURDIR)/$(TEST_LIB)

# The ParaView plugin builds vtkFerroVolumeMapper from vtk_plugin/FerroVolume itself (it
# does not need build/vtk) and writes build/paraview/env.sh (PV_PLUGIN_PATH); build/env.sh
# (written by `make vtk`, or created here) sources it.
PV_BUILD := build/paraview
# The line of build/env.sh that sources build/paraview/env.sh (if it exists); `make vtk`
# rewrites build/env.sh, so both targets add it.
define PV_ENV_HOOK
@touch build/env.sh
@grep -qF '$(PV_BUILD)/env.sh' build/env.sh || \
  echo 'if [ -f "$(CURDIR)/$(PV_BUILD)/env.sh" ]; then . "$(CURDIR)/$(PV_BUILD)/env.sh"; fi' >> build/env.sh
endef
define PV_PLUGIN
$(call cmake_build,paraview,$(PV_BUILD),$(1),-Wno-deprecated)
$(PV_ENV_HOOK)
endef
paraview: deps
	$(FFI_RELEASE)
	$(call PV_PLUGIN,$(RELEASE_LIB))
	@echo "ParaView plugin built: . build/env.sh && pvpython   (\"Ferrovol Volume\" is loaded)"
test-build-paraview:
	$(call PV_PLUGIN,$(TEST_LIB))

# pvbatch/pvpython/paraview tests in a private Xvfb (1920x1080 screen); build/data/cranium.vti
# is used when scripts/fetch-data.sh has made it (the cranium test says SKIP otherwise).
PV_TESTS = env -u DISPLAY scripts/with-xvfb.sh paraview/tests/run-all.sh $(1)
paraview-test: paraview
	$(call PV_TESTS,2)
test-paraview:
	$(call PV_TESTS,2)

paraview-regression: paraview
	$(call PV_TESTS,4)

demo: build
	$(FERROVOL) render --demo wavelet --shade --size 640x640 --azimuth 30 --elevation 20 --out build/demo.png
	@echo "demo image: $(CURDIR)/build/demo.png"

lint: deps lint-workspace lint-fuzz lint-publish
lint-workspace: lint-static
	$(CARGO) clippy --locked --workspace --all-targets -- -D warnings
	$(DOC)
# What needs no build: formatting (the workspace and the fuzz targets), the core's layers,
# file sizes, docs/ARCHITECTURE.md against the code.
lint-static:
	$(CARGO) fmt --all --check
	$(CARGO) fmt --manifest-path fuzz/Cargo.toml --check
	python3 scripts/check-core-layers.py
	python3 scripts/check-file-sizes.py
	python3 scripts/check-architecture-doc.py
DOC := RUSTDOCFLAGS="-D warnings" $(CARGO) doc --locked --no-deps -p ferrovol-core -p ferrovol-io -p ferrovol-ffi
# The fuzz targets are a workspace of their own (fuzz/Cargo.toml), checked in their own
# target folder (their formatting: lint-static).
lint-fuzz:
	$(CARGO) clippy --locked --manifest-path fuzz/Cargo.toml --all-targets -- -D warnings
# The library crates as crates.io would take them: packaged alone (the shaders inside
# ferrovol-core) and built from the package, in a target folder of their own. Cargo
# verifies ferrovol-io against the ferrovol-core it just packaged, through a local registry
# whose crates it takes as immutable: it reuses an unpacked copy, or a build, of a version
# it has seen (the same 0.2.0 with older code). Those copies and builds go first.
PUBLISH_TARGET := target/publish
lint-publish:
	rm -rf $${CARGO_HOME:-$$HOME/.cargo}/registry/src/-*/ferrovol-* \
	  $(PUBLISH_TARGET)/debug/deps/*ferrovol_* $(PUBLISH_TARGET)/debug/.fingerprint/ferrovol-*
	CARGO_TARGET_DIR=$(PUBLISH_TARGET) $(CARGO) publish --dry-run --locked --allow-dirty \
	  -p ferrovol-core -p ferrovol-io
# make test's share of the lint that needs the dependencies type-checked: the crates'
# documentation with rustdoc's warnings denied, then the packages type-checked rather than
# built (scripts/check-packages.sh), which finds the documentation's checks made.
test-crates:
	$(DOC)
	scripts/check-packages.sh

# The test build is also the workspace's clippy: clippy-driver, which `cargo clippy` runs in
# rustc's place for the workspace's own crates, compiles them with their lints denied and
# generates their code as rustc does (the dependencies are compiled by rustc as always), so
# `make test` and `make check` compile the crates once for both. The targets that build or
# run the test build all name it, since the setting is part of the artifacts' hashes; so
# does fuzz-smoke, whose build (scripts/fuzz.sh) is the fuzz targets' lint the same way.
LINTED := test-build-rust test-rust test-sanitize sanitize vtk-asan check fuzz-smoke
$(LINTED): export RUSTC_WORKSPACE_WRAPPER = $(shell command -v clippy-driver)
$(LINTED): export CLIPPY_ARGS = -D__CLIPPY_HACKERY__warnings__CLIPPY_HACKERY__

# Everything CI runs (scripts/test.sh: the builds, then the suites in two lanes, each
# suite's log in build/test-logs and its wall time; `scripts/test.sh NAME...` runs some).
test: deps
	@bash scripts/test.sh

# For contributors, before a commit: formatting, clippy and the Rust tests on lavapipe (the
# test binaries two at a time, scripts/rust-tests.sh).
check: deps
	$(CARGO) fmt --all --check
	$(FFI_TEST)
	scripts/rust-tests.sh

# The suites of `make test` one by one, without the builds they need (scripts/test.sh runs
# those first). The Rust tests' binaries and the test build of the C ABI library (the C ABI
# tests load and link target/debug/libferrovol.so, which `cargo test` alone does not build),
# and the real volumes of build/data (scripts/fetch-data.sh) for the suites after it.
test-data:
	@scripts/fetch-data.sh >/dev/null || echo "test-data: some of build/data is missing; those tests skip"
test-build-rust:
	$(FFI_TEST)
test-rust:
	scripts/rust-tests.sh
test-sanitize:
	scripts/sanitize.sh
test-regression-quick:
	$(REGRESSION) --quick
# The same scenes against pip's VTK (its own vtkGPUVolumeRayCastMapper is the reference).
REGRESSION_PIP = . $(PIP_SDK) && . $(PIP_BUILD)/env.sh && env -u DISPLAY scripts/with-xvfb.sh \
  vtk_plugin/tests/retry-on-x-failure.sh $$FERROVOL_SDK_PYTHON tests/regression/run.py \
  --out build/regression-pip
test-regression-quick-pip:
	$(REGRESSION_PIP) --quick

# The readers' fuzz targets (fuzz/, docs/FUZZING.md) built with coverage and run by AFL++
# for 20 s each on the committed corpus: fails on a crash, a hang or a heap bound exceeded.
fuzz-smoke: deps
	scripts/fuzz.sh smoke 20

# ffi/tests/c under -fsanitize=address,undefined (LSan on) and -fsanitize=thread, and the
# C demo at 32x32 under valgrind memcheck (scripts/sanitize.sh; run times in
# docs/RELIABILITY.md); logs in build/sanitize.
sanitize: deps
	scripts/sanitize.sh

# The regression suite (tests/regression/README.md): every scene of tests/regression/scenes.py
# rendered by vtkGPUVolumeRayCastMapper (the reference), vtkFixedPointVolumeRayCastMapper and
# vtkFerroVolumeMapper in a private Xvfb; SSIM, PSNR, FLIP and footprint colour difference
# against tests/regression/thresholds.toml; report in build/regression/index.html. Scenes
# whose data is missing are reported as skipped (scripts/fetch-data.sh makes it).
REGRESSION = . build/env.sh && env -u DISPLAY scripts/with-xvfb.sh \
  vtk_plugin/tests/retry-on-x-failure.sh /usr/bin/python3 tests/regression/run.py
regression: vtk
	@scripts/fetch-data.sh >/dev/null
	$(REGRESSION)
	$(MAKE) paraview-regression

regression-quick: vtk
	@scripts/fetch-data.sh >/dev/null || echo "regression-quick: data missing, those scenes are skipped"
	$(REGRESSION) --quick

# The first process after a shader change runs 3-4x slower on lavapipe until Mesa's shader
# cache holds the pipelines (measured), so a short priming run of both renderers goes first.
bench: build
	scripts/with-xvfb.sh $(FERROVOL) bench --vtk --frames 2 >/dev/null
	scripts/with-xvfb.sh $(FERROVOL) bench --vtk --frames 20 --png-dir build/bench
	. build/env.sh && scripts/with-xvfb.sh /usr/bin/python3 bench/fidelity.py

# vtkFerroVolumeMapper (zero-copy shared path and readback path) against
# vtkGPUVolumeRayCastMapper in a VTK window, the same benchmark scene, alternating rounds:
# in VTK's default (multisampled) window, then in one without multisampling; then the
# equal-fidelity table (bench/fidelity.py): frame time and error against each renderer's
# converged reference, scene by scene; then two volumes intermixed (bench/multi_volume.py).
bench-vtk: vtk
	. build/env.sh && scripts/with-xvfb.sh /usr/bin/python3 bench/vtk_mappers.py --frames 10 --rounds 1 >/dev/null
	. build/env.sh && scripts/with-xvfb.sh /usr/bin/python3 bench/vtk_mappers.py --frames 10 --rounds 5
	. build/env.sh && scripts/with-xvfb.sh /usr/bin/python3 bench/vtk_mappers.py --frames 10 --rounds 5 --multisamples 0
	. build/env.sh && scripts/with-xvfb.sh /usr/bin/python3 bench/fidelity.py
	. build/env.sh && scripts/with-xvfb.sh /usr/bin/python3 bench/multi_volume.py
	. build/env.sh && scripts/with-xvfb.sh /usr/bin/python3 bench/multi_volume.py --shade

# The soak test (vtk_plugin/tests/soak.py): 10 000 renders of vtkFerroVolumeMapper while
# everything changes; fails on an error or memory growth over 5%, plots the memory curve.
soak: vtk
	mkdir -p build/soak
	. build/env.sh && cd vtk_plugin/tests && ../../scripts/with-xvfb.sh /usr/bin/python3 soak.py \
	  --renders 10000 --csv ../../build/soak/soak.csv --svg ../../docs/img/soak-memory.svg

# The README's pictures.
pictures: build
	$(FERROVOL) render --demo wavelet --shade --size 640x640 --azimuth 30 --elevation 20 --out docs/img/wavelet-shaded.png
	$(FERROVOL) render --demo marschner-lobb --shade --size 640x640 --elevation 30 --out docs/img/marschner-lobb.png
	$(FERROVOL) render --demo wavelet --mode mip --size 640x640 --azimuth 30 --elevation 20 --out docs/img/wavelet-mip.png
	scripts/fetch-data.sh >/dev/null
	$(FERROVOL) render build/data/cranium.vti --tf ct-skin-bone --shade --elevation -90 --size 640x640 --out docs/img/cranium-ct.png
	$(FERROVOL) render build/data/cranium.vti --mode iso --iso 400 --iso=-500:0.25 --ao 16 --elevation -90 --view-up z --env-up z --zoom 1.3 --env-background --size 640x640 --out docs/img/cranium-iso.png
	$(FERROVOL) render build/data/cranium.vti --mode pathtrace --tf ct-bone --spp 64 --g 0.2 --elevation -90 --view-up z --env-up z --zoom 1.3 --env-background --size 256x256 --out docs/img/cranium-pathtrace.png
	$(FERROVOL) render build/data/cranium.vti --mode pathtrace --tf ct-bone --spp 64 --g 0.2 --psi 100 --elevation -90 --view-up z --env-up z --zoom 1.3 --env-background --size 256x256 --out docs/img/cranium-pathtrace-hybrid.png
	for m in preview traced; do $(FERROVOL) render build/data/cranium.vti --mode iso --tf ct-skin-bone --iso 400:1:0.95,0.92,0.85 --iso=-500:1:0.9,0.6,0.5 --scatter-inside $$m --scatter-samples 32 --absorption 0.3 --env-light 1 --elevation -90 --view-up z --env-up z --zoom 1.3 --env-background --size 320x320 --out docs/img/cranium-iso-scatter-$$m.png; done
	for b in 1x64 8x8 64x1; do $(FERROVOL) render build/data/cranium.vti --mode pathtrace --tf ct-bone --budget $$b --g 0.2 --psi 100 --elevation -90 --view-up z --env-up z --zoom 1.3 --env-background --size 256x256 --out docs/img/cranium-budget-$$b.png; done
	$(FERROVOL) render build/data/colin27.nii.gz --mode iso --iso 60:0.35:0.92,0.72,0.62 --iso 115:1:0.9,0.88,0.82 --ao 16 --elevation 90 --view-up z --env-up z --zoom 1.2 --size 640x640 --out docs/img/mri-iso.png

# ParaView 6.1 from Debian unstable, unpacked into build/pv6-sdk (scripts/pv6-sdk.sh): the
# plugin built in build/pv6-paraview and the same tests (paraview/README.md).
.PHONY: paraview6-test
paraview6-test:
	$(FFI_RELEASE)
	env -u DISPLAY scripts/with-xvfb.sh paraview/tests/run-pv6.sh 2
