#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# From a fresh Debian 12 machine: install dependencies, build, and run the main job on the
# shipped bunny scan (Level 1 -> 2: oriented surfels with influence radii).
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/setup.sh
cmake --preset release
cmake --build --preset release --target pointform_cli
./build/release/apps/pointform/pointform info data/bunny/bun_zipper.ply
./build/release/apps/pointform/pointform normals data/bunny/bun_zipper.ply -o bunny_surfels.ply
