#!/bin/sh
# SPDX-License-Identifier: MIT
# The CTest test gltf_validator: writes sample .glb files (gltf_samples, and `pointform export`
# of a hierarchy when the CLI is built) and validates them with the Khronos glTF validator.
# Exits 77 (CTest's "skipped") when node or the validator is not installed.
#   run_validator.sh NODE SAMPLES_EXE OUTPUT_FOLDER [POINTFORM_CLI]
set -eu
node="$1"
samples="$2"
out="$3"
cli="${4:-}"
here=$(cd "$(dirname "$0")" && pwd)

if [ -z "$node" ] || ! command -v "$node" >/dev/null 2>&1; then
  echo "skipped: node (Node.js) not found; bash scripts/setup.sh installs it"
  exit 77
fi
if [ ! -f "$here/node_modules/gltf-validator/package.json" ]; then
  echo "skipped: $here/node_modules/gltf-validator is not installed; bash scripts/setup.sh runs npm ci there"
  exit 77
fi

rm -rf "$out"
mkdir -p "$out"
"$samples" "$out"
if [ -n "$cli" ]; then
  "$cli" export "$out/sphere.pfh" -o "$out/cli_sphere.glb" --levels all -q
  "$cli" export "$out/sphere.pfh" -o "$out/cli_sphere_1_3.glb" --levels 1,3 -q
fi
exec "$node" "$here/validate.mjs" "$out"/*.glb
