# Sunbeam: the two set-up commands.
#   make demo   scan -> height field -> pack -> baked mesh -> rendered frame (examples/)
#   make test   every test (installs what it needs when missing)
CARGO ?= cargo
CARGO_FLAGS ?= --release --locked

.PHONY: all build demo test deps clean

# wgpu's GL/Wayland probing complains without a runtime dir; give tests a private one.
XDG_RUNTIME_DIR ?= $(shell d=$${TMPDIR:-/tmp}/sunbeam-xdg-$$(id -u); mkdir -p -m 700 $$d && echo $$d)
export XDG_RUNTIME_DIR

all: build

deps:
	scripts/ensure-deps.sh

build:
	$(CARGO) build $(CARGO_FLAGS) --workspace

demo: deps build
	$(MAKE) -C examples -j2

# One feature set and one profile for build and test, so nothing compiles twice.
test: deps
	$(CARGO) build $(CARGO_FLAGS) --workspace --all-targets
	$(CARGO) test $(CARGO_FLAGS) --workspace --no-fail-fast

clean:
	$(CARGO) clean
	rm -rf examples/out
