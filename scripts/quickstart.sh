#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# From a fresh Debian 12 machine: install dependencies, build, and run the main job on the
# shipped bunny scan: raw points -> oriented surfels with influence radii (Level 1 -> 2) -> their
# field -> a semi-regular multiresolution mesh (Level 3: base mesh refined until it is within the
# sampling density of the scan), then a picture of it with its edges drawn. It also builds the
# Python package, which `/usr/bin/python3 -c "import pointform"` then finds from the repository
# root (pointform/__init__.py loads build/release/python/pointform).
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/setup.sh
cmake --preset release
cmake --build --preset release --target pointform_cli pointform_python
./build/release/apps/pointform/pointform info data/bunny/bun_zipper.ply
./build/release/apps/pointform/pointform reconstruct data/bunny/bun_zipper.ply -o bunny.ply \
    --save-hierarchy bunny.pfh
./build/release/apps/pointform/pointform render bunny.ply -o bunny.png --wireframe
