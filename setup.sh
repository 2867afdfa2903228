#!/usr/bin/env bash
# sigmafem set-up on a Debian machine (bookworm or later):
#   ./setup.sh run    install what is missing, build, run the main job on the default scenario
#   ./setup.sh test   install what is missing, build, run the whole test suite: a Release build
#                     with warnings as errors and every test, then the readers' fuzzers
#                     (SIGMAFEM_FUZZ_SECONDS each, default 10): what CI runs (.ci/run)
#   ./setup.sh sanitize  install what is missing, build with AddressSanitizer and
#                     UndefinedBehaviorSanitizer (clang: a second compiler's warnings too), run
#                     the tests that fit under them. Not in the test command since stop 33:
#                     with it the command took 20 minutes, against 15 asked (README, Set-up).
# Debian packages are the only dependencies; apt-get runs only when one is missing (through
# sudo when not root).
set -euo pipefail
cd "$(dirname "$0")"
mode=${1:-run}
case "$mode" in run|test|sanitize) ;; *) echo "usage: ./setup.sh run|test|sanitize" >&2; exit 2 ;; esac

# Each step prints its start time from the beginning, and the test command ends with the time
# of each step (the README quotes them).
step_names=(); step_seconds=(); step_started=$SECONDS
clock() { printf '%d:%02d' $(($1 / 60)) $(($1 % 60)); }
step() {
  if [ ${#step_names[@]} -gt 0 ]; then step_seconds+=($((SECONDS - step_started))); fi
  step_started=$SECONDS
  [ $# -eq 0 ] && return
  step_names+=("$1")
  echo "== [$(clock "$SECONDS")] $1"
}

# OpenCL: the ICD loader and C++ headers to build; PoCL runs the kernels on any CPU (a GPU
# vendor's driver, where there is one, is picked up by the same loader).
# Vulkan: headers and loader, glslang to compile the shaders at build time, Mesa's lavapipe
# to run them on any CPU, and the Khronos validation layer that the tests switch on.
# Open MPI: `mpirun -n R sigmafem estimate` spreads the sigma points over R ranks (the tests
# run 1 to 3 ranks on this machine).
packages="g++ cmake ninja-build pkg-config libeigen3-dev libmetis-dev nlohmann-json3-dev libcli11-dev
          libgtest-dev libbenchmark-dev gnuplot-nox
          ocl-icd-opencl-dev opencl-clhpp-headers pocl-opencl-icd
          libvulkan-dev glslang-tools mesa-vulkan-drivers vulkan-validationlayers
          libopenmpi-dev openmpi-bin"
# The tests also fuzz the input readers with clang and libFuzzer (tests/fuzz/), and the
# sanitizer tier is built with clang.
[ "$mode" != run ] && packages="$packages clang libclang-rt-dev"
missing=""
for p in $packages; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'ok installed' || missing="$missing $p"
done
if [ -n "$missing" ]; then
  step "installing:$missing"
  sudo=""; [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing
fi

jobs=$(nproc 2>/dev/null || echo 2)
# Unity builds (CMake puts 8 sources in one translation unit) parse Eigen, gtest and the
# standard headers once per 8 files instead of once per file: on 2 cores the Release build
# took 3:00 instead of 4:30, the sanitizer build 5:32 instead of 8:05 (stop 32).
unity=-DCMAKE_UNITY_BUILD=ON
# A test whose device, fp64, gnuplot, validation layer or shared data is missing fails
# instead of skipping (tests/requirement.h): the packages above provide them all.
export SIGMAFEM_TESTS_REQUIRE=all

if [ "$mode" != sanitize ]; then
step "building (Release, warnings as errors)"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DSIGMAFEM_WERROR=ON $unity >/dev/null
cmake --build build -j "$jobs"

if [ "$mode" = run ]; then
  step "main job: sigmafem demo box"
  exec build/sigmafem demo box
fi

step "tests (Release)"
ctest --test-dir build --output-on-failure -j "$jobs"
fuzz_seconds=${SIGMAFEM_FUZZ_SECONDS:-10}
step "building the input readers' fuzzers (clang, libFuzzer, ASan and UBSan)"
cmake -S tests/fuzz -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ \
  -DSIGMAFEM_FUZZ_SECONDS="$fuzz_seconds" >/dev/null
cmake --build build-fuzz -j "$jobs"
step "fuzzing the input readers ($fuzz_seconds s each)"
ctest --test-dir build-fuzz --output-on-failure -j "$jobs"

else
step "building with AddressSanitizer and UndefinedBehaviorSanitizer (clang)"
# -O1 -g1: the optimisation AddressSanitizer's authors recommend, and line tables only, all a
# report's stack trace needs. With full -g this build took about 15 minutes on 2 cores, with -O2 -g1 11 min 42 s, with -O1 -g1 9 min
# 14 s (fresh machine, stop 30), 6:01 as a unity build (stop 32). Clang compiles it in two
# thirds of GCC's time (3:40 against 5:32 on the 2-core machine, stop 33; the tests below take
# the same 2 minutes), and its warnings, as errors here, add to GCC's in the Release build.
# Precompiled headers (Eigen, gtest, JSON) gained nothing over the unity build (3:43).
cmake -S . -B build-sanitize -G Ninja -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSIGMAFEM_WERROR=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DSIGMAFEM_SANITIZE=ON -DSIGMAFEM_BENCH=OFF $unity >/dev/null
cmake --build build-sanitize -j "$jobs"
step "tests (sanitizers)"
# The 1500-step box estimations run about 30x slower under the sanitizers (over 13 minutes
# each on 2 cores; so would the 2000-step liver ones, LiverEstimation and the 0.5 mm
# NoisyEstimation, the 1000-step surface-cloud ones, LiverCloudEstimation, and the Truth Cube's
# 600-step runs on 3072 tetrahedra, TruthCube); they run in the
# test command's Release build, and EstimationLoop covers the same code here in 80 steps (the
# CLI's 30-step surface-cloud runs and the point-cloud unit tests the cloud's code), and so does the bounded-history check (EstimationHistory: two
# 300-step box runs). Likewise the device conformance tests whose time goes into long
# CPU-reference runs (100-step trajectories and the reference they share, conformance_reference;
# repeated runs, 16 sigma points, the whole-run
# comparison) run there; the one-step, re-centring and iteration-cap tests with 1 and 4
# sigma points run here and cover the same host code. The residual diagnostics' two 100-step
# box runs (ResidualDiagnosticsBox) run there too; their synthetic tests run here. So do the
# whole diagnoses (DiagnoseBox, DiagnoseLiver: 5 to 20 filter runs each) and the Vulkan-against-OpenCL
# comparison (of two trajectories that trajectory cases keep; no host code of its own), the
# convergence of the refined truth (two runs on the box_diagnose mesh refined twice), the CLI's
# short diagnose, the SOFA comparison (the CPU reference's 2000-step runs, which the
# estimation tests here drive too), the filter and diagnose on SOFA's data (SofaData: whole
# diagnoses of 600-1000 steps; the claim checks they reach run here in ModelFormClaim) and the float64 Vulkan conformance cases (lavapipe's
# software doubles; VulkanSingle runs the same host code here). Left out when this tier was
# part of the test command, which took 28 minutes on 2 cores with them (stop 30).
# Vulkan on lavapipe runs under the sanitizers as it is: Mesa is not instrumented, and the
# Vulkan device holds one instance for the process so that the loader does not unload Mesa
# under its one-time allocations (host/vulkan/vulkan_device.cpp), which LeakSanitizer would
# otherwise report from an unloaded module. The ctest vulkan_validation (in the test command)
# is left out here: with the validation layer (loaded and unloaded with each instance) LeakSanitizer
# reports, at exit, allocations made by Mesa's LLVM and by modules already unloaded: none in
# sigmafem's code, and none it could free.
# intercept_tls_get_addr=0: GCC 12's sanitizer runtime (and LLVM's up to 16) takes a dynamic TLS
# block that happens to start 16 bytes past a page boundary for a pre-2.25 glibc header and
# reads garbage from before it; LeakSanitizer's tracer then crashes at exit ("Tracer caught
# signal 11"), with no leak found. Whether a block lands there depends on the heap's layout,
# so one build crashed on every OpenCL liver case (PoCL's libraries have dynamic TLS) and the
# next on none.
# VulkanLoopTurnsTest (the 38k liver's factor analysis and CPU reference run, 14 s in Release)
# runs in the test command; VulkanDeviceTest.CgGroupsGrowToKeepWithinTheLoopTurns covers the same
# host code here.
# DistributedEstimation (mpirun of the sanitized program) is left out: Open MPI's start-up
# keeps allocations to exit that LeakSanitizer would report; the test command runs it.
# tests/sanitizers/lsan.supp: PoCL's and LLVM's own allocations when PoCL compiles a kernel
# (a fresh machine's empty kernel cache), kept until exit; it says why.
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
LSAN_OPTIONS=suppressions="$PWD/tests/sanitizers/lsan.supp" \
  ctest --test-dir build-sanitize --output-on-failure -j "$jobs" \
  -E 'conformance_reference|TruthMeshTest.SpreadSprings|BoxEstimation|LiverEstimation|LiverCloudEstimation|TruthCube|NoisyEstimation|EstimationHistory|ResidualDiagnosticsBox|DiagnoseBox|DiagnoseLiver|CliTest.Diagnose|SofaReference|SofaData|WholeRun|VulkanAgainstOpenCl|vulkan_validation|Conformance.*(Trajectory|TwoRuns|_S16|VulkanDouble)|DistributedEstimation|VulkanLoopTurnsTest'
fi
step
echo "== passed in $(clock "$SECONDS"):"
for i in "${!step_names[@]}"; do echo "   $(clock "${step_seconds[$i]}")  ${step_names[$i]}"; done
