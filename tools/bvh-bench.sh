#!/usr/bin/env bash
# BVH build benchmark: builds bench/bvh_build_bench (needs Embree 3: tools/setup.sh) and runs
# it on the generated sphere, the bunny and the dragon. Build times are medians of RUNS runs,
# ours warm (repeated builds in one process) and cold (a fresh process per build, as `pt
# render` builds), with the CPU backend's collapse to the wide tree, next to Embree's build in
# the same run timed as Embree's authors time it (shared vertices, rtcCommitScene alone, after
# a warm-up build) and next to Embree's own `buildbench` (embree-tools) on the same mesh files,
# which bvh_build_bench runs once per run and parses (see runBuildbench there); also SAH costs
# and CPU trace speed. Then the seed's scene through `pt`: load time, build time, SAH cost and
# time to an image per builder. The date and the load average before and after say how busy
# the machine was (the ratios move with it).
#   tools/bvh-bench.sh [DRAGON_PLY]     (default assets/dragon_vrip.ply: tools/fetch-assets.sh)
# Environment: BUILD (build directory, default build), RUNS (default 5), RAYS (default 200000),
# SEED_SPP (samples per pixel of the seed scene's renders, default 16), SKIP_BENCH=1 (only the
# seed scene part).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD:-build}
dragon=${1:-assets/dragon_vrip.ply}
[ -f "$build/build.ninja" ] || cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
if ! cmake --build "$build" --target bvh_build_bench pt; then
  echo "bvh-bench: bvh_build_bench or pt not built (see above; CMake builds bvh_build_bench" \
    "only where Embree 3 is found: libembree-dev)" >&2
  exit 1
fi
printf 'bvh-bench: %s, %s cores, load average before: %s\n' "$(date -u '+%Y-%m-%d %H:%M UTC')" \
  "$(nproc)" "$(cut -d' ' -f1-3 /proc/loadavg)"
if [ -z "${SKIP_BENCH:-}" ]; then
  buildbench=()
  if command -v buildbench >/dev/null; then
    buildbench=(--buildbench "$(command -v buildbench)")
  else
    echo "bvh-bench: Embree's buildbench not found (embree-tools): its column stays empty" >&2
  fi
  "$build/bench/bvh_build_bench" --dragon "$dragon" --runs "${RUNS:-5}" --rays "${RAYS:-200000}" \
    "${buildbench[@]}"
  printf 'bvh-bench: load average after the build benchmark: %s\n' \
    "$(cut -d' ' -f1-3 /proc/loadavg)"
fi

# The seed's scene through `pt` itself, per builder: load time (PLY dragon + OBJ bunny), build
# time, SAH cost, and the time to an image (build + CPU render, 256x256 at SEED_SPP samples per
# pixel), medians of RUNS runs, builders alternated within each run. What chooses the default.
scene=configs/bunny-dragon.json
spp=${SEED_SPP:-16}
runs=${RUNS:-5}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
field() { sed -n "s|.* $1=\([^ ]*\).*|\1|p"; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
builders=(lbvh ploc sah)
for i in $(seq "$runs"); do
  for b in "${builders[@]}"; do
    "$build/pt" render "$scene" --backend cpu --builder "$b" --width 256 --height 256 \
      --spp "$spp" --out "$out/img.exr" 2>/dev/null >"$out/$b.$i"
  done
done
printf '\n%s, CPU render 256x256 at %s spp, %s threads, medians of %s runs\n' "$scene" "$spp" \
  "$(nproc)" "$runs"
printf '%-6s %8s %10s %10s %12s %10s %14s\n' builder load_s build_s sah_cost render_s Mrays/s \
  build+render_s
for b in "${builders[@]}"; do
  load=$(cat "$out/$b".* | field load_s | median)
  build_s=$(cat "$out/$b".* | field bvh_build_s | median)
  sah=$(cat "$out/$b".* | field bvh_sah_cost | median)
  render=$(cat "$out/$b".* | field seconds | median)
  mrays=$(cat "$out/$b".* | field 'Mrays/s' | median)
  total=$(for f in "$out/$b".*; do
    awk -v b="$(field bvh_build_s <"$f")" -v r="$(field seconds <"$f")" 'BEGIN {print b + r}'
  done | median)
  printf '%-6s %8s %10s %10s %12s %10s %14s\n' "$b" "$load" "$build_s" "$sah" "$render" "$mrays" \
    "$total"
done
printf 'bvh-bench: load average at the end: %s\n' "$(cut -d' ' -f1-3 /proc/loadavg)"
