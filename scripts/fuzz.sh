#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the libFuzzer harnesses (Clang, ASan + UBSan) and fuzzes every reader for SECONDS
# (default 60), seeded with the small files in data/. Fails on any crash or sanitizer report.
#   bash scripts/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"

bash scripts/setup.sh --fuzz
cmake --preset fuzz
cmake --build --preset fuzz --target read_fuzz

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
# Inputs that once found a bug run first, then the fuzzer explores from the seeds.
./build/fuzz/tests/fuzz/read_fuzz tests/fuzz/regressions/*
./build/fuzz/tests/fuzz/read_fuzz -max_total_time="$seconds" -max_len=65536 -timeout=10 \
  -rss_limit_mb=4096 -print_final_stats=1 -artifact_prefix=build/fuzz/ "$corpus"
