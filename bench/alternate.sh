#!/bin/bash
# Runs benchmark binaries in turn, ROUNDS times, and prints the least real time of each
# benchmark for each binary: an A/B comparison on a noisy machine (bench/RESULTS.md, stop 57).
#   bench/alternate.sh FILTER ROUNDS BINARY...
# e.g. two builds' bench/sigmafem_bench copied aside, compared on the liver's filter step:
#   bench/alternate.sh 'BM_filter_step/(vulkan|opencl)_factorised/' 3 /tmp/before /tmp/after
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 FILTER ROUNDS BINARY..." >&2
  exit 2
fi
filter="$1"
rounds="$2"
shift 2
for ((round = 1; round <= rounds; ++round)); do
  for binary in "$@"; do
    "$binary" --benchmark_filter="$filter" --benchmark_min_time=0.5 2>/dev/null |
      awk -v b="$binary" '/^BM_/ { print b, $1, $2, $3 }'
  done
done | awk '{ key = $1 " " $2; if (!(key in least) || $3 < least[key]) { least[key] = $3; unit[key] = $4 }; runs[key]++ }
            END { for (key in least) print key, least[key], unit[key], "(least of " runs[key] ")" }' | sort -k2,2 -k1,1
