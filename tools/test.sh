#!/usr/bin/env bash
# Sets up (installs Debian packages), builds and runs the whole test suite, then the CPU tests
# again under the sanitizers. The fuzz regression replay is part of the suite.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
# Unity builds: a fresh clone builds in 35-40 % less CPU time (CMakeLists.txt, README).
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON
cmake --build build
ctest --test-dir build --output-on-failure -j "$(nproc)"

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
cmake --build build-asan --target pt_tests
lavapipe='Vulkan|GpuTraversal|BothBackends|OnVulkan'
# ray_bench (label bench) is not built here: only pt_tests is.
VK_DRIVER_FILES=/nonexistent VK_ICD_FILENAMES=/nonexistent \
  ctest --test-dir build-asan --output-on-failure -j "$(nproc)" -E "$lavapipe" -LE 'slurm|bench'
ctest --test-dir build-asan --output-on-failure -R '^Vulkan\.CornellBoxMatchesCpuReference$'
