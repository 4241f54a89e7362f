#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds and runs the whole test suite.
#   bash scripts/test.sh         release build (build/release)
#   bash scripts/test.sh asan    AddressSanitizer + UndefinedBehaviorSanitizer build (build/asan)
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"

bash scripts/setup.sh
cmake --preset "$preset"
cmake --build --preset "$preset"
ctest --preset "$preset"
