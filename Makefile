# ferrovol — GPU volume ray casting on wgpu.
#   make demo   render the built-in demo volume to build/demo.png
#   make test   format, lint and run every test (installs what is missing first)
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
#               (a 3000-render version is in make vtk-test); plot: docs/img/soak-memory.svg
#   make sanitize  the C ABI's C/C++ test programs under ASan+UBSan+LSan and TSan, the C
#               demo under valgrind (docs/RELIABILITY.md); `make test` runs it
#   make vtk-asan  the VTK module built with ASan+UBSan (build/vtk-asan) and its CTest suite
#               (all but the soak) run on it; `make test` runs it
SHELL := /bin/bash
CARGO ?= cargo
export XDG_RUNTIME_DIR ?= /tmp/ferrovol-xdg-$(shell id -u)
FERROVOL := target/release/ferrovol

.PHONY: deps build demo test lint bench bench-vtk pictures vtk vtk-test paraview paraview-test paraview-regression \
        regression regression-quick fuzz-smoke soak sanitize vtk-asan

deps:
	@bash scripts/install-deps.sh
	@mkdir -p -m 700 $(XDG_RUNTIME_DIR) build

build: deps
	$(CARGO) build --release --locked -p ferrovol-cli
	$(MAKE) vtk

# The VTK module links the C ABI library (target/release/libferrovol.so); VTK 9.2 is
# ParaView's (docs/ARCHITECTURE.md, Machines). 2 cores: ninja -j2.
VTK_BUILD := build/vtk
vtk: deps
	$(CARGO) build --release --locked -p ferrovol-ffi
	cmake -G Ninja -S vtk_plugin -B $(VTK_BUILD) -DPython3_EXECUTABLE=/usr/bin/python3 >/dev/null
	ninja -C $(VTK_BUILD) -j2
	cp $(VTK_BUILD)/env.sh build/env.sh
	$(PV_ENV_HOOK)
	@echo "VTK module built: . build/env.sh && /usr/bin/python3 -c 'import vtk, ferrovol'"

# C++ and Python tests of vtkFerroVolumeMapper in a private Xvfb (images and measured
# figures land in build/vtk/test-images).
vtk-test: vtk
	@scripts/fetch-data.sh >/dev/null || echo "vtk-test: no build/data/cranium.vti; the examples render a synthetic volume"
	env -u DISPLAY scripts/with-xvfb.sh ctest --test-dir $(VTK_BUILD) --output-on-failure -j1

# The VTK module, its wrapping, examples and C++ tests built with AddressSanitizer and UBSan
# (FERROVOL_SANITIZE, vtk_plugin/CMakeLists.txt), and the CTest suite run on them (the Python
# tests preload the runtimes); the soak is left to `make soak`.
VTK_ASAN_BUILD := build/vtk-asan
vtk-asan: deps
	$(CARGO) build --release --locked -p ferrovol-ffi
	cmake -G Ninja -S vtk_plugin -B $(VTK_ASAN_BUILD) -DPython3_EXECUTABLE=/usr/bin/python3 \
	  -DFERROVOL_SANITIZE=ON >/dev/null
	ninja -C $(VTK_ASAN_BUILD) -j2
	env -u DISPLAY scripts/with-xvfb.sh ctest --test-dir $(VTK_ASAN_BUILD) --output-on-failure -j1 \
	  -E '^python.soak$$'

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
paraview: deps
	$(CARGO) build --release --locked -p ferrovol-ffi
	cmake -G Ninja -S paraview -B $(PV_BUILD) -Wno-deprecated >/dev/null
	ninja -C $(PV_BUILD) -j2
	$(PV_ENV_HOOK)
	@echo "ParaView plugin built: . build/env.sh && pvpython   (\"Ferrovol Volume\" is loaded)"

# pvbatch/pvpython/paraview tests in a private Xvfb (1920x1080 screen); build/data/cranium.vti
# is used when scripts/fetch-data.sh has made it (the cranium test says SKIP otherwise).
paraview-test: paraview
	env -u DISPLAY scripts/with-xvfb.sh paraview/tests/run-all.sh 2

paraview-regression: paraview
	env -u DISPLAY scripts/with-xvfb.sh paraview/tests/run-all.sh 4

demo: build
	$(FERROVOL) render --demo wavelet --shade --size 640x640 --azimuth 30 --elevation 20 --out build/demo.png
	@echo "demo image: $(CURDIR)/build/demo.png"

lint: deps
	$(CARGO) fmt --all --check
	$(CARGO) clippy --locked --workspace --all-targets -- -D warnings
	$(CARGO) fmt --manifest-path fuzz/Cargo.toml --check
	$(CARGO) clippy --locked --manifest-path fuzz/Cargo.toml --all-targets -- -D warnings
	python3 scripts/check-core-layers.py
	python3 scripts/check-architecture-doc.py

# The C ABI tests load and link target/debug/libferrovol.so, which `cargo test` alone does
# not build (it links tests against the rlib).
test: lint
	$(CARGO) build --locked -p ferrovol-ffi
	$(CARGO) test --locked --workspace
	$(MAKE) sanitize
	$(MAKE) fuzz-smoke
	$(MAKE) vtk-test
	$(MAKE) vtk-asan
	$(MAKE) paraview-test
	$(MAKE) regression-quick

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
