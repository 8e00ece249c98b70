#!/usr/bin/env bash
# A real single-node Slurm cluster: starts a private munged, slurmctld and slurmd on
# 127.0.0.1 (configuration and state in a temporary directory, nothing in /etc), renders the
# Cornell box as a job array with tools/slurm/render-array.sh, and checks that the merged
# image is the one-run image bit for bit; then that a failing task cancels the merge, and that
# resubmitting that slice and merging again gives the right image. Every daemon it started is
# stopped by its PID, also when a check fails. Installs slurm-wlm and munge when missing
# (exit 77, "skipped", where it cannot).
#
# tests/slurm_test.sh PT_BINARY     (CTest runs it: ctest -L slurm)
set -euo pipefail

pt=$(realpath "${1:?usage: slurm_test.sh PT_BINARY}")
repo=$(cd "$(dirname "$0")/.." && pwd)
started=$(date +%s%N)
say() { echo "slurm_test: $*"; }
fail() {
  say "FAILED: $*"
  exit 1
}

# ---- Packages -------------------------------------------------------------------------------
missing=()
for p in slurm-wlm munge; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    sudo -n true 2>/dev/null || { say "skipped: ${missing[*]} missing and no root"; exit 77; }
    sudo="sudo -n"
  fi
  say "installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null ||
    { $sudo apt-get update -qq && $sudo apt-get install -y -qq --no-install-recommends \
      "${missing[@]}" >/dev/null; }
fi
if [ "$(id -u)" -ne 0 ]; then
  say "skipped: the private daemons run as root (SlurmUser=root) and munged as user munge"
  exit 77
fi

# ---- Work directory and clean-up ------------------------------------------------------------
work=$(mktemp -d /tmp/pt-slurm.XXXXXX)
chmod 755 "$work"  # munged, as user munge, reaches its socket directory through it
pids=()            # daemons in start order
export SLURM_CONF="$work/slurm.conf"

cleanup() {
  local status=$?
  set +e
  if [ -f "$work/slurmctld.pid" ] || ((${#pids[@]} > 1)); then
    # Jobs first: steps outlive slurmd, so wait until none is left on the node.
    squeue -h -o %A 2>/dev/null | xargs -r scancel 2>/dev/null
    for ((i = 0; i < 100; ++i)); do
      [ -z "$(squeue -h 2>/dev/null)" ] && [ -z "$(scontrol listpids 2>/dev/null | tail -n +2)" ] &&
        break
      sleep 0.1
    done
  fi
  # Then the daemons, newest first, each by the PID recorded when it started.
  for ((i = ${#pids[@]} - 1; i >= 0; --i)); do
    local pid=${pids[$i]}
    kill -TERM "$pid" 2>/dev/null || continue
    for ((j = 0; j < 100; ++j)); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -0 "$pid" 2>/dev/null && kill -KILL "$pid" 2>/dev/null
  done
  if [ "$status" -ne 0 ] && [ "$status" -ne 77 ]; then
    for log in "$work"/*.log "$work"/*/*.log "$work"/*/*/*.log; do
      [ -f "$log" ] && { echo "---- $log"; tail -n 20 "$log"; }
    done
  fi
  rm -rf "$work"
  local ms=$((($(date +%s%N) - started) / 1000000))
  say "$( ((status == 0)) && echo passed || echo "exit $status") in $((ms / 1000)).$(printf %03d $((ms % 1000))) s"
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# A free port on 127.0.0.1, so that nothing else's Slurm is disturbed.
freePort() {
  local port
  while :; do
    port=$((20000 + RANDOM % 20000))
    (echo >"/dev/tcp/127.0.0.1/$port") 2>/dev/null || { echo "$port"; return; }
  done
}

# Waits for a PID file and records its PID.
recordPid() {
  for ((i = 0; i < 100; ++i)); do
    if [ -s "$1" ]; then
      pids+=("$(cat "$1")")
      return
    fi
    sleep 0.05
  done
  fail "no $1: the daemon did not start"
}

# ---- munged ---------------------------------------------------------------------------------
mkdir -p "$work/munge"
chown munge:munge "$work/munge"
chmod 755 "$work/munge"  # 0700 fails: "Socket is inaccessible"
runuser -u munge -- mungekey --create --keyfile="$work/munge/munge.key"
chmod 400 "$work/munge/munge.key"
runuser -u munge -- munged --socket="$work/munge/munge.socket" \
  --key-file="$work/munge/munge.key" --pid-file="$work/munge/munged.pid" \
  --log-file="$work/munge/munged.log" --seed-file="$work/munge/munged.seed"
recordPid "$work/munge/munged.pid"

# ---- slurmctld and slurmd -------------------------------------------------------------------
host=$(hostname -s)
mkdir -p "$work/state" "$work/spool"
cat >"$SLURM_CONF" <<CONF
ClusterName=ptci
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$(freePort)
SlurmdPort=$(freePort)
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge/munge.socket
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerParameters=batch_sched_delay=0
ReturnToService=2
MpiDefault=none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=ci Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -f "$SLURM_CONF"
recordPid "$work/slurmctld.pid"
slurmd -f "$SLURM_CONF"
recordPid "$work/slurmd.pid"
for ((i = 0; i < 200; ++i)); do
  [ "$(sinfo -h -o %T 2>/dev/null)" = idle ] && break
  sleep 0.1
done
[ "$(sinfo -h -o %T)" = idle ] || fail "the node is not idle: $(sinfo -h -o %T)"
say "cluster up (munged, slurmctld, slurmd: PIDs ${pids[*]})"

# ---- The render -----------------------------------------------------------------------------
# The state of a job, once it has left the queue.
finalState() {
  local state
  for ((i = 0; i < 600; ++i)); do
    state=$(scontrol show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | head -n 1)
    case "${state#JobState=}" in
      PENDING|RUNNING|COMPLETING|CONFIGURING|"") sleep 0.1 ;;
      *) echo "${state#JobState=}"; return ;;
    esac
  done
  echo TIMEOUT
}
jobId() { sed -n "s/^$1=\([0-9]*\).*/\1/p"; }

scene="$repo/configs/cornell-box.json"
options=(--backend cpu --width 32 --height 32)
"$pt" render "$scene" "${options[@]}" --spp 24 --out "$work/one-run.pfm" >/dev/null

submit() {
  "$repo/tools/slurm/render-array.sh" "$scene" --tasks 4 --spp 24 --pt "$pt" "$@" -- \
    "${options[@]}"
}

say "array of 4 slices and a merge"
ids=$(submit --out "$work/a/box.pfm")
echo "$ids"
merge=$(jobId merge_job <<<"$ids")
[ "$(finalState "$merge")" = COMPLETED ] || fail "merge job $merge: $(finalState "$merge")"
cmp "$work/a/box.pfm" "$work/one-run.pfm" || fail "the merged image is not the one-run image"
say "merged image = one-run image"

say "a failing task cancels the merge"
mkdir -p "$work/b/box.pfm.slices/slice-2.ptstate"  # task 2 cannot write its state
ids=$(submit --out "$work/b/box.pfm")
array=$(jobId array_job <<<"$ids")
merge=$(jobId merge_job <<<"$ids")
state=$(finalState "$merge")
[ "$state" = CANCELLED ] || fail "merge job $merge after a failed task: $state"
[ "$(finalState "${array}_2")" = FAILED ] || fail "task 2: $(finalState "${array}_2")"
[ ! -e "$work/b/box.pfm" ] || fail "the cancelled merge wrote an image"
grep -q "is a directory" "$work/b/box.pfm.slices/slice-2.log" || fail "task 2 failed otherwise"

say "resubmitting slice 2 and merging again"
rmdir "$work/b/box.pfm.slices/slice-2.ptstate"
ids=$(submit --out "$work/b/box.pfm" --only 2)
echo "$ids"
merge=$(jobId merge_job <<<"$ids")
[ "$(finalState "$merge")" = COMPLETED ] || fail "merge job $merge: $(finalState "$merge")"
cmp "$work/b/box.pfm" "$work/one-run.pfm" || fail "the merged image is not the one-run image"
say "merged image after resubmission = one-run image"
