#!/bin/sh
# The checks to run on a machine with a GPU (README, "On a GPU"): every test that runs a
# device back end, against the double-precision CPU reference, and the ensemble benchmarks,
# OpenCL and Vulkan side by side in one run. Device 0 of each back end must be the GPU
# (`sigmafem devices`, first line of devices.txt); no GPU is needed to build or test.
# Usage: bench/gpu_checks.sh [BUILD [OUT]]   (defaults: build, BUILD/gpu)
# Each part has a time limit (seconds: SIGMAFEM_GPU_TEST_LIMIT, SIGMAFEM_GPU_LANES_LIMIT,
# SIGMAFEM_GPU_BENCH_LIMIT, SIGMAFEM_GPU_DIAGNOSE_LIMIT; 220 + 80 + 200 + 100 s by default, under
# a 10-minute call) so that a lease of a few minutes always brings its logs back. On the H200
# the conformance part took about 170 s and the liver diagnoses 78 s.
set -u
build=${1:-build}
out=${2:-$build/gpu}
mkdir -p "$out"
status=0

"$build/sigmafem" devices >"$out/devices.txt" 2>&1 || status=1
cat "$out/devices.txt"
# The tests and benchmarks use device 0 of each back end. Where PoCL is installed beside the
# GPU's driver its CPU device may come first (it did on the first H200 lease): then point
# OCL_ICD_VENDORS at a folder holding only the GPU's .icd file (README, "On a GPU").
for api in OpenCL Vulkan; do
  if ! sed -n "/^$api /,/^[A-Z]/p" "$out/devices.txt" | grep -Eq -- '--device 0: .*\((discrete |integrated |virtual )?gpu'; then
    echo "gpu_checks: $api device 0 is not a GPU (see devices.txt above); stopping" >&2
    exit 1
  fi
done

# The WholeSolve cases force the CPU devices' one-work-item CG solve; a GPU never chooses it.
echo "== conformance (limit ${SIGMAFEM_GPU_TEST_LIMIT:-220} s)"
SIGMAFEM_TESTS_REQUIRE=all timeout "${SIGMAFEM_GPU_TEST_LIMIT:-220}" "$build/tests/sigmafem_tests" \
  --gtest_filter='Backends/*:Precisions/*:OpenClDeviceTest.*:VulkanDeviceTest.*:OpenClMultigridTest.*:VulkanMultigridTest.*-*WholeSolve*' \
  --gtest_output="xml:$out/conformance.xml" >"$out/conformance.log" 2>&1
code=$?
echo "conformance exit $code"
[ $code -eq 0 ] || status=1
grep -E "^\[  FAILED  \]" "$out/conformance.log" | sort -u | head -60
grep -E 'tests ran|FAILED TEST' "$out/conformance.log"
[ $code -eq 0 ] || tail -n 5 "$out/conformance.log"

# CG with sigma points side by side in its groups (OpenCL's since stop 62, Vulkan's partitions'
# since stop 63, the defaults) against a sigma point a group, on the large meshes, first: the
# A/B that PoCL and lavapipe could only stand in for; S = 16, where stop 32 profiled an
# iteration (S = 64 runs in the benchmarks' part). Then the hierarchy made often, at once and
# in the background (stop 63): the slowest step against the mean (BM_steps_with_makings).
echo "== CG sigma lanes, makings (limit ${SIGMAFEM_GPU_LANES_LIMIT:-80} s)"
timeout "${SIGMAFEM_GPU_LANES_LIMIT:-80}" "$build/bench/sigmafem_bench" \
  --benchmark_filter='BM_ensemble_step/(opencl(_gpu_form_one_lane)?|vulkan(_one_lane)?)_(liver_fine_38144|box_large_117240)/16/|BM_steps_with_makings/(opencl|vulkan)_[a-z_]*_liver_fine_38144' \
  --benchmark_min_time=0.3 >"$out/lanes.log" 2>&1
echo "lanes exit $?"
cat "$out/lanes.log"

echo "== benchmarks (limit ${SIGMAFEM_GPU_BENCH_LIMIT:-200} s)"
timeout "${SIGMAFEM_GPU_BENCH_LIMIT:-200}" "$build/bench/sigmafem_bench" \
  --benchmark_filter='BM_ensemble_step/(opencl|vulkan)_(liver_4768|liver_596|liver_fine_38144|box_large_117240)/|BM_ensemble_step/(opencl|vulkan)_polar_liver_4768/|BM_ensemble_step/cpu_liver_(596|4768)/16/|BM_filter_step/(opencl|vulkan|cpu)/|BM_filter_step/(opencl|vulkan|opencl_multigrid|vulkan_multigrid)_liver_fine_38144/|BM_ensemble_step/(opencl|vulkan)_multigrid_(liver_4768|liver_fine_38144|box_large_117240)/|BM_filter_step_parameters/(opencl|vulkan)/|BM_filter_step/vulkan_(texel|storage)_reads/|BM_ensemble_step/vulkan_(texel|storage)_reads_liver_4768/' \
  --benchmark_min_time=0.3 --benchmark_out="$out/bench.json" --benchmark_out_format=json \
  >"$out/bench.log" 2>&1
code=$?
echo "benchmarks exit $code"
[ $code -eq 0 ] || status=1
cat "$out/bench.log"

# Last, as it is the longest: diagnose on the liver with the OpenCL ensemble (end to end).
echo "== diagnose on OpenCL (limit ${SIGMAFEM_GPU_DIAGNOSE_LIMIT:-100} s)"
SIGMAFEM_TESTS_REQUIRE=all timeout "${SIGMAFEM_GPU_DIAGNOSE_LIMIT:-100}" "$build/tests/sigmafem_tests" \
  --gtest_filter='DiagnoseLiverOnOpenCl.*' --gtest_output="xml:$out/diagnose.xml" \
  >"$out/diagnose.log" 2>&1
code=$?
echo "diagnose exit $code"
[ $code -eq 0 ] || status=1
grep -E '^\[ +(OK|FAILED) ' "$out/diagnose.log"
exit $status
