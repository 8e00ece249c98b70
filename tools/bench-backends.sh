#!/usr/bin/env bash
# Side-by-side throughput of the backends on one machine, in one run (ratios only hold when
# taken together on these shared machines). Prints a table of medians of N runs each.
#   tools/bench-backends.sh [SCENE] [SIZE] [CPU_SPP] [GPU_SPP] [RUNS]
# Environment: THREADS (CPU threads and LP_NUM_THREADS for lavapipe, default: all cores).
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-configs/cornell-box.json}
size=${2:-256}
cpu_spp=${3:-256}
gpu_spp=${4:-64}
runs=${5:-3}
threads=${THREADS:-$(nproc)}
pt=${PT:-build/pt}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

field() { sed -n "s|.* $1=\([^ ]*\).*|\1|p"; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }

declare -A secs mrays
run() {  # label, then pt arguments
  local label=$1; shift
  for i in $(seq "$runs"); do
    LP_NUM_THREADS=$threads "$pt" render "$scene" --width "$size" --height "$size" \
      --out "$out/img.exr" "$@" 2>/dev/null >"$out/$label.$i"
  done
  secs[$label]=$(cat "$out/$label".* | field seconds | median)
  mrays[$label]=$(cat "$out/$label".* | field 'Mrays/s' | median)
  echo "$label: $(head -1 "$out/$label.1")" >&2
}

run cpu --backend cpu --threads "$threads" --spp "$cpu_spp"
run vulkan --backend vulkan --spp "$gpu_spp"
run vulkan-unspecialized --backend vulkan --spp "$gpu_spp" --no-specialize

printf '\n%s at %sx%s, %s threads, median of %s runs\n' "$scene" "$size" "$size" "$threads" "$runs"
printf '%-22s %10s %10s\n' backend seconds Mrays/s
for l in cpu vulkan vulkan-unspecialized; do
  printf '%-22s %10s %10s\n' "$l" "${secs[$l]}" "${mrays[$l]}"
done
awk -v a="${mrays[vulkan]}" -v b="${mrays[vulkan-unspecialized]}" \
  'BEGIN {printf "specialization speed-up (Mrays/s ratio): %.3f\n", a / b}'
