#!/usr/bin/env bash
# Sets up, builds and renders the canonical Cornell box to out/cornell-box.{png,exr}.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build --target pt
mkdir -p out
build/pt render configs/cornell-box.json --out out/cornell-box.png --out out/cornell-box.exr "$@"
