#!/usr/bin/env bash
# Speed on every backend: runs the ray benchmark (bench/ray_bench: CPU traversal, GPU ray
# queries on the Vulkan device, Embree) on every scene, Embree's path-tracer tutorial against
# our CPU path tracer on the Cornell box, and `pt converge` for the time to a fixed error on
# the Cornell box on each backend; draws docs/images/performance-*.png and writes
# docs/performance.md.
#   tools/performance.sh
# Environment:
#   BUILD        build directory (default build)
#   THREADS      CPU threads: ray_bench, pt, Embree's tutorial, and LP_NUM_THREADS for lavapipe
#                (default: all cores)
#   RUNS         repetitions of every measurement; the medians are reported (default 3)
#   SCENES       ray_bench scenes (default cornell-box,bunny-box,sphere,bunny-dragon)
#   BENCH_ARGS   more ray_bench arguments (e.g. --device 1, --builder sah, --embree-robust)
#   SIZE         `pt converge` image size (default 256), MAX_SPP (default 256),
#   REF_SPP      reference samples per pixel (default 2048), TARGET relMSE (default 1e-3),
#   CONVERGE_RUNS rounds of `pt converge` per backend (default RUNS)
#   FRAMES       timed frames of Embree's path tracer per run (default 40), PT_SPP samples
#                per pixel of our path tracer per run, on both backends (default 32: two
#                batches, so that the Vulkan backend's later dispatches, of 16 samples, count)
#   QUICK=1      everything small (seconds to a minute): only to check that the script works;
#                the document says so, and its numbers are not for quoting
#   REUSE_REF=1  keeps a reference already rendered with the same size, spp and seed
#   REPORT_ONLY=1 measures nothing: redraws the plots and the document from the last run
# Outputs: out/performance/ (logs, CSVs, the reference, the Embree scene), docs/images/,
# docs/performance.md (a hand-written block between the notes markers survives a rerun).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD:-build}
threads=${THREADS:-$(nproc)}
quick=${QUICK:-0}
scenes=${SCENES:-cornell-box,bunny-box,sphere,bunny-dragon}
if [[ $quick == 1 ]]; then
  runs=${RUNS:-1} size=${SIZE:-64} max_spp=${MAX_SPP:-64} ref_spp=${REF_SPP:-512}
  target=${TARGET:-1e-2} frames=${FRAMES:-4} pt_spp=${PT_SPP:-2}
  bench_mode=(--quick --repetitions "$runs")
else
  runs=${RUNS:-3} size=${SIZE:-256} max_spp=${MAX_SPP:-256} ref_spp=${REF_SPP:-2048}
  target=${TARGET:-1e-3} frames=${FRAMES:-40} pt_spp=${PT_SPP:-32}
  bench_mode=(--repetitions "$runs")
fi
converge_runs=${CONVERGE_RUNS:-$runs}
read -r -a bench_args <<<"${BENCH_ARGS:-}"
ref_seed=1000003  # the measured runs use the scene's own seed, 0
out=out/performance
images=docs/images
doc=docs/performance.md
mkdir -p "$out" "$images"
run_info=$out/run.env  # what the document says about the run: kept for REPORT_ONLY=1

if [[ ${REPORT_ONLY:-0} == 1 ]]; then
  # shellcheck source=/dev/null
  source "$run_info"
else
  tools/setup.sh
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  if ! cmake --build "$build" --target pt ray_bench; then
    echo "performance: ray_bench not built (CMake builds it where Google Benchmark is" \
      "found: libbenchmark-dev)" >&2
    exit 1
  fi
  pt=$build/pt
  bench=$build/bench/ray_bench
  export LP_NUM_THREADS=$threads
  started=$SECONDS
  rm -f "$out"/*.csv "$out"/*.txt

  # ---- 1. Ray throughput and agreement on every scene and backend ----------------------------
  echo "== ray_bench on $scenes"
  "$bench" --scenes "$scenes" --threads "$threads" "${bench_mode[@]}" "${bench_args[@]}" \
    --csv "$out/rays.csv" --agreement-csv "$out/agreement.csv" | tee "$out/ray_bench.txt"

  # ---- 2. Path tracing: Embree's tutorial against ours on the Cornell box --------------------
  # Embree's pathtracer reads the Cornell box as ray_bench writes it (the same triangles, the
  # camera, the emitter as a point light: its tutorial has no area lights) and counts its rays
  # itself (RayStats: one per rtcIntersect1 and rtcOccluded1); a shim that counts those calls
  # on their way into libembree3 checks that count once. Runs alternate between the two.
  echo "== path tracing, Cornell box ${size}x${size}"
  "$bench" --scenes cornell-box --size "$size" --export-embree "$out/cornell" >/dev/null
  embree_pt=(pathtracer -c "$out/cornell.ecs" --threads "$threads" --spp 1
    --max-path-length 64)
  shim=$out/count_rays.so
  cat >"$out/count_rays.c" <<'EOF'
// Counts the rays an Embree application traces one at a time (LD_PRELOAD), printed at exit.
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdatomic.h>
#include <stdio.h>
typedef void (*Trace)(void*, void*, void*);
static atomic_ulong intersect, occluded;
void rtcIntersect1(void* scene, void* context, void* ray) {
  static Trace next;
  if (!next) next = (Trace)dlsym(RTLD_NEXT, "rtcIntersect1");
  atomic_fetch_add_explicit(&intersect, 1, memory_order_relaxed);
  next(scene, context, ray);
}
void rtcOccluded1(void* scene, void* context, void* ray) {
  static Trace next;
  if (!next) next = (Trace)dlsym(RTLD_NEXT, "rtcOccluded1");
  atomic_fetch_add_explicit(&occluded, 1, memory_order_relaxed);
  next(scene, context, ray);
}
__attribute__((destructor)) static void report(void) {
  fprintf(stderr, "counted rtcIntersect1=%lu rtcOccluded1=%lu\n", (unsigned long)intersect,
          (unsigned long)occluded);
}
EOF
  counted=""
  have_embree_pt=1
  if ! command -v pathtracer >/dev/null; then
    have_embree_pt=0
    echo "Embree's pathtracer not found (Debian: embree-tools): its rows stay empty" |
      tee -a "$out/problems.txt"
  elif cc -O2 -shared -fPIC -o "$shim" "$out/count_rays.c" -ldl 2>"$out/shim.err"; then
    # Legacy benchmark mode, no warm-up: exactly $frames frames are rendered.
    LD_PRELOAD=$PWD/$shim "${embree_pt[@]}" --benchmark 0 "$frames" --legacy \
      >"$out/embree-count.txt" 2>&1 || true
    counted=$(sed -n 's/^counted rtcIntersect1=\([0-9]*\) rtcOccluded1=\([0-9]*\)/\1 \2/p' \
      "$out/embree-count.txt")
  fi
  : >"$out/pathtrace.txt"
  for ((run = 1; run <= runs; ++run)); do
    if ((have_embree_pt)); then
      "${embree_pt[@]}" --benchmark 2 "$frames" --legacy >"$out/embree-pt.$run.txt" 2>&1
      fps=$(sed -n 's/^BENCHMARK_RENDER_AVG //p' "$out/embree-pt.$run.txt")
      mrays=$(sed -n 's/^BENCHMARK_RENDER_MRAYPS_AVG //p' "$out/embree-pt.$run.txt")
      echo "embree $mrays $fps" | tee -a "$out/pathtrace.txt"
    fi
    for backend in cpu vulkan; do
      spp=$pt_spp
      if ! "$pt" render configs/cornell-box.json --backend "$backend" --threads "$threads" \
        --width "$size" --height "$size" --spp "$spp" --out "$out/pt-$backend.exr" \
        >"$out/pt-$backend.$run.txt" 2>"$out/pt-$backend.$run.err"; then
        echo "pt render --backend $backend failed: $(tail -1 "$out/pt-$backend.$run.err")" \
          >>"$out/problems.txt"
      fi
      sed -n "s/.* spp=\([0-9]*\) seconds=\([0-9.]*\) Mrays\/s=\([0-9.]*\).*/pt-$backend \3 \1 \2/p" \
        "$out/pt-$backend.$run.txt" | tee -a "$out/pathtrace.txt"
    done
  done

  # ---- 3. Time to relMSE $target on the Cornell box, each backend --------------------------
  ref=$out/cornell-box-ref-${size}px-${ref_spp}spp-seed$ref_seed.exr
  if [[ ${REUSE_REF:-0} == 1 && -f $ref ]]; then
    echo "== reusing $ref"
  else
    echo "== reference: Cornell box ${size}x${size}, CPU, $ref_spp spp, seed $ref_seed"
    "$pt" render configs/cornell-box.json --backend cpu --threads "$threads" --width "$size" \
      --height "$size" --spp "$ref_spp" --seed "$ref_seed" --out "$ref" 2>/dev/null
  fi
  rm -f "$out"/converge.*.csv
  for ((run = 1; run <= converge_runs; ++run)); do
    for backend in cpu vulkan; do
      echo "== pt converge, $backend, round $run of $converge_runs"
      if ! "$pt" converge configs/cornell-box.json --backend "$backend" --threads "$threads" \
        --width "$size" --height "$size" --max-spp "$max_spp" --reference "$ref" \
        --label baseline --csv "$out/converge.$backend.$run.csv" \
        >"$out/converge.$backend.$run.txt" 2>"$out/converge.$backend.$run.err"; then
        echo "pt converge --backend $backend failed: $(tail -1 "$out/converge.$backend.$run.err")" \
          >>"$out/problems.txt"
      fi
    done
  done

  elapsed=$((SECONDS - started))
  cpu_model=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1)
  vk_device=$("$pt" devices 2>/dev/null | head -1 | sed 's/^[0-9]*: //') || vk_device="(none)"
  embree_version=$(dpkg-query -W -f='${Version}' libembree3-3 2>/dev/null) || embree_version="?"
  run_date=$(date -u +%Y-%m-%d)
  load=$(cut -d' ' -f1-3 /proc/loadavg)
  declare -p quick runs converge_runs size max_spp ref_spp target frames pt_spp threads scenes elapsed \
    cpu_model vk_device embree_version run_date load counted ref_seed bench_args >"$run_info"
fi

# ---- Merge --------------------------------------------------------------------------------------
median() { sort -g | awk '{v[NR] = $1} END {if (NR) print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
g() { awk -v x="$1" 'BEGIN {if (x == "") print "—"; else printf "%.3g", x}'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN {if (a == "" || b == "" || b == 0) print "—"; else printf "%.2f", a / b}'; }

# Convergence: the median seconds of each level over the rounds (the errors do not depend on
# the round: the same sample indices give the same image).
converge=$out/converge.csv
{
  echo "backend,spp,seconds,relmse,mrays_per_s"
  for f in "$out"/converge.*.*.csv; do [[ -f $f ]] && tail -n +2 "$f"; done |
    awk -F, -v OFS=, '{print $2, $6, $7, $9, $10}' | sort -t, -k1,1 -k2,2n |
    awk -F, -v OFS=, '
      function median(list,   v, n, i, j, x) {
        n = split(list, v, " ")
        for (i = 2; i <= n; ++i) for (j = i; j > 1 && v[j - 1] + 0 > v[j] + 0; --j) {
          x = v[j]; v[j] = v[j - 1]; v[j - 1] = x
        }
        return n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2
      }
      function flush() { if (key != "") print key, median(secs), err, median(mrays) }
      { k = $1 OFS $2
        if (k != key) { flush(); key = k; secs = ""; mrays = "" }
        secs = secs " " $3; mrays = mrays " " $5; err = $4 }
      END { flush() }'
} >"$converge"

# Backends in the order ray_bench lists them, the reference (embree) last among the ratios.
backends=$(awk -F, 'NR > 1 && !seen[$5]++ {print $5}' "$out/rays.csv" | tr '\n' ' ')
reference=embree

# ---- Plots ----------------------------------------------------------------------------------------
if gnuplot -e 'set terminal' 2>&1 | grep -q pngcairo; then
  term="pngcairo size 900,560 font ',10'"
else
  term="png size 900,560"
fi
rm -f "$images"/performance-*.png
# Mrays/s per scene and ray type, one bar per backend, log scale.
awk -F, -v backends="$backends" '
  NR > 1 { key = $1 " " $3; if (!(key in seen)) { seen[key] = 1; order[++n] = key }; v[key, $5] = $6 }
  END {
    nb = split(backends, B, " ")
    for (i = 1; i <= n; ++i) {
      split(order[i], k, " "); line = k[1] "/" k[2]
      for (b = 1; b <= nb; ++b) line = line " " ((order[i], B[b]) in v ? v[order[i], B[b]] : "NaN")
      print line
    }
  }' "$out/rays.csv" >"$out/rays.dat"
colors=('#1b9e77' '#d95f02' '#7570b3' '#e7298a' '#66a61e' '#e6ab02')
cmds=() i=0
for b in $backends; do
  col=$((i + 2))
  if ((i == 0)); then
    cmds+=("'$out/rays.dat' using $col:xtic(1) title '$b' lc rgb '${colors[$i]}'")
  else
    cmds+=("'' using $col title '$b' lc rgb '${colors[$i]}'")
  fi
  i=$((i + 1))
done
gnuplot <<EOF
set terminal $term
set output '$images/performance-rays.png'
set title "Ray throughput, ${threads} CPU threads (Mrays/s, median of $runs; higher is better)" noenhanced
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.9 border -1
set logscale y
set ylabel 'Mrays/s'
set xtics rotate by 35 right noenhanced
set grid ytics lc rgb '#dddddd'
set key outside top center horizontal reverse Left noenhanced
set lmargin 14
set bmargin 7
plot $(IFS=,; echo "${cmds[*]}")
EOF
# relMSE against time, both backends, and the target.
plot=()
for backend in cpu vulkan; do
  awk -F, -v b="$backend" 'NR > 1 && $1 == b {print $3, $4}' "$converge" >"$out/converge.$backend.dat"
  [[ -s $out/converge.$backend.dat ]] || continue
  dt=1 pt_=7
  [[ $backend == vulkan ]] && dt=2 pt_=6
  plot+=("'$out/converge.$backend.dat' using 1:2 with linespoints dt $dt pt $pt_ title '$backend'")
done
plot+=("$target with lines lc rgb 'gray50' dt 3 title 'target relMSE $target'")
gnuplot <<EOF
set terminal $term
set output '$images/performance-converge.png'
set title "Cornell box ${size}x${size}: relMSE against render time (pt converge)" noenhanced
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set xlabel 'cumulative render time (s): CPU wall clock, Vulkan device timestamps'
set ylabel 'relMSE against the reference'
set grid xtics ytics mxtics mytics lc rgb '#dddddd'
set key inside bottom left noenhanced box opaque
plot $(IFS=,; echo "${plot[*]}")
EOF

# ---- Tables -----------------------------------------------------------------------------------------
rays_table() {
  awk -F, -v backends="$backends" -v ref="$reference" '
    NR > 1 { key = $1 SUBSEP $3; if (!(key in seen)) { seen[key] = 1; order[++n] = key }
             tris[key] = $2; count[key] = $4; v[key, $5] = $6 }
    END {
      nb = split(backends, B, " ")
      head = "| scene | triangles | rays | type |"; rule = "|---|--:|--:|---|"
      for (b = 1; b <= nb; ++b) { head = head " " B[b] " |"; rule = rule "--:|" }
      for (b = 1; b <= nb; ++b) if (B[b] != ref) { head = head " " B[b] " / " ref " |"; rule = rule "--:|" }
      print head; print rule
      for (i = 1; i <= n; ++i) {
        split(order[i], k, SUBSEP)
        line = sprintf("| %s | %d | %d | %s |", k[1], tris[order[i]], count[order[i]], k[2])
        for (b = 1; b <= nb; ++b)
          line = line " " (((order[i], B[b]) in v) ? sprintf("%.3g", v[order[i], B[b]]) : "—") " |"
        for (b = 1; b <= nb; ++b) if (B[b] != ref) {
          r = "—"
          if (((order[i], B[b]) in v) && ((order[i], ref) in v) && v[order[i], ref] > 0)
            r = sprintf("%.2f", v[order[i], B[b]] / v[order[i], ref])
          line = line " " r " |"
        }
        print line
      }
    }' "$out/rays.csv"
}
agreement_table() {
  awk -F, '
    NR > 1 { key = $1 SUBSEP $2; pair = $3 "–" $4
             if (!(key in seen)) { seen[key] = 1; order[++n] = key }
             if (!(pair in pseen)) { pseen[pair] = 1; pairs[++np] = pair }
             c[key, pair] = $6 " / " $5; if ($6 > 0) bad[key, pair] = 1 }
    END {
      head = "| scene | type |"; rule = "|---|---|"
      for (p = 1; p <= np; ++p) { head = head " " pairs[p] " |"; rule = rule "--:|" }
      print head; print rule
      for (i = 1; i <= n; ++i) {
        split(order[i], k, SUBSEP); line = "| " k[1] " | " k[2] " |"
        for (p = 1; p <= np; ++p) {
          cell = ((order[i], pairs[p]) in c) ? c[order[i], pairs[p]] : "—"
          if ((order[i], pairs[p]) in bad) cell = "**" cell "**"
          line = line " " cell " |"
        }
        print line
      }
    }' "$out/agreement.csv"
}
time_to_target() {  # backend: seconds at which relMSE first crosses the target (log-log interpolation)
  awk -F, -v b="$1" -v target="$target" '
    function lerp(x, x0, x1, y0, y1) { return y0 + (x - x0) / (x1 - x0) * (y1 - y0) }
    NR > 1 && $1 == b { ++n; s[n] = $2; t[n] = $3; r[n] = $4; m[n] = $5 }
    END {
      if (!n) { print "— | — | — | —"; exit }
      if (r[1] <= target) { printf "≤ %.3g | ≤ %d", t[1], s[1] }
      else {
        for (i = 2; i <= n; ++i) if (r[i] <= target) break
        if (i > n) printf "not reached | > %d", s[n]
        else printf "%.3g | %.0f", exp(lerp(log(target), log(r[i - 1]), log(r[i]), log(t[i - 1]), log(t[i]))),
          exp(lerp(log(target), log(r[i - 1]), log(r[i]), log(s[i - 1]), log(s[i])))
      }
      printf " | %.3g | %d spp: %.3g s, relMSE %.3g\n", m[n], s[n], t[n], r[n]
    }' "$converge"
}
floor_estimate() {
  awk -F, -v m="$max_spp" -v r="$ref_spp" -v target="$target" '
    NR > 1 && $1 == "cpu" {e = $4} END {
      if (e == "") print "not measured"
      else printf "%.2g (%.0f%% of the target)", e * m / r, 100 * e * m / r / target }' "$converge"
}
pt_field() {  # name column(2 Mrays/s, 3 fps or spp, 4 seconds): median over runs
  awk -v n="$1" -v c="$2" '$1 == n {print $c}' "$out/pathtrace.txt" | median
}
embree_mrays=$(pt_field embree 2) embree_fps=$(pt_field embree 3)
cpu_mrays=$(pt_field pt-cpu 2) cpu_spp=$(pt_field pt-cpu 3) cpu_secs=$(pt_field pt-cpu 4)
vk_mrays=$(pt_field pt-vulkan 2) vk_spp=$(pt_field pt-vulkan 3) vk_secs=$(pt_field pt-vulkan 4)
pixels=$((size * size))
per_path() { awk -v m="$1" -v s="$2" -v spp="$3" -v p="$pixels" 'BEGIN {if (m == "" || s == "") print "—"; else printf "%.2f", m * 1e6 * s / (p * spp)}'; }
embree_per_path=$(awk -v m="$embree_mrays" -v f="$embree_fps" -v p="$pixels" 'BEGIN {if (m == "" || f == "") print "—"; else printf "%.2f", m * 1e6 / f / p}')
count_line="not checked in this run (no C compiler for the shim, or no pathtracer)"
if [[ -n $counted ]]; then
  read -r n_isect n_occl <<<"$counted"
  count_line=$(awk -v i="$n_isect" -v o="$n_occl" -v f="$frames" -v p="$pixels" -v m="$embree_mrays" -v fps="$embree_fps" 'BEGIN {
    c = (i + o) / f; e = m * 1e6 / fps
    printf "%.4g rays per frame counted (%.4g rtcIntersect1 + %.4g rtcOccluded1 calls over %d frames), against %.4g from Embree'"'"'s own counter (median Mrays/s over median frames/s): %+.1f%%", c, i / f, o / f, f, e, 100 * (e - c) / c }')
fi

# ---- The document -----------------------------------------------------------------------------------
notes=""
if [[ -f $doc ]] && grep -q '<!-- notes:begin -->' "$doc"; then
  notes=$(sed -n '/<!-- notes:begin -->/,/<!-- notes:end -->/p' "$doc")
fi
[[ -n $notes ]] || notes=$'<!-- notes:begin -->\n(none yet)\n<!-- notes:end -->'
quick_note=""
if [[ $quick == 1 ]]; then
  quick_note=$'\n> **QUICK=1 run**: tiny ray sets, one repetition, a small image and a loose target. It only\n> shows that the script works; none of its numbers are for quoting. Rerun without QUICK.\n'
fi
{
  cat <<EOF
# Speed on every backend

Generated by \`tools/performance.sh\` on $run_date (UTC); every number and plot below comes
from that run.
$quick_note
- Machine: $(nproc) cores ($cpu_model), $threads CPU threads for every CPU measurement and for
  lavapipe (LP_NUM_THREADS); load average $load when the run ended. Vulkan device: $vk_device.
- Embree $embree_version (Debian's libembree3 and embree-tools).
- The whole run took $((elapsed / 60)) min $((elapsed % 60)) s of wall time, one measurement at a time.
- Every number is the median of $runs repetitions. On a machine shared with other work only
  ratios taken in the same run mean much; the absolute numbers move with the load.

## How to rerun

\`\`\`sh
tools/performance.sh                      # QUICK=1 tools/performance.sh: a minute, to test it
build/bench/ray_bench --quick             # the ray benchmark alone, seconds
build/bench/ray_bench --scenes sphere --backends cpu,embree --repetitions 5
\`\`\`

The script installs packages and builds like the other tools, runs everything into
\`out/performance/\` and rewrites this file (the notes block at the end is kept). \`THREADS\`,
\`RUNS\`, \`SCENES\`, \`BENCH_ARGS\`, \`SIZE\`, \`MAX_SPP\`, \`REF_SPP\`, \`TARGET\`, \`FRAMES\`,
\`PT_SPP\` and \`BUILD\` override the defaults; \`REPORT_ONLY=1\` redraws the plots and this file
from the last run. \`ray_bench --help\` lists its options; it also takes Google Benchmark's
\`--benchmark_*\` flags (e.g. \`--benchmark_filter=sphere/.*\`).

## Ray throughput

![Mrays/s per scene, ray type and backend](images/performance-rays.png)

Mrays/s of \`ray_bench\` (${bench_args[*]:-default options}), median of $runs; the last columns are
ratios to Embree in the same run (above 1: faster than Embree).

$(rays_table)

How it is measured:

- **Ray sets**, fixed per scene and made from the renderer's own scene data and random numbers
  (sample 0 of every pixel): **primary**: one camera ray per pixel, jittered in the pixel
  (closest hit, coherent); **bounce**: from every primary hit, a cosine-weighted direction
  about the normal from the integrator's offset origin (closest hit, incoherent); **shadow**:
  from every primary hit to a point on an emitter picked as next-event estimation picks it,
  traced only where both sides face each other, as the integrator does (any hit, \`0 < t < 1\`).
  The sphere (1,051,200 triangles, \`uvSphere(726, 725)\` of \`bench/bench_util.h\`) gets a
  camera at 3.4 radii and a small light out of view; it is convex, so its shadow rays are
  rarely occluded and must prove that nothing is in the way.
- **cpu**: \`closestHit\` / \`anyHit\` of \`host/bvh/traverse.h\` over the tree the renderer builds
  for the CPU (the default builder and leaf size, 8, unless \`BENCH_ARGS\` says otherwise; every
  backend here traces that tree, though the Vulkan renderer's own default is 3 per leaf), the
  batch spread over the threads.
- **cpu-wide**: the same queries over the 8-wide tree collapsed from it (\`host/bvh/wide_bvh.h\`),
  which the CPU renderer traverses.
- **vulkan**: the ray-query shader (\`shaders/raycast.comp\`, the path tracer's traversal) through
  \`traceRaysVulkan\`, which sets up a context, compiles the shader and uploads the BVH and the
  rays into device-local buffers on every call; what is timed is the dispatch alone (timestamp
  queries around it: reading the rays from device memory, tracing, writing the hits), as the
  path tracer's Vulkan times are. A set is traced as copies of itself up to 2^20 rays per
  dispatch, enough to fill a GPU. On lavapipe this is the CPU again, through LLVM-compiled
  SPIR-V, eight rays to a vector, with a few milliseconds per dispatch of its own.
- **embree**: \`rtcIntersect1\` / \`rtcOccluded1\` one ray at a time over Embree's own BVH
  (default scene flags and build quality), on the same threads.
- Time per repetition is Google Benchmark's (manual time: the call's wall clock, or the
  dispatch's device time), at least \`--min-time\` (0.5 s unless quick) per repetition;
  repetitions of all backends of a scene run in random order, so that a slow spell of the
  machine does not fall on one backend only.

### Do the backends find the same hits?

Rays whose results differ / rays compared, for every pair of backends and against a
double-precision brute force (Möller–Trumbore over every triangle; on large scenes an evenly
spread subset of the rays, to bound its cost). Closest hits agree when both miss or their
distances agree to 1e-5 of the larger of the distance and the origin's largest coordinate
(a hit computed in float is only as exact as its coordinates); shadow rays when both are
occluded or both clear. Non-zero counts are in bold; \`out/performance/ray_bench.txt\` spells
out the first three rays of each, with the brute force's answer.

$(agreement_table)

## Path tracing: our CPU reference against Embree's path tracer

The Cornell box at ${size}x${size}, $threads threads, median of $runs runs (alternating).

| renderer | Mrays/s | rays per path | settings |
|---|--:|--:|---|
| Embree's \`pathtracer\` tutorial (embree-tools) | $(g "$embree_mrays") | $embree_per_path | 1 spp per frame, $frames frames after 2 warm-up, \`--max-path-length 64\`, $(g "$embree_fps") frames/s |
| \`pt render --backend cpu\` | $(g "$cpu_mrays") | $(per_path "$cpu_mrays" "$cpu_secs" "$cpu_spp") | $cpu_spp spp in $(g "$cpu_secs") s, the scene's settings (NEE+MIS, Russian roulette from depth 3, max depth 64) |
| \`pt render --backend vulkan\` | $(g "$vk_mrays") | $(per_path "$vk_mrays" "$vk_secs" "$vk_spp") | $vk_spp spp in $(g "$vk_secs") s (device time), on $vk_device |

Our CPU path tracer runs at **$(ratio "$cpu_mrays" "$embree_mrays")×** Embree's path tracer's rays/s.

How the Embree numbers come about, and what they compare:

- Embree's tutorial reads the Cornell box from \`out/performance/cornell.{obj,mtl,ecs}\`, which
  \`ray_bench --export-embree\` writes from the same triangles \`pt\` loads, with the same camera
  and diffuse reflectances. Its scene code has no area lights (\`QuadLight\` is parsed but not
  converted), so the light becomes a point light at its centre, just below it, as Embree's own
  Cornell box scene for this tutorial does; the light quad stays in as black geometry.
- **Its rays/s is its own count**: the tutorial counts one ray per \`rtcIntersect1\` and per
  \`rtcOccluded1\` (its RayStats) and prints Mrays/s per frame (\`BENCHMARK_RENDER_MRAYPS_AVG\`).
  Checked in this run by a shim that counts those calls on their way into libembree3
  (LD_PRELOAD): $count_line.
- Ours counts the same way (every closest-hit and every any-hit ray) over the render's wall
  clock. Both count camera, bounce and shadow rays, one shadow ray per diffuse vertex.
- The integrators differ, so the rays per path differ: Embree's stops a path when its
  throughput falls below 0.01 (no Russian roulette) and traces a shadow ray at every vertex;
  ours uses Russian roulette from the third bounce and MIS. Rays/s is the fair measure here
  (work per ray: traversal plus shading), not frames/s. Embree's tutorial is C++ with
  Embree's single-ray calls, not its ISPC or packet variants.
- Not done: our integrator's exact ray stream over Embree's traversal. It would need a
  traversal hook in \`host/cpu/integrator_lanes.cpp\`; Embree's own path tracer with its own count is
  the comparison the goal asks for. The ray benchmark above gives the traversal-only ratio.

## Time to relMSE $target, Cornell box ${size}x${size}

![relMSE against time](images/performance-converge.png)

\`pt converge\` on each backend, levels 1, 2, 4, … $max_spp spp, against a CPU reference of
$ref_spp spp (seed $ref_seed; the runs use the scene's seed 0). Seconds are the medians over
$converge_runs rounds; the time to the target is interpolated on the log-log curve between levels.

| backend | seconds to relMSE $target | spp at the target | Mrays/s | last level |
|---|--:|--:|--:|---|
| cpu | $(time_to_target cpu) |
| vulkan | $(time_to_target vulkan) |

Both backends take the same samples (the same sample indices give the same image), so they
reach the target at the same spp and differ only in time. The reference's own noise is in
every relMSE: about the error at $max_spp spp times $max_spp/$ref_spp, here $(floor_estimate),
which makes the time to the target slightly longer on both backends alike. Seconds: CPU wall
clock of the render; Vulkan device timestamps around the dispatches (no set-up, compilation
or upload), as in [accuracy.md](accuracy.md).
EOF
  if [[ -s $out/problems.txt ]]; then
    printf '\n## Problems in this run\n\n'
    sed 's/^/- /' "$out/problems.txt"
  fi
  cat <<EOF

## Notes on this run

Hand-written observations; they describe the run this file was generated from and are kept
when the script rewrites the file, so check them against the tables after a rerun.

$notes
EOF
} >"$doc"
echo "wrote $doc and $images/performance-*.png (${elapsed}s of measuring)"
