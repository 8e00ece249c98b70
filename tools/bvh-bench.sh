#!/usr/bin/env bash
# BVH build benchmark: builds bench/bvh_build_bench (needs Embree 3: tools/setup.sh) and runs
# it on the generated sphere, the bunny and the dragon. Build times are medians of RUNS runs
# next to Embree's own build in the same run; also SAH costs and CPU trace speed.
#   tools/bvh-bench.sh [DRAGON_PLY]     (default assets/dragon_vrip.ply: tools/fetch-assets.sh)
# Environment: BUILD (build directory, default build), RUNS (default 5), RAYS (default 200000).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD:-build}
dragon=${1:-assets/dragon_vrip.ply}
[ -f "$build/build.ninja" ] || cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
if ! cmake --build "$build" --target bvh_build_bench; then
  echo "bvh-bench: bvh_build_bench not built (CMake builds it only where Embree 3 is found:" \
    "libembree-dev)" >&2
  exit 1
fi
"$build/bench/bvh_build_bench" --dragon "$dragon" --runs "${RUNS:-5}" --rays "${RAYS:-200000}"
