#!/bin/sh
# SPDX-License-Identifier: MIT
# The CTest test viewer_e2e: makes the shipped bunny scan's samples (its points with oriented
# normals), reconstructs them into a hierarchy and opens both with `pointform view` in Debian's
# chromium, driven by playwright-core (viewer_e2e.mjs). Exits 77
# (CTest's "skipped") when node, chromium, three.js or playwright-core is missing.
#   run_viewer_e2e.sh NODE POINTFORM SCAN OUTPUT_FOLDER
# PF_UPDATE_DOCS_SCREENSHOT=1 also copies the screenshot to docs/images/viewer_bunny.png.
set -eu
node="$1"
cli="$2"
scan="$3"
out="$4"
here=$(cd "$(dirname "$0")" && pwd)
viewer="$here/../../viewer"

if [ -z "$node" ] || ! command -v "$node" >/dev/null 2>&1; then
  echo "skipped: node (Node.js) not found; bash scripts/setup.sh installs it"
  exit 77
fi
chromium="${PF_CHROMIUM:-/usr/bin/chromium}"
if [ ! -x "$chromium" ]; then
  echo "skipped: $chromium not found; bash scripts/setup.sh installs chromium"
  exit 77
fi
for f in three/build/three.module.js playwright-core/package.json; do
  if [ ! -f "$viewer/node_modules/$f" ]; then
    echo "skipped: $viewer/node_modules/$f is not installed; bash scripts/setup.sh runs npm ci in viewer/"
    exit 77
  fi
done

rm -rf "$out"
mkdir -p "$out"
"$cli" normals "$scan" -o "$out/samples.ply" -q
"$cli" reconstruct "$out/samples.ply" -o "$out/bunny.ply" --save-hierarchy "$out/bunny.pfh" --json \
  > "$out/bunny.json"
docs=""
if [ "${PF_UPDATE_DOCS_SCREENSHOT:-0}" = 1 ]; then
  docs="$here/../../docs/images/viewer_bunny.png"
fi
# shellcheck disable=SC2086
exec "$node" "$here/viewer_e2e.mjs" "$cli" "$out/bunny.pfh" "$out/samples.ply" "$out/bunny.json" \
  "$out" $docs
