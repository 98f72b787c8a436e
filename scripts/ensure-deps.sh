#!/usr/bin/env bash
# Install what `make test` / `make demo` need when it is missing: Debian packages
# (software Vulkan/GL drivers, Xvfb, OpenEXR tools, Ninja, glslang and SPIRV-Tools, Chromium,
# Blender's executable and numpy for its glTF exporter: the add-on's panels and viewport) and the
# npm packages (glTF-Validator, three.js, playwright-core) under tests/node, and Blender as a Python module
# for the add-on's tests (scripts/ensure-bpy.sh). Idempotent; quiet when all is there.
set -euo pipefail
cd "$(dirname "$0")/.."

PKGS="mesa-vulkan-drivers libvulkan1 libegl1 libegl-mesa0 libgl1-mesa-dri xvfb xauth openimageio-tools ninja-build glslang-tools spirv-tools chromium blender python3-numpy"
missing=""
for p in $PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "ensure-deps: installing Debian packages:$missing" >&2
  SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  for i in 1 2 3 4 5 6; do $SUDO apt-get update -qq && break; sleep 10; done
  for i in 1 2 3 4 5 6; do $SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null && break; sleep 10; done
fi

if [ -f tests/node/package.json ] && { [ ! -d tests/node/node_modules ] || [ ! -d tests/node/node_modules/playwright-core ]; }; then
  command -v npm >/dev/null || { echo "ensure-deps: npm not found (apt-get install nodejs npm)" >&2; exit 1; }
  echo "ensure-deps: installing npm validators in tests/node" >&2
  (cd tests/node && for i in 1 2 3; do npm ci --no-audit --no-fund --loglevel=error && break; sleep 5; done)
fi

# bpy for tests/blender: a failed install fails CI (SUNBEAM_REQUIRE_ALL=1); elsewhere those tests skip.
if ! scripts/ensure-bpy.sh; then
  [ "${SUNBEAM_REQUIRE_ALL:-}" = 1 ] && exit 1
  echo "ensure-deps: no bpy; tests/blender will skip" >&2
fi
