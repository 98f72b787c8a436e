# Sunbeam: the two set-up commands.
#   make demo   scan -> height field -> pack -> baked mesh -> rendered frame (examples/)
#   make test   every test (installs what it needs when missing)
CARGO ?= cargo
CARGO_FLAGS ?= --release --locked

# Where cargo really puts the tools: CARGO_TARGET_DIR, build.target-dir of a cargo
# config (CARGO_BUILD_TARGET_DIR), or ./target. Asked of cargo itself, and only when
# a recipe needs it; the profile folder follows CARGO_FLAGS. `make demo BIN=DIR` overrides.
TARGET_DIR = $(eval TARGET_DIR := $(shell $(CARGO) metadata --format-version 1 --no-deps | sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p'))$(TARGET_DIR)
PROFILE_DIR = $(if $(filter --release,$(CARGO_FLAGS)),release,debug)
BIN = $(TARGET_DIR)/$(PROFILE_DIR)
# Goals of examples/Makefile for `make demo` (default: all of it).
DEMO_GOALS ?=

.PHONY: all build demo test deps clean blender-addon blender-docs-img blender-panels-img

# wgpu's GL/Wayland probing complains without a runtime dir; give tests a private one.
XDG_RUNTIME_DIR ?= $(shell d=$${TMPDIR:-/tmp}/sunbeam-xdg-$$(id -u); mkdir -p -m 700 $$d && echo $$d)
export XDG_RUNTIME_DIR

all: build

deps:
	scripts/ensure-deps.sh

build:
	$(CARGO) build $(CARGO_FLAGS) --workspace

demo: deps build
	@test -x '$(BIN)/sunbeam-import' || { echo "make demo: no tools in '$(BIN)' (cargo metadata's target_directory + $(PROFILE_DIR)); set BIN=DIR" >&2; exit 1; }
	$(MAKE) -C examples -j2 BIN='$(BIN)' $(DEMO_GOALS)

# One feature set and one profile for build and test, so nothing compiles twice.
test: deps
	$(CARGO) build $(CARGO_FLAGS) --workspace --all-targets
	$(CARGO) test $(CARGO_FLAGS) --workspace --no-fail-fast
	SUNBEAM_BIN='$(BIN)' tests/blender/run.sh
	tests/blender/panels_test.sh

# The Blender add-on as an installable zip (docs/BLENDER.md), byte-identical for the same sources.
BLENDER_ZIP ?= target/blender/sunbeam_blender.zip
blender-addon:
	mkdir -p $(dir $(BLENDER_ZIP))
	scripts/blender-addon-zip.py $(BLENDER_ZIP)

# docs/img/blender-*.png: the add-on's test render and its hand-written reference (docs/BLENDER.md).
blender-docs-img: deps
	SUNBEAM_BIN='$(BIN)' SUNBEAM_BLENDER_IMG=docs/img tests/blender/run.sh RenderTest

# docs/img/blender-panel-*.png: screenshots of the add-on's panels (docs/BLENDER.md), taken by
# Blender's own executable (SUNBEAM_BLENDER, default blender) under xvfb-run; `make test` takes
# them again and compares (tests/blender/panels_test.sh).
blender-panels-img:
	tests/blender/panel_screenshots.sh docs/img

clean:
	$(CARGO) clean
	rm -rf examples/out
