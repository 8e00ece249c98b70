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
# without NDEBUG so that every PT_DCHECK runs too. Lavapipe's JIT does not run under ASan, so
# the Vulkan tests (and the Slurm cluster test) stay in the normal run above.
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DPT_SANITIZE=ON
cmake --build build-asan --target pt_tests
ctest --test-dir build-asan --output-on-failure -j "$(nproc)" -E 'Vulkan|GpuTraversal' -LE slurm
