#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the libFuzzer harnesses (Clang, ASan + UBSan) and fuzzes for SECONDS in all (default
# 60): every reader (half the time, seeded with the small files in data/), the hierarchy reader,
# the scene language, the edit and lattice files of `deform` and the PNG decoder (an eighth each,
# at most, seeded from tests/fuzz/seeds/). Fails on any crash, hang or sanitizer report.
#   bash scripts/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
# ccache (CMakeLists.txt uses it where installed): paths relative to this checkout and the
# working directory left out of the hash, so that a fresh clone of the same sources (as CI builds)
# compiles from the cache.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true
seconds="${1:-60}"
readers_seconds=$(( (seconds + 1) / 2 ))
other_seconds=$(( (seconds - readers_seconds) / 4 ))
other_seconds=$(( other_seconds > 0 ? other_seconds : 1 ))

bash scripts/setup.sh --fuzz
cmake --preset fuzz
cmake --build --preset fuzz --target read_fuzz hierarchy_fuzz scene_fuzz edit_fuzz png_fuzz
harnesses=build/fuzz/tests/fuzz
common=(-timeout=10 -rss_limit_mb=4096 -print_final_stats=1 -artifact_prefix=build/fuzz/)
# regressions HARNESS PREFIX: runs the inputs in tests/fuzz/regressions/ that once found a bug in
# that harness (named PREFIX-...; the readers' are the rest).
regressions() {
  local files=()
  if [[ "$2" == readers ]]; then
    mapfile -d '' files < <(find tests/fuzz/regressions -maxdepth 1 -type f \
      ! -name 'hierarchy-*' ! -name 'scene-*' ! -name 'edit-*' ! -name 'png-*' -print0 | sort -z)
  else
    mapfile -d '' files < <(find tests/fuzz/regressions -maxdepth 1 -type f -name "$2-*" -print0 |
      sort -z)
  fi
  if (( ${#files[@]} > 0 )); then
    "$harnesses/$1" "${files[@]}"
  fi
}

corpus=build/fuzz/corpus
mkdir -p "$corpus"
index=0
for ext in ply xyz pts csv off obj pcd las; do
  # Seeds: the shipped files of this format under 64 KiB, prefixed with the format's byte.
  while IFS= read -r -d '' file; do
    { printf "\\$(printf '%03o' "$index")"; cat "$file"; } > "$corpus/$(basename "$file").$index"
  done < <(find data -name "*.$ext" -size -64k -print0)
  index=$((index + 1))
done
# Inputs that once found a bug run first (each harness takes those of its kind), then the fuzzers
# explore from the seeds.
regressions read_fuzz readers
"$harnesses/read_fuzz" -max_total_time="$readers_seconds" -max_len=65536 "${common[@]}" "$corpus"

# seeded NAME MAX_LEN [OPTIONS...]: fuzzes harness NAME_fuzz for other_seconds from the seeds in
# tests/fuzz/seeds/NAME/, after the regressions named NAME-*.
seeded() {
  local name="$1" max_len="$2"
  shift 2
  local seed_corpus="build/fuzz/corpus-$name"
  mkdir -p "$seed_corpus"
  cp "tests/fuzz/seeds/$name"/* "$seed_corpus"/
  regressions "${name}_fuzz" "$name"
  "$harnesses/${name}_fuzz" -max_total_time="$other_seconds" -max_len="$max_len" "$@" \
    "${common[@]}" "$seed_corpus"
}
seeded hierarchy 65536
seeded scene 16384 -dict=tests/fuzz/scene.dict
seeded edit 16384
seeded png 65536
