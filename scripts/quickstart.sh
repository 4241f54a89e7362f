#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# From a fresh Debian 12 machine: install dependencies, build, and run the main job on the
# shipped bunny scan: oriented surfels with influence radii (Level 1 -> 2), then the
# marching-cubes surface of their field and a picture of it.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/setup.sh
cmake --preset release
cmake --build --preset release --target pointform_cli
./build/release/apps/pointform/pointform info data/bunny/bun_zipper.ply
./build/release/apps/pointform/pointform normals data/bunny/bun_zipper.ply -o bunny_surfels.ply
./build/release/apps/pointform/pointform mc data/bunny/bun_zipper.ply -o bunny_mc.ply
./build/release/apps/pointform/pointform render bunny_mc.ply -o bunny_mc.png --wireframe
