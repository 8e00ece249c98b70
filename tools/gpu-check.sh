#!/usr/bin/env bash
# The speed issue's GPU figures and the GPU's agreement with the CPU reference, on a machine
# with an NVIDIA GPU (and its Vulkan driver), in one run:
#  - the agreement and device traversal tests (validation off: the layers may be missing);
#  - the Cornell box and the seed's scene (bunny and dragon, when its meshes are at hand) at
#    1024x1024, each on the GPU (GPU_SPP) and on the CPU reference with every core (CPU_SPP),
#    so that the GPU/CPU ratio is taken on one machine in one run; and on the GPU once more
#    with one sample per dispatch (--samples-per-pass 1: no path regeneration), to tell what
#    regeneration is worth there;
#  - `pt diff` of the GPU's image against the CPU's at CPU_SPP: the same samples, so what
#    differs is floating-point divergence;
#  - the ray benchmark (build/bench/ray_bench, where it was built) on the Cornell box, the
#    1M-triangle sphere and the seed's scene: the GPU's ray queries against our CPU traversal
#    and Embree on every core, with its agreement check.
#
# That machine may have neither this machine's libraries nor the meshes. On the build machine,
#   tools/gpu-check.sh --bundle
# copies the shared libraries that build/pt, build/pt_tests and build/bench/ray_bench load
# (the largest, Embree's, gzipped), the Vulkan loader and the dynamic loader into
# out/gpu-bundle/lib, and the seed scene's meshes, gzipped, into out/gpu-bundle (about 30 MB in
# all; with build/, about 55 of the 64 MiB a run may carry). Send build/ and out/gpu-bundle
# with the checkout; there,
#   tools/gpu-check.sh [GPU_SPP] [CPU_SPP]          (SIZE=512: another resolution)
# runs the binaries through the bundled dynamic loader when out/gpu-bundle exists, so they need
# nothing from the machine but its Vulkan driver. Results go to $OUT (default: a temporary
# directory); a table comes last. The whole run takes a few minutes on an H100-class GPU
# with 16 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
bundle=out/gpu-bundle
size=${SIZE:-1024}

if [ "${1:-}" = "--bundle" ]; then
  rm -rf "$bundle"
  mkdir -p "$bundle/lib"
  # Every library the binaries load, by the name they ask for, and libvulkan, which the
  # Vulkan-Hpp dispatcher opens at run time.
  binaries=(build/pt build/pt_tests)
  [ -x build/bench/ray_bench ] && binaries+=(build/bench/ray_bench)
  libs=$(ldd "${binaries[@]}" | awk '$2 == "=>" && $3 ~ /^\// {print $1 " " $3}' | sort -u)
  vulkan=$(ldconfig -p | awk '$1 == "libvulkan.so.1" {print $NF; exit}')
  [ -n "$vulkan" ] || { echo "gpu-check: libvulkan.so.1 not found (Debian: libvulkan1)" >&2; exit 1; }
  while read -r name path; do cp -L "$path" "$bundle/lib/$name"; done <<<"$libs
libvulkan.so.1 $vulkan"
  cp -L /lib64/ld-linux-x86-64.so.2 "$bundle/lib/"
  # glibc's other libraries, which the binaries do not load but NVIDIA's driver may: from the
  # bundled glibc, not the machine's, whose version may differ.
  libc_dir=$(dirname "$(awk '$1 == "libc.so.6" {print $2}' <<<"$libs")")
  for name in libdl.so.2 libpthread.so.0 librt.so.1; do
    [ -f "$libc_dir/$name" ] && cp -L "$libc_dir/$name" "$bundle/lib/"
  done
  # Libraries above 8 MB (Embree's is 44 MB) travel gzipped; the run unpacks them.
  find "$bundle/lib" -type f -size +8M -exec gzip {} \;
  if [ -f assets/dragon_vrip.ply ] && [ -f /usr/share/glmark2/models/bunny.obj ]; then
    gzip -c assets/dragon_vrip.ply >"$bundle/dragon_vrip.ply.gz"
    gzip -c /usr/share/glmark2/models/bunny.obj >"$bundle/bunny.obj.gz"
  else
    echo "gpu-check: the seed scene's meshes are missing (tools/fetch-assets.sh, glmark2-data);" \
      "the bundle leaves the scene out" >&2
  fi
  du -sh "$bundle"
  exit 0
fi

gpu_spp=${1:-1024}
cpu_spp=${2:-16}
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"

# The binaries, through the bundled loader when there is a bundle.
runner=()
if [ -d "$bundle/lib" ]; then
  for gz in "$bundle"/lib/*.gz; do
    [ -e "$gz" ] && [ ! -e "${gz%.gz}" ] && gunzip -c "$gz" >"${gz%.gz}"
  done
  runner=("$bundle/lib/ld-linux-x86-64.so.2" --library-path "$PWD/$bundle/lib")
fi
run() { "${runner[@]}" "$@"; }

# Some NVIDIA container images keep the driver's ICD file where the Vulkan loader does not look.
nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -z "${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}" ] && [ -f "$nvidia_icd" ]; then
  export VK_DRIVER_FILES=$nvidia_icd
fi

# The tests find configs/ and build/pt by the absolute paths they were built with: when this
# checkout lives elsewhere (a copy sent to another machine), link that path to it.
built=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' build/CMakeCache.txt 2>/dev/null || true)
if [ -n "$built" ] && [ ! -e "$built" ]; then
  mkdir -p "$(dirname "$built")" && ln -s "$PWD" "$built"
fi

# The scenes: the Cornell box, and the seed's scene with its meshes from the bundle or from
# where this machine keeps them.
scenes=(cornell-box)
cp configs/cornell-box.json "$out/cornell-box.json"
if [ -f "$bundle/dragon_vrip.ply.gz" ]; then
  mkdir -p "$out/meshes"
  gunzip -c "$bundle/dragon_vrip.ply.gz" >"$out/meshes/dragon_vrip.ply"
  gunzip -c "$bundle/bunny.obj.gz" >"$out/meshes/bunny.obj"
  sed -e "s|/usr/share/glmark2/models/bunny.obj|$out/meshes/bunny.obj|" \
    -e "s|\.\./assets/dragon_vrip.ply|$out/meshes/dragon_vrip.ply|" \
    configs/bunny-dragon.json >"$out/bunny-dragon.json"
  scenes+=(bunny-dragon)
elif [ -f assets/dragon_vrip.ply ] && [ -f /usr/share/glmark2/models/bunny.obj ]; then
  sed -e "s|\.\./assets/|$PWD/assets/|" configs/bunny-dragon.json >"$out/bunny-dragon.json"
  scenes+=(bunny-dragon)
else
  echo "gpu-check: no meshes for the seed scene; the Cornell box only" >&2
fi

run build/pt devices
PT_NO_VALIDATION=1 run build/pt_tests --gtest_filter='Vulkan.*:VulkanLoopCap.*:GpuTraversal.*' 2>&1 |
  tail -20

field() { sed -n "s|.* $1=\([^ ]*\).*|\1|p" "$2"; }
rows=()
for scene in "${scenes[@]}"; do
  common=("$out/$scene.json" --width "$size" --height "$size")
  run build/pt render "${common[@]}" --spp "$gpu_spp" --out "$out/$scene-gpu.exr" |
    tee "$out/$scene-gpu.txt"
  run build/pt render "${common[@]}" --spp "$gpu_spp" --samples-per-pass 1 \
    --out "$out/$scene-gpu-k1.exr" >"$out/$scene-gpu-k1.txt"
  run build/pt render "${common[@]}" --spp "$cpu_spp" --out "$out/$scene-gpu-$cpu_spp.exr" \
    >"$out/$scene-gpu-$cpu_spp.txt"
  run build/pt render "${common[@]}" --backend cpu --spp "$cpu_spp" \
    --out "$out/$scene-cpu-$cpu_spp.exr" | tee "$out/$scene-cpu.txt"
  diff=$(run build/pt diff "$out/$scene-gpu-$cpu_spp.exr" "$out/$scene-cpu-$cpu_spp.exr" 2>&1 |
    tr '\n' ' ' || true)
  echo "$scene diff: $diff" | tee "$out/$scene-diff.txt"
  relmse=$(sed -n 's/.* relmse=\([^ ]*\).*/\1/p' "$out/$scene-diff.txt")
  device=$(sed -n 's/.* device="\([^"]*\)".*/\1/p' "$out/$scene-gpu.txt" | tr ' ' '_')
  rows+=("$scene $(field 'Mrays/s' "$out/$scene-gpu.txt") $(field 'Mrays/s' "$out/$scene-cpu.txt") \
${device:-?} ${relmse:-?} $(field 'Mrays/s' "$out/$scene-gpu-k1.txt")")
done

# The ray benchmark, bounded in time: the table above comes first in importance.
if [ -x build/bench/ray_bench ]; then
  bench_scenes=cornell-box,sphere
  [ -f "$out/bunny-dragon.json" ] && bench_scenes+=,bunny-dragon
  timeout 420 "${runner[@]}" build/bench/ray_bench --configs "$out" --scenes "$bench_scenes" \
    --csv "$out/ray_bench.csv" >"$out/ray_bench.txt" 2>&1 ||
    echo "gpu-check: ray_bench failed or timed out (see $out/ray_bench.txt)"
  sed -n '/^ray_bench:/p; /^Mrays\/s/,$p' "$out/ray_bench.txt"
fi

printf '\n%-14s %12s %12s %9s %12s %16s  %s\n' scene 'GPU Grays/s' 'CPU Grays/s' 'GPU/CPU' \
  'relMSE' 'GPU 1/dispatch' device
for row in "${rows[@]}"; do
  awk -v r="$row" 'BEGIN {
    split(r, f, " ")
    printf "%-14s %12.3f %12.4f %9.1f %12s %16.3f  %s\n", f[1], f[2] / 1000, f[3] / 1000, f[2] / f[3],
      f[5], f[6] / 1000, f[4]
  }'
done
echo "GPU at $gpu_spp spp, CPU reference at $cpu_spp spp on every core, ${size}x$size; relMSE:" \
  "GPU against CPU at $cpu_spp spp; GPU 1/dispatch: Grays/s with one sample per dispatch." \
  "Files in $out"
