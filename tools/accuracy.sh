#!/usr/bin/env bash
# What accuracy costs in time: renders a high-spp CPU reference of the Cornell box and of the
# bunny, runs `pt converge` for each knob on the CPU and on the Vulkan backend, merges the
# CSVs, plots relMSE against seconds (docs/plots/*.png) and writes docs/accuracy.md.
#   tools/accuracy.sh [SIZE] [MAX_SPP]        (default 64 256)
# Environment:
#   REF_SPP  reference samples per pixel (default 32 x MAX_SPP)
#   TARGET   relMSE whose time to reach is tabulated (default 0.01)
#   RUNS     rounds of every configuration; times are the median over rounds (default 3)
#   THREADS  CPU threads, and LP_NUM_THREADS for lavapipe (default: all cores)
#   BUILD    build directory (default build)
#   REUSE_REF=1 keeps a reference already rendered with the same size, spp and seed
#   REPORT_ONLY=1 renders nothing: redraws the plots and the document from the last run
# Renders run one at a time. Outputs: out/accuracy/ (references, CSVs, logs), docs/plots/,
# docs/accuracy.md (a hand-written block between the notes markers survives a rerun).
set -euo pipefail
cd "$(dirname "$0")/.."
size=${1:-64}
max_spp=${2:-256}
ref_spp=${REF_SPP:-$((32 * max_spp))}
target=${TARGET:-0.01}
runs=${RUNS:-3}
threads=${THREADS:-$(nproc)}
build=${BUILD:-build}
ref_seed=1000003  # the studied runs use the scenes' own seed, 0
out=out/accuracy
plots=docs/plots
doc=docs/accuracy.md
scenes=(cornell-box bunny-box)

# Configurations: label and `pt converge` flags. "baseline" is the scenes' own settings:
# NEE+MIS, Russian roulette on (from depth 3), max depth 64, Owen-scrambled Sobol numbers,
# PLOC BVH with the backend's default leaf size (8 on the CPU, 3 with Vulkan), watertight
# intersection, specialized.
declare -A flags=(
  [baseline]="" [nee]="--strategy nee" [bsdf]="--strategy bsdf" [rr-off]="--rr off"
  [depth-1]="--max-depth 1" [depth-2]="--max-depth 2" [depth-4]="--max-depth 4"
  [independent]="--sampler independent"
  [leaf-1]="--leaf-size 1" [leaf-4]="--leaf-size 4" [leaf-16]="--leaf-size 16"
  [lbvh]="--builder lbvh" [sah]="--builder sah" [fast-isect]="--intersection fast"
  [unspecialized]="--no-specialize"
)
cpu_labels="baseline nee bsdf rr-off depth-1 depth-2 depth-4 independent leaf-1 leaf-4 leaf-16"
cpu_labels="$cpu_labels lbvh sah fast-isect"
vulkan_labels="$cpu_labels unspecialized"
# Knob groups: file name, title, labels (each plot and table shows one group).
groups=(
  "strategy|Direct light: NEE+MIS (baseline) vs NEE only vs BSDF only|baseline nee bsdf"
  "depth|Russian roulette on (baseline) / off, max depth 64 (baseline), 4, 2, 1|baseline rr-off depth-4 depth-2 depth-1"
  "sampler|Random numbers: Owen-scrambled Sobol (baseline) vs independent|baseline independent"
  "leaf|BVH leaf size 1, 4, the default (baseline: 8 on the CPU, 3 with Vulkan), 16|leaf-1 leaf-4 baseline leaf-16"
  "builder|BVH builder: PLOC (baseline) vs LBVH vs binned SAH (trace time; build time below)|baseline lbvh sah"
  "intersection|Ray/triangle test: watertight (baseline) vs Moller-Trumbore (not watertight)|baseline fast-isect"
  "specialize|Specialization constants on (baseline) / off, Vulkan only|baseline unspecialized"
)

tools/setup.sh
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target pt
pt=$build/pt
export LP_NUM_THREADS=$threads
mkdir -p "$out/csv" "$out/logs" "$out/dat" "$plots"
run_info=$out/run.env  # what the document says about the run: kept for REPORT_ONLY=1
if [[ ${REPORT_ONLY:-0} == 1 ]]; then
  # shellcheck source=/dev/null
  source "$run_info"
else
  rm -f "$out"/csv/*.csv "$out"/problems.txt
  started=$SECONDS
  reference() { echo "$out/$1-ref-${size}px-${ref_spp}spp-seed$ref_seed.exr"; }
  for scene in "${scenes[@]}"; do
    ref=$(reference "$scene")
    if [[ ${REUSE_REF:-0} == 1 && -f $ref ]]; then
      echo "== $scene: reusing $ref"
    else
      echo "== $scene: reference, CPU, $ref_spp spp, seed $ref_seed"
      "$pt" render "configs/$scene.json" --backend cpu --threads "$threads" --width "$size" \
        --height "$size" --spp "$ref_spp" --seed "$ref_seed" --out "$ref" 2>/dev/null
    fi
  done
  # Every configuration once per round, so that a slow spell of the machine hits one round
  # of every configuration rather than every round of one.
  for ((run = 1; run <= runs; ++run)); do
    for scene in "${scenes[@]}"; do
      ref=$(reference "$scene")
      for backend in cpu vulkan; do
        labels=$cpu_labels
        [[ $backend == vulkan ]] && labels=$vulkan_labels
        for label in $labels; do
          name=$scene.$backend.$label.run$run
          # shellcheck disable=SC2086  # flags are words
          if "$pt" converge "configs/$scene.json" --backend "$backend" --threads "$threads" \
            --width "$size" --height "$size" --max-spp "$max_spp" --reference "$ref" \
            --label "$label" --csv "$out/csv/$name.csv" ${flags[$label]} \
            >"$out/logs/$name.txt" 2>"$out/logs/$name.err"; then
            status=0
          else
            status=$?
          fi
          # Status 1: some samples were NaN/Inf or cut short; the rows are kept and flagged.
          if ((status == 1)); then
            echo "$name: $(tail -1 "$out/logs/$name.err")" >>"$out/problems.txt"
          elif ((status != 0)); then
            cat "$out/logs/$name.err" >&2
            exit "$status"
          fi
          echo "$name: $(tail -1 "$out/logs/$name.txt")  (elapsed ${SECONDS}s)"
        done
      done
    done
  done
  # BVH build time and size per builder: the median of 5 builds (a 1-spp, 8x8 CPU render
  # prints them), for the builder table.
  : >"$out/builds.txt"
  for scene in "${scenes[@]}"; do
    for builder in ploc lbvh sah; do
      for _ in 1 2 3 4 5; do
        "$pt" render "configs/$scene.json" --backend cpu --threads "$threads" --width 8 \
          --height 8 --spp 1 --builder "$builder" --out "$out/build-probe.pfm" 2>/dev/null |
          sed -n "s/.*bvh_nodes=\([0-9]*\) bvh_build_s=\([0-9.]*\).*/$scene $builder \1 \2/p"
      done | sort -k4 -g | sed -n 3p >>"$out/builds.txt"
    done
  done
  rm -f "$out/build-probe.pfm"
  elapsed=$((SECONDS - started))
  cpu_model=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)
  vk_device=$("$pt" devices 2>/dev/null | head -1 | sed 's/^[0-9]*: //') || vk_device="(none)"
  run_date=$(date -u +%Y-%m-%d)
  declare -p size max_spp ref_spp runs threads elapsed cpu_model vk_device run_date >"$run_info"
fi
rm -f "$out"/dat/*.dat "$out"/dat/*.guide "$plots"/accuracy-*.png

# ---- Merge the rounds (median seconds and Mrays/s per level), split per curve for gnuplot ----
# The errors do not depend on the round: the same sample indices give the same image.
merged=$out/accuracy.csv
{
  echo "label,backend,scene,width,height,spp,seconds,rmse,relmse,mrays_per_s"
  for f in "$out"/csv/*.csv; do tail -n +2 "$f"; done |
    sort -t, -k1,1 -k2,2 -k3,3 -k4,4n -k5,5n -k6,6n |
    awk -F, -v OFS=, '
      function median(list,   v, n, i, j, x) {
        n = split(list, v, " ")
        for (i = 2; i <= n; ++i) for (j = i; j > 1 && v[j - 1] + 0 > v[j] + 0; --j) {
          x = v[j]; v[j] = v[j - 1]; v[j - 1] = x
        }
        return n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2
      }
      function flush() { if (key != "") print key, median(secs), rest, median(mrays) }
      { k = $1 OFS $2 OFS $3 OFS $4 OFS $5 OFS $6
        if (k != key) { flush(); key = k; secs = ""; mrays = "" }
        secs = secs " " $7; mrays = mrays " " $10; rest = $8 OFS $9 }
      END { flush() }'
} >"$merged"
awk -F, -v dir="$out/dat" 'NR > 1 {
  f = dir "/" $3 "." $2 "." $1 ".dat"; print $6, $7, $9 > f }' "$merged"

# ---- Plots: one per scene and knob group; CPU solid, Vulkan dashed, a colour per config ------
if gnuplot -e 'set terminal' 2>&1 | grep -q pngcairo; then
  term="pngcairo size 900,620 font ',10'"
else
  term="png size 900,620"
fi
declare -A pretty=([cornell-box]="Cornell box" [bunny-box]="Bunny box")
colors=('#000000' '#d95f02' '#1b9e77' '#7570b3' '#e7298a')
for scene in "${scenes[@]}"; do
  for g in "${groups[@]}"; do
    IFS='|' read -r gname gtitle glabels <<<"$g"
    cmds=() color=0
    for label in $glabels; do
      for backend in cpu vulkan; do
        dat=$out/dat/$scene.$backend.$label.dat
        [[ -f $dat ]] || continue
        [[ $gname == specialize && $backend == cpu ]] && continue
        dt=1 pt_=7
        [[ $backend == vulkan ]] && dt=2 pt_=6
        cmds+=("'$dat' using 2:3 with linespoints lc rgb '${colors[$color]}' dt $dt pt $pt_ ps 0.8 title '$label ($backend)'")
      done
      color=$((color + 1))
    done
    cmds+=("$target with lines lc rgb 'gray50' dt 3 title 'target relMSE $target'")
    # A slope -1 guide (relMSE proportional to 1/time, what an unbiased estimator follows
    # at constant speed) through the baseline's last point.
    guide_backend=cpu
    [[ $gname == specialize ]] && guide_backend=vulkan
    base=$out/dat/$scene.$guide_backend.baseline.dat
    guide=$out/dat/$scene.$gname.guide
    awk 'NR == 1 {t0 = $2} {t = $2; r = $3} END {print t0, r * t / t0; print t, r}' "$base" >"$guide"
    cmds+=("'$guide' using 1:2 with lines lc rgb 'gray60' dt 4 title 'slope -1 through baseline ($guide_backend)'")
    plot=$(IFS=,; echo "${cmds[*]}")
    gnuplot <<EOF
set terminal $term
set output '$plots/accuracy-$scene-$gname.png'
set title "${pretty[$scene]} ${size}x${size}: $gtitle" noenhanced
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set xlabel 'cumulative render time (s): CPU wall clock, Vulkan device timestamps'
set ylabel 'relMSE against the reference'
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set key inside bottom left noenhanced box opaque
plot $plot
EOF
  done
done

# ---- Tables --------------------------------------------------------------------------------
# For one scene and group: per configuration and backend, the last level (spp, seconds,
# relMSE, Mrays/s), the log-log slope of relMSE against spp over the last three levels, the
# time to reach the target relMSE and the relMSE at equal time T, where T (per backend) is
# the smallest final time in the group, so that every curve reaches it. Both by linear
# interpolation between levels on the log-log curve.
table() {  # scene, labels, backends
  awk -F, -v scene="$1" -v labels="$2" -v backends="$3" -v target="$target" -f tools/time-to-target.awk -f <(cat <<'EOF'
    function atTime(k, T,   i) {
      if (T < t[k, 1]) return "—"
      if (T <= t[k, 1]) return g(r[k, 1])
      for (i = 2; i <= n[k]; ++i) if (t[k, i] >= T)
        return g(exp(lerp(log(T), log(t[k, i - 1]), log(t[k, i]), log(r[k, i - 1]), log(r[k, i]))))
      return "—"
    }
    function slope(k,   i, m, x, y, sx, sy, sxx, sxy) {
      m = n[k] < 3 ? n[k] : 3
      if (m < 2) return "—"
      for (i = n[k] - m + 1; i <= n[k]; ++i) {
        x = log(s[k, i]); y = log(r[k, i]); sx += x; sy += y; sxx += x * x; sxy += x * y
      }
      return sprintf("%.2f", (m * sxy - sx * sy) / (m * sxx - sx * sx))
    }
    NR > 1 && $3 == scene {
      k = $1 SUBSEP $2; i = ++n[k]; s[k, i] = $6; t[k, i] = $7; r[k, i] = $9; mr[k, i] = $10
    }
    END {
      nl = split(labels, L, " "); nb = split(backends, B, " ")
      for (b = 1; b <= nb; ++b) for (l = 1; l <= nl; ++l) {
        k = L[l] SUBSEP B[b]
        if (n[k] && (!(B[b] in T) || t[k, n[k]] < T[B[b]])) T[B[b]] = t[k, n[k]]
      }
      print "| configuration | backend | spp | seconds | relMSE | slope | Mrays/s | seconds to relMSE " target " | relMSE at equal time |"
      print "|---|---|--:|--:|--:|--:|--:|--:|--:|"
      for (l = 1; l <= nl; ++l) for (b = 1; b <= nb; ++b) {
        k = L[l] SUBSEP B[b]
        if (!n[k]) continue
        printf "| %s | %s | %d | %s | %s | %s | %s | %s | %s (at %s s) |\n", L[l], B[b], s[k, n[k]],
          g(t[k, n[k]]), g(r[k, n[k]]), slope(k), g(mr[k, n[k]]), timeTo(k), atTime(k, T[B[b]]),
          g(T[B[b]])
      }
    }
EOF
  ) "$merged"
}
field() {  # scene backend label column(6 spp, 7 seconds, 9 relmse, 10 mrays): the last level
  awk -F, -v s="$1" -v b="$2" -v l="$3" -v c="$4" '$3 == s && $2 == b && $1 == l {v = $c} END {print v}' "$merged"
}
ratio() { awk -v a="$1" -v b="$2" 'BEGIN {printf "%.2f", a / b}'; }

# ---- The document ------------------------------------------------------------------------------
notes=""
if [[ -f $doc ]] && grep -q '<!-- notes:begin -->' "$doc"; then
  notes=$(sed -n '/<!-- notes:begin -->/,/<!-- notes:end -->/p' "$doc")
fi
[[ -n $notes ]] || notes=$'<!-- notes:begin -->\n(none yet)\n<!-- notes:end -->'
# The integrators' comparison is written by tools/accuracy-integrators.sh: kept as it is.
integrators=""
if [[ -f $doc ]] && grep -q '<!-- integrators:begin -->' "$doc"; then
  integrators=$(sed -n '/<!-- integrators:begin -->/,/<!-- integrators:end -->/p' "$doc")
fi
{
  cat <<EOF
# What accuracy costs in time

Generated by \`tools/accuracy.sh $size $max_spp\` on $run_date (UTC); every number and plot
below comes from that run.

- Machine: $(nproc) cores ($cpu_model), $threads CPU threads; Vulkan on
  $vk_device.
- Image ${size}x${size}; \`pt converge\` levels 1, 2, 4, … $max_spp spp; references rendered on
  the CPU at $ref_spp spp with seed $ref_seed (the studied runs use the scenes' seed 0).
- Rendering took $((elapsed / 60)) min $((elapsed % 60)) s of wall time, one render at a time.
- Every configuration ran $runs times, in $runs rounds of all of them; the times and Mrays/s
  are the medians over the rounds. The errors (relMSE at a given spp) are deterministic and
  do not depend on the round or on the load.

## How to rerun

\`\`\`sh
tools/accuracy.sh [SIZE] [MAX_SPP]     # e.g. tools/accuracy.sh $size $max_spp
\`\`\`

It installs packages and builds like the other tools, renders the references into
\`out/accuracy/\`, runs \`pt converge\` RUNS times per configuration and backend, one render at a
time, merges the rows into \`out/accuracy/accuracy.csv\`, draws \`docs/plots/accuracy-*.png\`
with gnuplot and rewrites this file (the notes block at the end is kept). \`REF_SPP\`,
\`TARGET\`, \`RUNS\`, \`THREADS\` and \`BUILD\` override the defaults (32 × MAX_SPP, 0.01, 3,
all cores, \`build\`); \`REPORT_ONLY=1\` redraws the plots and this file from the last run's CSVs without
rendering. One configuration by hand:

\`\`\`sh
build/pt converge configs/cornell-box.json --backend cpu --width $size --height $size \\
  --max-spp $max_spp --reference out/accuracy/cornell-box-ref-${size}px-${ref_spp}spp-seed$ref_seed.exr \\
  --strategy nee --label nee --csv nee.csv
\`\`\`

## How to read it

- **relMSE** is the mean over pixels and channels of (image − reference)² / (reference² +
  0.01), as \`pt diff\` computes it; **seconds** is the cumulative render time of the levels
  so far (CPU: wall clock of the render; Vulkan: device timestamps around the dispatches,
  without set-up, shader compilation or upload). Each level adds the next sample indices to
  the film, so the last row of a run is the same image as one render at MAX_SPP.
- **slope** is the log-log slope of relMSE against spp over the last three levels. An
  unbiased estimator gives about −1 (MSE ∝ 1/N); a slope towards 0 means the error has hit a
  floor: bias. A biased configuration converges to a different image than the reference.
- **seconds to relMSE $target**: when the curve first crosses the target (interpolated
  linearly on the log-log curve between levels); "not reached" within MAX_SPP.
- **relMSE at equal time**: the curve read at time T, the smallest final time among the
  group's configurations on that backend (so every curve reaches it), again interpolated on
  the log-log curve; "—" when T is before a configuration's first level.
- The reference is itself noisy: at $ref_spp spp its own relMSE is roughly the baseline's
  error at $max_spp spp times $max_spp/$ref_spp, and that floor is included in every number.
  RMSE is in the CSV too but is dominated by the few pixels on the light's edge (a sample
  there sees either the light, radiance about 17, or the ceiling, below 1), so the plots and
  tables use relMSE.
- Identical sample indices give (nearly) identical images on both backends, so at equal
  spp the two backends' relMSE agree and only their times differ.
- The plots: CPU solid with filled points, Vulkan dashed with open points, one colour per
  configuration; the target relMSE dotted; a slope −1 guide (relMSE ∝ 1/time) through the
  baseline's last point.
EOF
  for scene in "${scenes[@]}"; do
    printf '\n## %s\n' "${pretty[$scene]}"
    for g in "${groups[@]}"; do
      IFS='|' read -r gname gtitle glabels <<<"$g"
      printf '\n### %s\n\n![%s, %s](plots/accuracy-%s-%s.png)\n\n' "$gtitle" "${pretty[$scene]}" \
        "$gname" "$scene" "$gname"
      backends="cpu vulkan"
      [[ $gname == specialize ]] && backends=vulkan
      table "$scene" "$glabels" "$backends"
    done
    if [[ -s $out/builds.txt ]]; then
      awk -v s="$scene" 'BEGIN {
          print "\nBVH builds (median of 5; the trace times are in the table above):\n"
          print "| builder | nodes | build seconds |"; print "|---|--:|--:|" }
        $1 == s { printf "| %s | %d | %.4f |\n", $2 == "ploc" ? "PLOC (baseline)" : $2 == "lbvh" ? "LBVH" : "binned SAH", $3, $4 }' \
        "$out/builds.txt"
    fi
    spec=$(field "$scene" vulkan baseline 7) unspec=$(field "$scene" vulkan unspecialized 7)
    if [[ -n $spec && -n $unspec ]]; then
      printf '\nSpecialization on Vulkan, %s: %s s specialized vs %s s unspecialized for %s spp, a speed-up of %s× (Mrays/s %s vs %s).\n' \
        "${pretty[$scene]}" "$(printf %.3g "$spec")" "$(printf %.3g "$unspec")" \
        "$(field "$scene" vulkan baseline 6)" "$(ratio "$unspec" "$spec")" \
        "$(printf %.3g "$(field "$scene" vulkan baseline 10)")" \
        "$(printf %.3g "$(field "$scene" vulkan unspecialized 10)")"
    fi
  done
  if [[ -s $out/problems.txt ]]; then
    printf '\n## Runs with invalid samples\n\nThese runs reported NaN/Inf or truncated samples (left out of the image, rows kept):\n\n'
    sed 's/^/- /' "$out/problems.txt"
  fi
  [[ -z $integrators ]] || printf '\n%s\n' "$integrators"
  cat <<EOF

## Notes on this run

Hand-written observations; they describe the run this file was generated from and are kept
when the script rewrites the file, so check them against the tables after a rerun.

$notes

## Not measured

- A double-precision CPU reference is not offered: the CPU integrator computes in float
  (only the film accumulates in double), so the reference shares the renderer's float
  arithmetic. Its float paths agree with an independent double-precision sum where that
  was tested (a pixel over a million samples, tests/robustness_test.cpp).
EOF
} >"$doc"
echo "wrote $doc and $plots/accuracy-*.png in ${elapsed}s of rendering"
