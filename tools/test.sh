#!/usr/bin/env bash
# Sets up (installs Debian packages), builds and runs the whole test suite, then the CPU tests
# again under the sanitizers. The fuzz regression replay is part of the suite.
set -euo pipefail
cd "$(dirname "$0")/.."
# The packages the build and the suite use (tools/setup.sh installs the fuzzers' and plots' too).
tools/setup.sh --tests
# Unity builds: a fresh clone builds in 35-40 % less CPU time (CMakeLists.txt, README).
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON
# One compile per core: Ninja's default on 2 cores is 3 jobs, and the third costs more than it
# gives (the checked build: 259 s wall, 492 CPU-s with 3 jobs; 238 s, 436 CPU-s with 2).
cmake --build build -j "$(nproc)"
# The tests run with glibc's allocator tuned for lavapipe's shader compiles, which allocate and
# free large blocks many times over: blocks up to 32 MiB (the most glibc allows) come from the
# heap rather than from fresh zeroed pages of the kernel each time, the heap is not trimmed, and
# it sits on transparent huge pages. The lavapipe tests of media and glTF textures (ctest -R,
# empty Mesa cache, medians of 3-4): 35.8 s -> 23.3 s wall. The compilers gain nothing from it
# and the sanitized run below has ASan's own allocator.
# The suite's compiled shaders (vulkan/spirv_cache.h) go to a cache of its own, emptied
# first: each variant is compiled once per run whatever the user's cache holds, and then
# shared by the tests' processes (the sanitized run's too).
export PT_SHADER_CACHE_DIR="$PWD/build/shader-cache"
rm -rf "$PT_SHADER_CACHE_DIR"
# The Slurm test (a private cluster renders a job array; ctest -L slurm) spends its 25-35 s
# mostly waiting (apt, the daemons, the queue: 8 CPU-s), so it runs beside the others rather
# than in one of ctest's slots; exit status 77 is its "skipped".
slurmLog=$(mktemp)
tests/slurm_test.sh build/pt >"$slurmLog" 2>&1 &
slurmPid=$!
failed=0
GLIBC_TUNABLES=glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=4294967295 \
  ctest --test-dir build --output-on-failure -j "$(nproc)" -LE slurm || failed=1
slurmStatus=0
wait "$slurmPid" || slurmStatus=$?
cat "$slurmLog"
rm -f "$slurmLog"
case $slurmStatus in
  0) echo "SlurmJobArray: passed" ;;
  77) echo "SlurmJobArray: skipped" ;;
  *)
    echo "SlurmJobArray: FAILED (exit status $slurmStatus)"
    failed=1
    ;;
esac
[ "$failed" = 0 ]

# The CPU side again under AddressSanitizer + UndefinedBehaviorSanitizer (docs/errors.md),
# without NDEBUG so that every PT_DCHECK runs too. Tests that render on lavapipe (their names
# match $lavapipe) stay in the normal run above: under ASan their CPU halves take minutes.
# The Vulkan driver is hidden from this run, so a test that renders on lavapipe without
# saying so in its name fails here ("no Vulkan driver found") and gets renamed, rather than
# slowing this run unnoticed. One small render on lavapipe does run under ASan, for the host
# side of the Vulkan backend (uploads, batches, read-back); tests/lavapipe_under_asan_test.cpp
# keeps the driver loaded so that LeakSanitizer can see what lavapipe's LLVM still holds.
# Line tables only (-g1): the sanitizers' reports name file and line, and the build takes
# 15-30 % less time per file than with full debug information. The shaders were checked by
# the first build (PT_CHECK_SHADERS).
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DPT_SANITIZE=ON -DCMAKE_UNITY_BUILD=ON \
  -DPT_CHECK_SHADERS=OFF
cmake --build build-asan --target pt_tests -j "$(nproc)"
# The sanitized tests run in two processes per core, GoogleTest's shards (GTEST_TOTAL_SHARDS),
# not in a process per test as ctest runs them: a sanitized process takes 0.17 s to start and
# exit (its instrumented globals, LeakSanitizer's scan), 520 times a run. Two per core, since
# the shards are uneven (2 shards: the last ended 20 s after the first; 4: 131 s against
# 170 s for the whole run, 2 cores). The normal run above
# keeps each test in a process of its own, so a test that passes only after another is caught
# there. A shard that fails prints its whole log (the failing test's name, the report).
# ray_bench and the Slurm test (ctest labels bench, slurm) are not run here.
# The same names as CMakeLists.txt's PT_LAVAPIPE_TEST_NAME (files of such tests only are not
# compiled into this build).
lavapipeTests='*Vulkan*:*GpuTraversal*:*BothBackends*:*OnVulkan*'
shards=$((2 * $(nproc)))
logs=$(mktemp -d)
pids=()
for ((i = 0; i < shards; ++i)); do
  (cd build-asan && VK_DRIVER_FILES=/nonexistent VK_ICD_FILENAMES=/nonexistent \
    GTEST_TOTAL_SHARDS=$shards GTEST_SHARD_INDEX=$i \
    timeout 1800 ./pt_tests --gtest_filter="-$lavapipeTests") >"$logs/shard-$i.log" 2>&1 &
  pids+=($!)
done
for ((i = 0; i < shards; ++i)); do
  if wait "${pids[$i]}"; then
    echo "sanitized shard $((i + 1))/$shards: $(grep -E '^\[  PASSED  \]' "$logs/shard-$i.log")"
  else
    cat "$logs/shard-$i.log"
    echo "sanitized shard $((i + 1))/$shards FAILED"
    failed=1
  fi
done
rm -rf "$logs"
[ "$failed" = 0 ]
ctest --test-dir build-asan --output-on-failure -R '^Vulkan\.CornellBoxMatchesCpuReference$'
