#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds and runs the whole test suite.
#   bash scripts/test.sh         release build (build/release)
#   bash scripts/test.sh asan    AddressSanitizer + UndefinedBehaviorSanitizer build (build/asan)
# ctest includes gltf_validator (the Khronos glTF validator, which setup.sh installs with npm ci;
# "skipped" without node or the validator) and viewer_e2e (the page of `pointform view` in
# Debian's chromium through playwright-core, from viewer/node_modules; "skipped" without them).
# The release build also runs the Python package's
# pytest suite (python/tests) with Debian's /usr/bin/python3; the asan build has no Python module
# (an instrumented extension cannot load into an uninstrumented interpreter).
set -euo pipefail
cd "$(dirname "$0")/.."
# ccache (CMakeLists.txt uses it where installed): paths relative to this checkout and the
# working directory left out of the hash, so that a fresh clone of the same sources (as CI builds)
# compiles from the cache.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true
preset="${1:-release}"

bash scripts/setup.sh
cmake --preset "$preset"
cmake --build --preset "$preset"
ctest --preset "$preset"
if [[ $preset == release ]]; then
  /usr/bin/python3 -m pytest -q python/tests
fi
