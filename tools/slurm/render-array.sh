#!/usr/bin/env bash
# Renders a scene on a Slurm cluster: a job array with one slice of the sample indices per
# task (`pt render --task-index`), and a merge job that runs once every task has succeeded
# (`pt merge`) and writes the image, the same bits as one render of all the samples.
#
# tools/slurm/render-array.sh SCENE --tasks N [--spp S] [--out FILE]... [--dir DIR]
#     [--only LIST] [--pt PATH] [--job-name NAME] [--sbatch ARG]... [-- RENDER OPTION...]
#
#   --tasks N      slices (array tasks); Slurm allows indices up to MaxArraySize-1 (1000)
#   --spp S        samples per pixel of the whole render (default: the scene's)
#   --out FILE     what the merge job writes (.exr, .pfm, .png or .ptstate); repeatable;
#                  default: SCENE's name with .exr, in the current directory
#   --dir DIR      slice film states, job scripts and logs (default: FIRST_OUT.slices)
#   --only LIST    submit only these task indices (sbatch --array syntax, e.g. 2 or 1,3-4),
#                  to render failed slices again; the merge job still merges all N
#   --pt PATH      the pt binary (default: $PT, else build/pt of this repository)
#   --sbatch ARG   passed to both sbatch calls, e.g. --sbatch=--partition=gpu; repeatable
#   -- ...         options for every `pt render`, e.g. -- --backend cpu --width 1024
#
# Every path must be on a file system the compute nodes share. A task resumes its slice's
# film state when one is there (after a pre-emption or a failure), so resubmitting is
# always safe. Prints "array_job=ID tasks=LIST" and "merge_job=ID".
set -euo pipefail

usage() {
  sed -n '6,7p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
die() {
  echo "render-array.sh: $*" >&2
  exit 2
}

repo=$(cd "$(dirname "$0")/../.." && pwd)
scene="" tasks="" spp="" dir="" only="" pt="${PT:-$repo/build/pt}" name=""
outs=() sbatchArgs=() renderArgs=()
while (($#)); do
  case "$1" in
    --tasks) tasks=${2:?}; shift 2 ;;
    --spp) spp=${2:?}; shift 2 ;;
    --out) outs+=("${2:?}"); shift 2 ;;
    --dir) dir=${2:?}; shift 2 ;;
    --only) only=${2:?}; shift 2 ;;
    --pt) pt=${2:?}; shift 2 ;;
    --job-name) name=${2:?}; shift 2 ;;
    --sbatch) sbatchArgs+=("${2:?}"); shift 2 ;;
    --sbatch=*) sbatchArgs+=("${1#--sbatch=}"); shift ;;
    --) shift; renderArgs=("$@"); break ;;
    -h|--help) usage ;;
    -*) die "unknown option '$1'" ;;
    *) [ -z "$scene" ] || die "one scene only (got '$scene' and '$1')"; scene=$1; shift ;;
  esac
done
if [ -z "$scene" ] || [ -z "$tasks" ]; then usage; fi
[[ "$tasks" =~ ^[1-9][0-9]*$ ]] || die "--tasks: expected a positive number, got '$tasks'"
[ -z "$spp" ] || [[ "$spp" =~ ^[1-9][0-9]*$ ]] || die "--spp: expected a positive number"
[ -f "$scene" ] || die "$scene: not found"
[ -x "$pt" ] || die "$pt: no pt binary there (build it, or give --pt PATH or PT=PATH)"
command -v sbatch >/dev/null || die "sbatch not found: run this on a Slurm login node"

# Absolute paths: the jobs run elsewhere, in another directory.
scene=$(realpath "$scene")
pt=$(realpath "$pt")
stem=$(basename "${scene%.*}")
((${#outs[@]})) || outs=("$PWD/$stem.exr")
for i in "${!outs[@]}"; do outs[i]=$(realpath -m "${outs[i]}"); done
dir=$(realpath -m "${dir:-${outs[0]}.slices}")
name=${name:-pt-$stem}
mkdir -p "$dir"
for out in "${outs[@]}"; do mkdir -p "$(dirname "$out")"; done

# The job scripts, written out so that they can be read and resubmitted by hand.
q() {
  local a
  for a in "$@"; do printf '%q ' "$a"; done
}
sppArgs=()
[ -z "$spp" ] || sppArgs=(--spp "$spp")
cat >"$dir/task.sh" <<TASK
#!/usr/bin/env bash
# One slice of the render: task \$SLURM_ARRAY_TASK_ID of $tasks (written by render-array.sh).
set -euo pipefail
state=$(printf %q "$dir")/slice-\$SLURM_ARRAY_TASK_ID.ptstate
resume=()
[ ! -f "\$state" ] || resume=(--resume "\$state")
threads=()
cpus=\${SLURM_CPUS_PER_TASK:-\${SLURM_CPUS_ON_NODE:-}}
[ -z "\$cpus" ] || threads=(--threads "\$cpus")
exec $(q "$pt") render $(q "$scene") --task-count $tasks $(q "${sppArgs[@]}")\\
  --checkpoint "\$state" "\${resume[@]}" "\${threads[@]}" $(q "${renderArgs[@]}")
TASK
states=()
for ((t = 0; t < tasks; ++t)); do states+=("$dir/slice-$t.ptstate"); done
outArgs=()
for out in "${outs[@]}" "$dir/merged.ptstate"; do outArgs+=(--out "$out"); done
cat >"$dir/merge.sh" <<MERGE
#!/usr/bin/env bash
# Merges the $tasks slices into the image (written by render-array.sh).
set -euo pipefail
exec $(q "$pt") merge $(q "${states[@]}") $(q "${outArgs[@]}")
MERGE
chmod +x "$dir/task.sh" "$dir/merge.sh"

array=${only:-0-$((tasks - 1))}
arrayJob=$(sbatch --parsable --job-name="$name" --array="$array" \
  --output="$dir/slice-%a.log" "${sbatchArgs[@]}" "$dir/task.sh")
arrayJob=${arrayJob%%;*}  # "ID;CLUSTER" on federated clusters
# Without --kill-on-invalid-dep a merge whose slices failed would stay pending forever.
mergeJob=$(sbatch --parsable --job-name="$name-merge" --dependency="afterok:$arrayJob" \
  --kill-on-invalid-dep=yes --output="$dir/merge.log" "${sbatchArgs[@]}" "$dir/merge.sh")
mergeJob=${mergeJob%%;*}
echo "array_job=$arrayJob tasks=$array"
echo "merge_job=$mergeJob"
echo "slices, scripts and logs in $dir; the merge writes ${outs[*]}" >&2
