#!/usr/bin/env bash
# On a machine with an NVIDIA GPU (and its Vulkan driver): the CPU/GPU agreement tests on the
# GPU, then the Cornell box at 1024x1024 on the GPU and on the CPU reference with every core,
# in one run, so the ratio holds. Expects a build in build/ (pt and pt_tests) made on an
# x86-64 Debian 12 machine; needs only libvulkan1 at run time.
#   tools/gpu-check.sh [GPU_SPP] [CPU_SPP]
set -euo pipefail
cd "$(dirname "$0")/.."
gpu_spp=${1:-1024}
cpu_spp=${2:-16}
out=${OUT:-$(mktemp -d)}

# The tests find configs/ and build/pt by the absolute paths they were built with: when this
# checkout lives elsewhere (a copy sent to another machine), link that path to it.
built=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' build/CMakeCache.txt 2>/dev/null || true)
if [ -n "$built" ] && [ ! -e "$built" ]; then
  mkdir -p "$(dirname "$built")" && ln -s "$PWD" "$built"
fi

build/pt devices
# Agreement with the CPU reference and the device traversal tests, validation off (the
# layers may be missing there).
PT_NO_VALIDATION=1 build/pt_tests --gtest_filter='Vulkan.*:VulkanLoopCap.*:GpuTraversal.*' 2>&1 |
  tail -20

build/pt render configs/cornell-box.json --width 1024 --height 1024 --spp "$gpu_spp" \
  --out "$out/gpu-1024.exr" | tee "$out/gpu.txt"
build/pt render configs/cornell-box.json --backend cpu --width 1024 --height 1024 \
  --spp "$cpu_spp" --out "$out/cpu-1024.exr" | tee "$out/cpu.txt"

field() { sed -n "s|.* $1=\([^ ]*\).*|\1|p" "$2"; }
g=$(field 'Mrays/s' "$out/gpu.txt")
c=$(field 'Mrays/s' "$out/cpu.txt")
printf '\n%-8s %14s\n' backend 'Grays/s'
awk -v g="$g" -v c="$c" 'BEGIN {
  printf "%-8s %14.4f\n%-8s %14.4f\nGPU / CPU: %.1f\n", "gpu", g / 1000, "cpu", c / 1000, g / c }'
