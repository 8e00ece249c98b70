#!/usr/bin/env bash
# Which integrator to choose: the error against time of the path tracer, BDPT and SPPM on the
# Cornell box and on the water caustic, CPU backend. Every point is one whole `pt render`
# process (SPPM's progressive state cannot be extended, so `pt converge` cannot run it; the
# path tracer and BDPT are timed the same way for a fair comparison), its wall time measured
# around the process and its error taken by `pt diff` against a per-scene reference.
#   tools/accuracy-integrators.sh [SIZE]      (default 64)
# Environment:
#   RUNS     rounds of every render; times are the median over rounds (default 3)
#   THREADS  CPU threads (default 2)
#   BUILD    build directory (default build)
#   REUSE_REF=1   keeps references already rendered with the same settings
#   REPORT_ONLY=1 renders nothing: redraws the plots and the document block from the last run
# Outputs: out/accuracy-integrators/ (references, images, results.csv, logs),
# docs/plots/integrators-*.png, and the block between the integrators markers in
# docs/accuracy.md (tools/accuracy.sh keeps that block when it rewrites the file; the
# hand-written reading inside it, between the integrators-notes markers, survives a rerun).
set -euo pipefail
cd "$(dirname "$0")/.."
size=${1:-64}
runs=${RUNS:-3}
threads=${THREADS:-2}
build=${BUILD:-build}
pt=$build/pt
out=out/accuracy-integrators
plots=docs/plots
doc=docs/accuracy.md
scenes=(cornell-box water-caustic)
integrators=(path bdpt sppm)
declare -A pretty=([cornell-box]="Cornell box" [water-caustic]="Water caustic")

# Samples per pixel (SPPM: iterations) of the studied renders; every integrator of a scene has
# the same number of levels, so that a round can interleave them level by level.
declare -A levels=(
  [cornell-box.path]="16 32 64 128 256 512 1024 2048"
  [cornell-box.bdpt]="2 4 8 16 32 64 128 256"
  [cornell-box.sppm]="8 16 32 64 128 256 512 1024"
  [water-caustic.path]="16 32 64 128 256 512 1024 2048"
  [water-caustic.bdpt]="2 4 8 16 32 64 128 256"
  [water-caustic.sppm]="4 8 16 32 64 128 256 512"
)
# SPPM's knobs per scene: an initial radius of a few pixels' footprint (the Cornell box is 550
# units across, a pixel of a 64-pixel image about 9 units: 25 gave a third of radius 10's
# relMSE at 64 iterations; the water caustic's radius is the best of docs/sppm.md's search)
# and 20,000 photons per iteration.
declare -A sppm_flags=(
  [cornell-box]="--sppm-radius 25 --sppm-photons 20000"
  [water-caustic]="--sppm-radius 0.1 --sppm-photons 20000"
)
# References: the path tracer on the Cornell box; on the water caustic, where the path tracer
# barely converges, SPPM with a small radius and many iterations (which favours SPPM's bias:
# the document says so). Two seeds each: the first is the reference, the difference of the
# two measures its own noise.
declare -A ref_flags=(
  [cornell-box]="--integrator path --spp 16384"
  [water-caustic]="--integrator sppm --sppm-radius 0.05 --sppm-photons 20000 --spp 2048"
)
ref_seeds=(1000003 1000004)  # the studied renders use seed 0
# Where the reference is not the path tracer's: a long path-traced render to check it against
# (its own noise is large, but it shares no bias with SPPM).
declare -A check_flags=([water-caustic]="--integrator path --spp 16384")
check_seed=2000001
# relMSE whose time to reach is tabulated, per scene.
declare -A target=([cornell-box]=0.0005 [water-caustic]=0.005)

[[ -x $pt ]] || { echo "no $pt: build it first (cmake --build $build --target pt)" >&2; exit 2; }
mkdir -p "$out/img" "$out/logs" "$plots"
results=$out/results.csv
run_info=$out/run.env
reference() { echo "$out/$1-ref-${size}px-seed$2.pfm"; }
check_image() { echo "$out/$1-check-${size}px-seed$check_seed.pfm"; }
now() { echo "$EPOCHREALTIME"; }

if [[ ${REPORT_ONLY:-0} != 1 ]]; then
  started=$SECONDS
  for scene in "${scenes[@]}"; do
    for seed in "${ref_seeds[@]}"; do
      ref=$(reference "$scene" "$seed")
      if [[ ${REUSE_REF:-0} == 1 && -f $ref ]]; then
        echo "== $scene: reusing $ref"
        continue
      fi
      echo "== $scene: reference, ${ref_flags[$scene]}, seed $seed"
      t0=$(now)
      # shellcheck disable=SC2086  # flags are words
      "$pt" render "configs/$scene.json" --backend cpu --threads "$threads" --width "$size" \
        --height "$size" --seed "$seed" ${ref_flags[$scene]} --out "$ref" \
        >"$out/logs/$scene-ref-$seed.txt" 2>&1
      awk -v a="$t0" -v b="$(now)" 'BEGIN {printf "   %.1f s\n", b - a}' | tee -a "$out/logs/$scene-ref-$seed.txt"
    done
    check=$(check_image "$scene")
    [[ -n ${check_flags[$scene]:-} ]] || continue
    if [[ ${REUSE_REF:-0} == 1 && -f $check ]]; then
      echo "== $scene: reusing $check"
      continue
    fi
    echo "== $scene: check of the reference, ${check_flags[$scene]}, seed $check_seed"
    # shellcheck disable=SC2086  # flags are words
    "$pt" render "configs/$scene.json" --backend cpu --threads "$threads" --width "$size" \
      --height "$size" --seed "$check_seed" ${check_flags[$scene]} --out "$check" \
      >"$out/logs/$scene-check.txt" 2>&1
  done
  echo "scene,integrator,spp,run,seconds,render_seconds,rmse,relmse,load1" >"$results"
  loads=()
  # Round by round, level by level, the three integrators one after the other, so that a
  # busy spell of the (shared) machine hits all of them alike.
  for ((run = 1; run <= runs; ++run)); do
    for scene in "${scenes[@]}"; do
      ref=$(reference "$scene" "${ref_seeds[0]}")
      read -ra n_levels <<<"${levels[$scene.path]}"
      for ((i = 0; i < ${#n_levels[@]}; ++i)); do
        for integrator in "${integrators[@]}"; do
          read -ra list <<<"${levels[$scene.$integrator]}"
          spp=${list[$i]}
          extra=""
          [[ $integrator == sppm ]] && extra=${sppm_flags[$scene]}
          name=$scene.$integrator.$spp.run$run
          img=$out/img/$name.pfm
          load=$(cut -d' ' -f1 /proc/loadavg)
          loads+=("$load")
          t0=$(now)
          # shellcheck disable=SC2086  # flags are words
          "$pt" render "configs/$scene.json" --backend cpu --threads "$threads" --width "$size" \
            --height "$size" --seed 0 --integrator "$integrator" --spp "$spp" $extra \
            --out "$img" >"$out/logs/$name.txt" 2>&1
          t1=$(now)
          render_s=$(sed -n 's/.* seconds=\([0-9.]*\) .*/\1/p' "$out/logs/$name.txt")
          # `pt diff` exits with 1 when the images differ, as they do.
          read -r rmse relmse < <({ "$pt" diff "$img" "$ref" || true; } |
            sed -n 's/^rmse=\([^ ]*\) relmse=\([^ ]*\) .*/\1 \2/p')
          seconds=$(awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.3f", b - a}')
          echo "$scene,$integrator,$spp,$run,$seconds,$render_s,$rmse,$relmse,$load" >>"$results"
          printf '%-40s %7.2f s  rmse %-10s relmse %-10s load %s  (elapsed %ds)\n' "$name" \
            "$seconds" "$rmse" "$relmse" "$load" "$SECONDS"
          rm -f "$img"
        done
      done
    done
  done
  elapsed=$((SECONDS - started))
  load_range=$(printf '%s\n' "${loads[@]}" | sort -g | sed -n '1p;$p' | paste -sd- -)
  cpu_model=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)
  run_date=$(date -u '+%Y-%m-%d %H:%M')
  declare -p size runs threads elapsed load_range cpu_model run_date >"$run_info"
fi
# shellcheck source=/dev/null
source "$run_info"

# ---- Medians over the rounds, per scene, integrator and level ------------------------------
merged=$out/merged.csv
{
  echo "scene,integrator,spp,seconds,render_seconds,rmse,relmse"
  tail -n +2 "$results" | sort -t, -k1,1 -k2,2 -k3,3n |
    awk -F, -v OFS=, -f tools/median.awk -f <(cat <<'EOF'
      function flush() {
        if (key != "") print key, median(s), median(rs), median(e), median(re)
      }
      { k = $1 OFS $2 OFS $3
        if (k != key) { flush(); key = k; s = rs = e = re = "" }
        s = s " " $5; rs = rs " " $6; e = e " " $7; re = re " " $8 }
      END { flush() }
EOF
    )
} >"$merged"
rm -f "$out"/*.dat
awk -F, -v dir="$out" 'NR > 1 { print $3, $4, $6, $7 > (dir "/" $1 "." $2 ".dat") }' "$merged"

# The references' own noise: RMSE and relMSE of the two seeds' images. Each image's own error
# against the true image is about the difference's over sqrt(2) (RMSE) or over 2 (relMSE).
declare -A ref_noise
for scene in "${scenes[@]}"; do
  ref_noise[$scene]=$({ "$pt" diff "$(reference "$scene" "${ref_seeds[0]}")" \
    "$(reference "$scene" "${ref_seeds[1]}")" || true; } |
    sed -n 's/^rmse=\([^ ]*\) relmse=\([^ ]*\) .*/\1 \2/p' |
    awk '{printf "RMSE %.3g and relMSE %.3g between the two seeds, so about RMSE %.3g and relMSE %.3g of its own", $1, $2, $1 / sqrt(2), $2 / 2}')
done
declare -A ref_check
for scene in "${!check_flags[@]}"; do
  ref_check[$scene]=$({ "$pt" diff "$(check_image "$scene")" \
    "$(reference "$scene" "${ref_seeds[0]}")" || true; } |
    sed -n 's/^rmse=\([^ ]*\) relmse=\([^ ]*\) .*/RMSE \1, relMSE \2/p')
done

# ---- Plots: relMSE and RMSE against whole-process seconds, one PNG per scene ---------------
if gnuplot -e 'set terminal' 2>&1 | grep -q pngcairo; then
  term="pngcairo size 1100,480 font ',10'"
else
  term="png size 1100,480"
fi
declare -A colors=([path]='#000000' [bdpt]='#d95f02' [sppm]='#1b9e77')
for scene in "${scenes[@]}"; do
  rel=() abs=()
  for integrator in "${integrators[@]}"; do
    dat=$out/$scene.$integrator.dat
    style="with linespoints lc rgb '${colors[$integrator]}' pt 7 ps 0.8 title '$integrator'"
    rel+=("'$dat' using 2:4 $style")
    abs+=("'$dat' using 2:3 $style")
  done
  rel+=("${target[$scene]} with lines lc rgb 'gray50' dt 3 title 'relMSE ${target[$scene]}'")
  gnuplot <<EOF
set terminal $term
set output '$plots/integrators-$scene.png'
set multiplot layout 1,2 title "${pretty[$scene]} ${size}x${size}, CPU, $threads threads: path vs BDPT vs SPPM (medians of $runs runs)" noenhanced
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set xlabel 'whole-process wall time (s)'
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set key top right noenhanced box opaque
set ylabel 'relMSE against the reference'
plot $(IFS=,; echo "${rel[*]}")
set ylabel 'RMSE against the reference'
plot $(IFS=,; echo "${abs[*]}")
unset multiplot
EOF
done

# ---- Table: per scene and integrator, the time to reach the target relMSE ------------------
# Interpolated linearly on the log-log curve between levels; the cost per sample is the slope
# of the time against spp between the first and the last level (the process's fixed cost
# removed); the slope of relMSE against spp over the last three levels (-1 for an unbiased
# estimator, flatter for bias or a reference's floor).
table() {  # scene
  awk -F, -v scene="$1" -v target="${target[$1]}" -f tools/time-to-target.awk -f <(cat <<'EOF'
    function slope(k,   i, m, x, y, sx, sy, sxx, sxy) {
      m = 3
      for (i = n[k] - m + 1; i <= n[k]; ++i) {
        x = log(s[k, i]); y = log(r[k, i]); sx += x; sy += y; sxx += x * x; sxy += x * y
      }
      return sprintf("%.2f", (m * sxy - sx * sy) / (m * sxx - sx * sx))
    }
    NR > 1 && $1 == scene {
      k = $2; i = ++n[k]; s[k, i] = $3; t[k, i] = $4; e[k, i] = $6; r[k, i] = $7
    }
    END {
      split("path bdpt sppm", L, " ")
      print "| integrator | spp (SPPM: iterations) | wall s | RMSE | relMSE | slope | ms per sample | wall s to relMSE " target " |"
      print "|---|--:|--:|--:|--:|--:|--:|--:|"
      for (l = 1; l <= 3; ++l) {
        k = L[l]
        if (!n[k]) continue
        cost = (t[k, n[k]] - t[k, 1]) / (s[k, n[k]] - s[k, 1]) * 1000
        printf "| %s | %s–%s | %s–%s | %s–%s | %s–%s | %s | %s | %s |\n", k, s[k, 1], s[k, n[k]],
          g(t[k, 1]), g(t[k, n[k]]), g(e[k, 1]), g(e[k, n[k]]), g(r[k, 1]), g(r[k, n[k]]),
          slope(k), g(cost), timeTo(k)
      }
    }
EOF
  ) "$merged"
}

# ---- The block in docs/accuracy.md ------------------------------------------------------------
reading=$'<!-- integrators-notes:begin -->\n(none yet)\n<!-- integrators-notes:end -->'
if grep -q '<!-- integrators-notes:begin -->' "$doc"; then
  reading=$(sed -n '/<!-- integrators-notes:begin -->/,/<!-- integrators-notes:end -->/p' "$doc")
fi
block=$out/block.md
{
  cat <<EOF
<!-- integrators:begin -->
## Which integrator: path, BDPT and SPPM

Generated by \`tools/accuracy-integrators.sh $size\` on $run_date UTC ($runs rounds,
$((elapsed / 60)) min $((elapsed % 60)) s of rendering); the reading below is written by hand.

- Machine: $(nproc) cores ($cpu_model), shared with other builds: load average (1 min)
  $load_range during the run; CPU backend, $threads threads, ${size}x${size}.
- Every point is one whole \`pt render\` process (\`--seed 0\`), its wall time measured
  around the process (scene load, BVH build, render, image write) and its error from
  \`pt diff\` against the scene's reference. SPPM cannot be extended by \`pt converge\`, so
  every level of every integrator is a separate render; the times are medians over the
  $runs rounds, which interleave the integrators level by level so that they see the same
  load. The errors do not depend on the round.
- SPPM: \`${sppm_flags[cornell-box]}\` on the Cornell box,
  \`${sppm_flags[water-caustic]}\` on the water caustic; \`--spp\` sets its iterations. SPPM is consistent but biased: its error
  contains the blur of its radius, which shrinks with the iterations.
- References (seed ${ref_seeds[0]}; a second seed, ${ref_seeds[1]}, only to measure their noise):
  - Cornell box: the path tracer, \`${ref_flags[cornell-box]}\`: ${ref_noise[cornell-box]}.
  - Water caustic: SPPM, \`${ref_flags[water-caustic]}\`: ${ref_noise[water-caustic]}.
    Against a path-traced render, \`${check_flags[water-caustic]}\` (seed $check_seed): ${ref_check[water-caustic]}.
    An SPPM reference shares SPPM's kind of bias (a smaller radius, but the same blur), so
    it favours the SPPM curve; the path tracer converges too slowly here for a reference in
    this run's time (docs/sppm.md used 98,304 path-traced samples per pixel, 640 s).
- relMSE: mean of (image − reference)² / (reference² + 0.01) over pixels and channels; RMSE:
  root mean square difference (dominated by a few bright pixels).
- The table: the range of levels, their wall times and errors (first–last), the log-log
  slope of relMSE against spp over the last three levels, the time one more sample per pixel
  costs (the slope of wall time against spp), and the wall time to reach the stated relMSE
  (interpolated on the log-log curve).

\`\`\`sh
tools/accuracy-integrators.sh $size    # RUNS=3 THREADS=2 by default; REPORT_ONLY=1 redraws
build/pt render configs/water-caustic.json --backend cpu --threads 2 --width 64 --height 64 \\
  --seed 0 --integrator sppm ${sppm_flags[water-caustic]} --spp 64 --out s.pfm
build/pt diff s.pfm out/accuracy-integrators/water-caustic-ref-${size}px-seed${ref_seeds[0]}.pfm
\`\`\`
EOF
  for scene in "${scenes[@]}"; do
    printf '\n### %s\n\n![%s: relMSE and RMSE against wall time](plots/integrators-%s.png)\n\n' \
      "${pretty[$scene]}" "${pretty[$scene]}" "$scene"
    table "$scene"
  done
  printf '\n### Reading\n\n%s\n<!-- integrators:end -->\n' "$reading"
} >"$block"
if grep -q '<!-- integrators:begin -->' "$doc"; then
  awk -v file="$block" '
    /<!-- integrators:begin -->/ { while ((getline line < file) > 0) print line; skip = 1; next }
    /<!-- integrators:end -->/ { skip = 0; next }
    !skip' "$doc" >"$doc.tmp"
else  # first run: before the hand-written notes of tools/accuracy.sh
  awk -v file="$block" '
    /^## Notes on this run/ { while ((getline line < file) > 0) print line; print "" }
    { print }' "$doc" >"$doc.tmp"
fi
mv "$doc.tmp" "$doc"
echo "wrote $doc (integrators block), $plots/integrators-*.png, $merged"
