#!/usr/bin/env bash
# The release binary against fuzz corpora, as a user would run it: `pt render` on every scene
# file, and on a fixed scene whose OBJ, PLY or MTL file is each corpus file in turn; `pt diff`
# on every image file. Every run must exit 0 or 2 (diff: 0, 1 or 2) without a signal, a
# refusal (status 2) must print exactly one line on stderr, and a refused render must leave
# no output file. Prints the counts and every violation; exits 1 if there was any.
#   tools/cli-sweep.sh [CORPUS_DIR...]   (default: fuzz/corpus tests/data/fuzz-regressions;
#                                         each holds scene/ obj/ ply/ mtl/ image/ subfolders)
# Environment: BUILD (build directory, default build), TIMEOUT (seconds per run, default 20).
set -uo pipefail
cd "$(dirname "$0")/.."
root=$PWD
pt=$root/${BUILD:-build}/pt
timeout=${TIMEOUT:-20}
[[ -x $pt ]] || { echo "cli-sweep: $pt not built (cmake --build build)" >&2; exit 2; }
(($#)) || set -- fuzz/corpus tests/data/fuzz-regressions
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The fixed scene around the mesh and material files: the Cornell-style OBJ+MTL box of the
# tests (for the MTL files), and copies with one plain material that load the mesh from the
# OBJ or from a PLY file.
cp tests/data/scene/mtl/box.json tests/data/scene/mtl/box.obj tests/data/scene/mtl/box.mtl "$work/"
sed 's/"type": *"obj"/"type": "ply"/; s/box\.obj/box.ply/; s/"materials": *"mtl"/"material": "white"/' \
  "$work/box.json" >"$work/box-ply.json"
sed 's/"materials": *"mtl"/"material": "white"/' "$work/box.json" >"$work/box-obj.json"
"$pt" render "$work/box.json" --backend cpu --width 8 --height 8 --spp 1 \
  --out "$work/ref.exr" >/dev/null 2>&1 || { echo "cli-sweep: the fixed scene does not render" >&2; exit 2; }
# The meshes the scene corpus names (the fuzz target's fixed files, fuzz/fuzz_entry.cpp).
printf 'mtllib mesh.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl red\nf 1 2 3\nusemtl lamp\nf 1 3 4\n' \
  >"$work/mesh.obj"
printf 'newmtl red\nKd 0.8 0.1 0.1\nnewmtl lamp\nKd 0 0 0\nKe 4 4 4\n' >"$work/mesh.mtl"
printf '%s\n' ply 'format ascii 1.0' 'element vertex 4' 'property float x' 'property float y' \
  'property float z' 'element face 1' 'property list uchar int vertex_indices' end_header \
  '0 0 0' '1 0 0' '1 1 0' '0 1 0' '4 0 1 2 3' >"$work/mesh.ply"
cp "$work/box.obj" "$work/box.obj.orig"
cp "$work/box.mtl" "$work/box.mtl.orig"

runs=0 violations=0
declare -A counts
check() {  # kind file allowed-statuses command...
  local kind=$1 file=$2 allowed=$3
  shift 3
  rm -f "$work/out.exr"
  timeout "$timeout" "$@" >"$work/stdout" 2>"$work/stderr"
  local rc=$? lines
  lines=$(wc -l <"$work/stderr")
  runs=$((runs + 1))
  counts["$kind status $rc"]=$((${counts["$kind status $rc"]:-0} + 1))
  local why=""
  [[ " $allowed " == *" $rc "* ]] || why="exit status $rc"
  ((rc == 124)) && why="timed out after ${timeout}s"
  ((rc == 2 && lines != 1)) && why="$lines lines on stderr for a refusal"
  [[ $rc != 0 && -e $work/out.exr ]] && why="output file left by a failed render"
  if [[ -n $why ]]; then
    violations=$((violations + 1))
    echo "VIOLATION $kind $file: $why: $(head -c 300 "$work/stderr")"
  fi
}

for dir in "$@"; do
  for f in "$dir"/scene/*; do
    [[ -f $f ]] || continue
    # A scene from the corpus, beside the fixed mesh files it may name.
    cp "$f" "$work/scene.json"
    check scene "$f" "0 2" "$pt" render "$work/scene.json" --backend cpu --width 8 --height 8 \
      --spp 1 --threads 1 --out "$work/out.exr"
  done
  for f in "$dir"/pbrt/*; do
    [[ -f $f ]] || continue
    # A pbrt-v4 scene file from the corpus (the meshes it names are the fixed ones, if any).
    cp "$f" "$work/scene.pbrt"
    check pbrt "$f" "0 2" "$pt" render "$work/scene.pbrt" --backend cpu --width 8 --height 8 \
      --spp 1 --threads 1 --out "$work/out.exr"
  done
  # Each mesh or material file in turn in place of the fixed scene's own.
  for kind_scene in obj:box-obj.json ply:box-ply.json mtl:box.json; do
    kind=${kind_scene%%:*} scene=${kind_scene#*:}
    for f in "$dir/$kind"/*; do
      [[ -f $f ]] || continue
      cp "$f" "$work/box.$kind"
      check "$kind" "$f" "0 2" "$pt" render "$work/$scene" --backend cpu --threads 1 \
        --out "$work/out.exr"
    done
    [[ -f $work/box.$kind.orig ]] && cp "$work/box.$kind.orig" "$work/box.$kind"
  done
  for f in "$dir"/image/*; do
    [[ -f $f ]] || continue
    # The extension a user's file would have, from the magic number (as the fuzz target does).
    magic=$(head -c 4 "$f" | od -An -tx1 | tr -d ' \n')
    ext=png
    [[ $magic == 5046* || $magic == 5066* ]] && ext=pfm  # "PF", "Pf"
    [[ $magic == 762f3101 ]] && ext=exr
    cp "$f" "$work/image.$ext"
    check image "$f" "0 1 2" "$pt" diff "$work/image.$ext" "$work/ref.exr"
  done
done

for key in "${!counts[@]}"; do echo "${counts[$key]} $key"; done | sort -k2
echo "cli-sweep: $runs runs, $violations violations"
((violations == 0))
