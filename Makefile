# ferrovol — GPU volume ray casting on wgpu.
#   make demo   render the built-in demo volume to build/demo.png
#   make test   format, lint and run every test (installs what is missing first)
#   make bench  VTK's GPU ray cast benchmark scene, ferrovol vs vtkGPUVolumeRayCastMapper
#   make build  release build of the `ferrovol` command
SHELL := /bin/bash
CARGO ?= cargo
export XDG_RUNTIME_DIR ?= /tmp/ferrovol-xdg-$(shell id -u)
FERROVOL := target/release/ferrovol

.PHONY: deps build demo test lint bench pictures

deps:
	@bash scripts/install-deps.sh
	@mkdir -p -m 700 $(XDG_RUNTIME_DIR) build

build: deps
	$(CARGO) build --release --locked -p ferrovol-cli

demo: build
	$(FERROVOL) render --demo wavelet --shade --size 640x640 --azimuth 30 --elevation 20 --out build/demo.png
	@echo "demo image: $(CURDIR)/build/demo.png"

lint: deps
	$(CARGO) fmt --all --check
	$(CARGO) clippy --locked --workspace --all-targets -- -D warnings

test: lint
	$(CARGO) test --locked --workspace

# The first process after a shader change runs 3-4x slower on lavapipe until Mesa's shader
# cache holds the pipelines (measured), so a short priming run of both renderers goes first.
bench: build
	scripts/with-xvfb.sh $(FERROVOL) bench --vtk --frames 2 >/dev/null
	scripts/with-xvfb.sh $(FERROVOL) bench --vtk --frames 20 --png-dir build/bench

# The README's pictures.
pictures: build
	$(FERROVOL) render --demo wavelet --shade --size 640x640 --azimuth 30 --elevation 20 --out docs/img/wavelet-shaded.png
	$(FERROVOL) render --demo marschner-lobb --shade --size 640x640 --elevation 30 --out docs/img/marschner-lobb.png
	$(FERROVOL) render --demo wavelet --mode mip --size 640x640 --azimuth 30 --elevation 20 --out docs/img/wavelet-mip.png
	scripts/fetch-data.sh >/dev/null
	$(FERROVOL) render build/data/cranium.vti --tf ct-skin-bone --shade --elevation -90 --size 640x640 --out docs/img/cranium-ct.png
