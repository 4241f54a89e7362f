#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs everything pointform needs from Debian 12 packages. Run as root (or with sudo).
#   bash scripts/setup.sh          build and test dependencies
#   bash scripts/setup.sh --peers  also the peers of the side-by-side benchmarks (Open3D, CGAL)
#   bash scripts/setup.sh --fuzz   also Clang and libFuzzer for scripts/fuzz.sh
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libnanoflann-dev libcli11-dev nlohmann-json3-dev
  libembree-dev libstb-dev libopenmesh-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang-format
  python3 python3-dev python3-numpy python3-pybind11 python3-pytest
)
case "${1:-}" in
  --peers) packages+=(python3-open3d libcgal-dev libtbb-dev time) ;;
  --fuzz) packages+=(clang-14 libclang-rt-14-dev libomp-14-dev) ;;
  "") ;;
  *) echo "setup: unknown option $1 (expected --peers or --fuzz)" >&2; exit 2 ;;
esac

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages already installed"
  exit 0
fi

sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  sudo_cmd=(sudo)
fi
echo "setup: installing ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
