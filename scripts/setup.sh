#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs everything pointform needs from Debian 12 packages. Run as root (or with sudo).
# Then installs the Khronos glTF validator (npm gltf-validator, pinned by
# tests/gltf/package-lock.json) into tests/gltf/node_modules with `npm ci`, for the test
# gltf_validator; Node.js and npm come from Debian (nodejs, npm) unless node and npm are there.
# Likewise three.js and playwright-core (pinned by viewer/package-lock.json) into
# viewer/node_modules, for the page `pointform view` serves and the test viewer_e2e, which drives
# Debian's chromium.
#   bash scripts/setup.sh          build and test dependencies
#   bash scripts/setup.sh --peers  also the peers of the side-by-side benchmarks (Open3D, CGAL)
#   bash scripts/setup.sh --fuzz   also Clang and libFuzzer for scripts/fuzz.sh
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git ccache
  libeigen3-dev libnanoflann-dev libcli11-dev nlohmann-json3-dev
  libembree-dev libpng-dev libopenmesh-dev libcpp-httplib-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang-format chromium
  python3 python3-dev python3-numpy python3-pybind11 python3-pytest
)
case "${1:-}" in
  --peers) packages+=(python3-open3d libcgal-dev libtbb-dev time) ;;
  --fuzz) packages+=(clang-14 libclang-rt-14-dev libomp-14-dev) ;;
  "") ;;
  *) echo "setup: unknown option $1 (expected --peers or --fuzz)" >&2; exit 2 ;;
esac

# Node.js and npm (the glTF validator's runtime): Debian's, unless both are already on the PATH
# (another build of Node.js, such as NodeSource's, which Debian's npm package would conflict with).
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  packages+=(nodejs npm)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages already installed"
else
  sudo_cmd=()
  if [[ $(id -u) -ne 0 ]]; then
    sudo_cmd=(sudo)
  fi
  echo "setup: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# npm_install DIR WHAT CONSEQUENCE PACKAGE...: `npm ci` in DIR, exactly as its package-lock.json
# pins them, unless every PACKAGE is installed and the lock file has not changed since the last
# install. A failure only warns, saying CONSEQUENCE.
npm_install() {
  local dir="$1" what="$2" consequence="$3"
  shift 3
  local needed=0 package
  for package in "$@"; do
    [[ -f "$dir/node_modules/$package/package.json" ]] || needed=1
  done
  [[ "$dir/package-lock.json" -nt "$dir/node_modules/.package-lock.json" ]] && needed=1
  if ((needed == 0)); then
    echo "setup: $what already installed ($dir/node_modules)"
    return
  fi
  echo "setup: installing $what (npm ci in $dir)"
  if ! (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error); then
    echo "setup: warning: npm ci failed in $dir; $consequence" >&2
  fi
}

here="$(dirname "$0")/.."
# The glTF validator, for the test gltf_validator (skipped without it).
npm_install "$here/tests/gltf" "the glTF validator" "the test gltf_validator will be skipped" \
  gltf-validator
# three.js (the viewer page) and playwright-core (its browser test): without them `pointform
# view` warns that the page cannot work and the test viewer_e2e reports "skipped".
npm_install "$here/viewer" "three.js and playwright-core" \
  "the page of pointform view will not work and the test viewer_e2e will be skipped" \
  three playwright-core
