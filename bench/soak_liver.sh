#!/usr/bin/env bash
# Soak run (issue 14): STEPS filter steps of the shipped liver on the OpenCL back end.
#   bench/soak_liver.sh [STEPS [BUILD_DIR]]      (defaults: 100000, build)
# 1. The data: the liver scenario run for STEPS steps by `sigmafem generate` (the trajectory
#    holds its last point after its last knot).
# 2. The engine (bench/soak_main.cpp): the filter with the OpenCL ensemble, keeping only the
#    change detection's window of steps, as an unbounded run must; its resident memory must
#    stay within 5% of its level at step 1000 (exit 1 otherwise). Samples: BUILD_DIR/soak/engine.csv.
# 3. The `estimate` command, which keeps every step for its reports (estimates.csv, the
#    residual tests, the plots): its memory grows with the steps, and the script reports by
#    how much per step. Samples (seconds, step, rss_kb, every second): BUILD_DIR/soak/estimate.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
steps=${1:-100000}
build=${2:-build}
program="$build/sigmafem"
work=$(mktemp -d "${TMPDIR:-/tmp}/sigmafem_soak.XXXXXX")
trap 'rm -rf "$work"' EXIT
mkdir -p "$build/soak"
cp scenarios/liver.json scenarios/liver.msh scenarios/liver_trajectory.csv "$work/"
sed -i "s/\"steps\": [0-9]*/\"steps\": $steps/" "$work/liver.json"
grep -q "\"steps\": $steps" "$work/liver.json" || { echo "could not set the step count" >&2; exit 2; }

echo "== generating $steps steps of the liver (CPU reference)"
"$program" generate "$work/liver.json" --out "$work/data" --vtk-every 0 --quiet

echo "== the engine on OpenCL, keeping the detector's window (VmRSS every 1000 steps)"
engine=0
"$build/bench/sigmafem_soak" "$work/liver.json" "$work/data" opencl 1000 > "$build/soak/engine.csv" || engine=$?

echo "== sigmafem estimate on OpenCL, keeping every step (VmRSS every second)"
# The progress line is drawn only on a terminal: script(1) gives the run one, and its log
# tells the step reached at each sample.
script -qfec "'$program' estimate '$work/liver.json' --data '$work/data' --out '$work/estimate' --backend opencl" \
  "$work/log" >/dev/null &
runner=$!
echo "seconds,step,rss_kb" > "$work/estimate.csv"
start=$(date +%s)
pid=""
while kill -0 "$runner" 2>/dev/null; do
  [ -z "$pid" ] && pid=$(pgrep -n -f "^$program estimate $work" || true)
  if [ -n "$pid" ] && [ -r "/proc/$pid/status" ]; then
    rss=$(awk '/^VmRSS:/{print $2}' "/proc/$pid/status" 2>/dev/null || true)
    step=$(tr '\r' '\n' < "$work/log" | grep -o 'step [0-9]*/' | tail -1 | tr -dc 0-9 || true)
    [ -n "$rss" ] && [ -n "$step" ] && echo "$(( $(date +%s) - start )),$step,$rss" >> "$work/estimate.csv"
  fi
  sleep 1
done
wait "$runner" || { echo "the estimation failed:" >&2; tr '\r' '\n' < "$work/log" | tail -5 >&2; exit 1; }
mv "$work/estimate.csv" "$build/soak/estimate.csv"
# From the first sample at or after step 1000 to the last one before the reports are written.
awk -F, 'NR > 1 && $2 >= 1000 && $2 < '"$steps"' { if (first == "") { first = $3; first_step = $2 } last = $3; last_step = $2 }
  END { if (first == "" || last_step == first_step) { print "estimate: too few samples"; exit }
        printf "estimate: VmRSS %d kB at step %d, %d kB at step %d: %.0f bytes per filter step kept for the reports\n",
               first, first_step, last, last_step, 1024 * (last - first) / (last_step - first_step) }' \
  "$build/soak/estimate.csv"
exit "$engine"
