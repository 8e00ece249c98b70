#!/usr/bin/env bash
# Sets up, builds and renders the canonical Cornell box to out/cornell-box.{png,exr}.
# Uses the Vulkan backend when a GPU is present; on a machine without one, the CPU reference
# is about twice as fast as lavapipe (software Vulkan), so it uses that. Extra arguments
# go to `pt render` (e.g. --spp 4096, or --backend vulkan to force lavapipe).
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build --target pt
mkdir -p out
backend=cpu
if build/pt devices 2>/dev/null | grep -qv '(cpu;'; then backend=vulkan; fi
echo "rendering with --backend $backend" >&2
build/pt render configs/cornell-box.json --backend "$backend" \
  --out out/cornell-box.png --out out/cornell-box.exr "$@"
