#!/usr/bin/env bash
# Sets up (installs Debian packages), builds and runs the whole test suite, then the CPU tests
# again under the sanitizers. The fuzz regression replay is part of the suite.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build
ctest --test-dir build --output-on-failure -j "$(nproc)"

# The CPU side again under AddressSanitizer + UndefinedBehaviorSanitizer (docs/errors.md),
# without NDEBUG so that every PT_DCHECK runs too. The Vulkan tests proper (and the Slurm
# cluster test) stay in the normal run above: they pass under ASan but take long there.
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DPT_SANITIZE=ON
cmake --build build-asan --target pt_tests
vulkan='Vulkan|GpuTraversal'
both='Robust|SeedScene'  # CPU tests that also render on lavapipe to compare
# ray_bench (label bench) is not built here: only pt_tests is. The other tests that render on
# lavapipe run here with leak detection on: tests/lavapipe_under_asan_test.cpp keeps the
# driver loaded, so what its LLVM holds at exit stays reachable.
ctest --test-dir build-asan --output-on-failure -j "$(nproc)" -E "$vulkan|$both" -LE 'slurm|bench'
# Lavapipe's LLVM leaks 128 bytes in a library the driver unloads before LeakSanitizer can
# name it, so leak detection is off for these; memory errors and undefined behaviour still fail.
ASAN_OPTIONS=detect_leaks=0 ctest --test-dir build-asan --output-on-failure -j "$(nproc)" \
  -R "$both" -E "$vulkan"
