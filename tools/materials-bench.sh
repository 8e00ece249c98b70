#!/usr/bin/env bash
# What each material costs, and what the coated material's knobs buy: writes docs/materials.md.
#  1. The Cornell box with its two blocks made of each material type (the diffuse original
#     first), rendered on the CPU and on the Vulkan backend: seconds per sample per pixel and
#     Mrays/s, the median of RUNS rounds, and the ratio to the diffuse scene.
#  2. The blocks made of coateddiffuse (rough coat) with maxdepth and nsamples varied: error
#     against a reference with maxdepth 100 (relMSE at the largest spp: the bias of short
#     random walks stays as a floor) and the time the CPU took.
#   tools/materials-bench.sh [SIZE] [SPP]        (default 128 64)
# Environment: RUNS (default 3), THREADS (default: all cores), BUILD (default build),
#   REF_SPP (default 4096), KNOB_SPP (default 256), REUSE_REF=1 keeps a reference already there.
# The scene variants are written to out/materials/ from configs/cornell-box.json.
set -euo pipefail
cd "$(dirname "$0")/.."
size=${1:-128}
spp=${2:-64}
runs=${RUNS:-3}
threads=${THREADS:-$(nproc)}
build=${BUILD:-build}
ref_spp=${REF_SPP:-4096}
knob_spp=${KNOB_SPP:-256}
knob_size=64
out=out/materials
doc=docs/materials.md
mkdir -p "$out"
cmake --build "$build" --target pt >/dev/null
pt=$build/pt
export LP_NUM_THREADS=$threads

# ---- Scene variants: the blocks' material replaced, everything else the Cornell box's ------
# variant name -> JSON of the blocks' material (pbrt-v4's parameter names).
python3 - "$out" <<'EOF'
import json, sys
out = sys.argv[1]
base = json.load(open('configs/cornell-box.json'))
variants = {
    'diffuse': None,
    'conductor-smooth': {'type': 'conductor', 'roughness': 0},
    'conductor-rough': {'type': 'conductor', 'roughness': 0.1},
    'dielectric-smooth': {'type': 'dielectric', 'eta': 1.5},
    'dielectric-rough': {'type': 'dielectric', 'eta': 1.5, 'roughness': 0.1},
    'thindielectric': {'type': 'thindielectric', 'eta': 1.5},
    'diffusetransmission': {'type': 'diffusetransmission', 'reflectance': [0.5, 0.5, 0.5],
                            'transmittance': [0.4, 0.4, 0.4]},
    'coateddiffuse-smooth': {'type': 'coateddiffuse', 'reflectance': [0.7, 0.4, 0.3]},
    'coateddiffuse-rough': {'type': 'coateddiffuse', 'reflectance': [0.7, 0.4, 0.3],
                            'roughness': 0.1},
}
knobs = {f'coated-depth{d}-samples{n}': (d, n)
         for d, n in [(1, 1), (2, 1), (3, 1), (5, 1), (10, 1), (30, 1), (10, 2), (10, 4),
                      (100, 1)]}
def write(name, material):
    scene = json.loads(json.dumps(base))
    if material is not None:
        scene['materials'].append(dict(name='blocks', **material))
        for shape in scene['shapes']:
            if shape.get('name', '').startswith(('short_block', 'tall_block')):
                shape['material'] = 'blocks'
    json.dump(scene, open(f'{out}/{name}.json', 'w'), indent=1)
for name, material in variants.items():
    write(name, material)
for name, (depth, samples) in knobs.items():
    write(name, dict(variants['coateddiffuse-rough'], maxdepth=depth, nsamples=samples))
open(f'{out}/variants.txt', 'w').write(' '.join(variants) + '\n' + ' '.join(knobs) + '\n')
EOF
{ read -r -a variants; read -r -a knobs; } <"$out/variants.txt"

# ---- 1. Cost per material: every variant once per round, both backends ----------------------
: >"$out/cost.txt"
for ((run = 1; run <= runs; ++run)); do
  for v in "${variants[@]}"; do
    for backend in cpu vulkan; do
      line=$("$pt" render "$out/$v.json" --backend "$backend" --threads "$threads" \
        --width "$size" --height "$size" --spp "$spp" --out "$out/probe.exr" 2>/dev/null)
      secs=$(sed -n 's/.* seconds=\([0-9.]*\).*/\1/p' <<<"$line")
      mrays=$(sed -n 's/.*Mrays\/s=\([0-9.]*\).*/\1/p' <<<"$line")
      invalid=$(sed -n 's/.*invalid_samples=\([0-9]*\).*/\1/p' <<<"$line")
      echo "$v $backend $secs $mrays $invalid" >>"$out/cost.txt"
      echo "round $run: $v $backend ${secs}s ${mrays} Mrays/s invalid=$invalid"
    done
  done
done

# ---- 2. The coated material's knobs against a long-walk reference (CPU) ----------------------
ref=$out/coated-ref-${knob_size}px-${ref_spp}spp.exr
if [[ ${REUSE_REF:-0} != 1 || ! -f $ref ]]; then
  echo "reference: coated, maxdepth 100, $ref_spp spp"
  "$pt" render "$out/coated-depth100-samples1.json" --backend cpu --threads "$threads" \
    --width "$knob_size" --height "$knob_size" --spp "$ref_spp" --seed 1000003 --out "$ref" \
    2>/dev/null >/dev/null
fi
for k in "${knobs[@]}"; do
  "$pt" converge "$out/$k.json" --backend cpu --threads "$threads" --width "$knob_size" \
    --height "$knob_size" --max-spp "$knob_spp" --reference "$ref" --label "$k" \
    --csv "$out/$k.csv" >/dev/null 2>&1
  echo "knob $k: $(tail -1 "$out/$k.csv")"
done

# ---- The document ---------------------------------------------------------------------------
notes=""
if [[ -f $doc ]] && grep -q '<!-- notes:begin -->' "$doc"; then
  notes=$(sed -n '/<!-- notes:begin -->/,/<!-- notes:end -->/p' "$doc")
fi
[[ -n $notes ]] || notes=$'<!-- notes:begin -->\n(none yet)\n<!-- notes:end -->'
cpu_model=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)
vk_device=$("$pt" devices 2>/dev/null | head -1 | sed 's/^[0-9]*: //') || vk_device="(none)"
{
  cat <<EOF
# What materials cost

Written by \`tools/materials-bench.sh $size $spp\` on $(date -u +%Y-%m-%d) ($cpu_model, $threads
threads; Vulkan device: $vk_device). Rerun it to regenerate this file; the notes block at the
end is kept.

## Cost of each material against the diffuse Cornell box

The Cornell box (configs/cornell-box.json) at ${size}x${size}, $spp spp, with both blocks made
of the material named (the walls stay diffuse; out/materials/ holds the scenes). Median of
$runs rounds; \`seconds\` is the render's own time (set-up excluded), \`x diffuse\` the ratio of
seconds to the diffuse scene's on the same backend. Rays/s differ with the paths' lengths
(glass lets paths bounce longer), so seconds per image is the figure to compare.

| blocks | CPU s | CPU Mrays/s | CPU x diffuse | Vulkan s | Vulkan Mrays/s | Vulkan x diffuse | invalid |
|---|--:|--:|--:|--:|--:|--:|--:|
EOF
  awk -v runs="$runs" '
    function median(list,   v, n, i, j, x) {
      n = split(list, v, " ")
      for (i = 2; i <= n; ++i) for (j = i; j > 1 && v[j - 1] + 0 > v[j] + 0; --j) {
        x = v[j]; v[j] = v[j - 1]; v[j - 1] = x }
      return n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2 }
    { key = $1 SUBSEP $2; secs[key] = secs[key] " " $3; mrays[key] = mrays[key] " " $4
      invalid[$1] += $5; if (!($1 in seen)) { seen[$1] = 1; order[++n] = $1 } }
    END {
      dc = median(secs["diffuse" SUBSEP "cpu"]); dv = median(secs["diffuse" SUBSEP "vulkan"])
      for (i = 1; i <= n; ++i) { v = order[i]
        c = median(secs[v SUBSEP "cpu"]); g = median(secs[v SUBSEP "vulkan"])
        printf "| %s | %.3f | %.2f | %.2f | %.3f | %.2f | %.2f | %d |\n", v, c,
          median(mrays[v SUBSEP "cpu"]), c / dc, g, median(mrays[v SUBSEP "vulkan"]), g / dv,
          invalid[v] } }' "$out/cost.txt"
  cat <<EOF

## The coated material's random walk: maxdepth and nsamples

Both blocks coateddiffuse (reflectance 0.7 0.4 0.3, roughness 0.1, thickness 0.01, eta 1.5),
${knob_size}x${knob_size}, CPU, against a reference with maxdepth 100 and nsamples 1 at
$ref_spp spp (another seed). relMSE at $knob_spp spp: a walk cut short loses the light that
bounces between coat and base more often, a bias that stays however many samples are taken;
nsamples averages more walks per evaluation (f and pdf), which lowers the noise per sample
and costs time. \`seconds\` is the CPU's time for all $knob_spp samples.

| maxdepth | nsamples | relMSE at $knob_spp spp | seconds | relMSE x seconds |
|--:|--:|--:|--:|--:|
EOF
  for k in "${knobs[@]}"; do
    depth=${k#coated-depth}
    depth=${depth%-samples*}
    samples=${k##*-samples}
    tail -1 "$out/$k.csv" | awk -F, -v d="$depth" -v n="$samples" \
      '{ printf "| %s | %s | %.3g | %.3f | %.3g |\n", d, n, $9, $7, $9 * $7 }'
  done
  echo
  echo "## Notes on this run"
  echo
  echo "$notes"
} >"$doc"
echo "wrote $doc"
