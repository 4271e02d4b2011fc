#!/usr/bin/env bash
# A single-node Slurm on this (Debian) machine, then the bundled sweep as a 4-task job array
# through the shipped job script, merged and compared with the unsharded run.
#
#   scripts/slurm-local.sh [SWEEP.toml]     # default examples/sweep-mount.toml; needs root
#
# Steps (each idempotent: a second run reuses what the first set up):
# 1. apt-get install slurm-wlm munge (after apt-get update) unless slurmctld and munged exist;
# 2. a munge key if none, munged started as the munge user;
# 3. /etc/slurm/slurm.conf naming this host (its CPUs and memory from `slurmd -C`),
#    ProctrackType=proctrack/linuxproc, TaskPlugin=task/none, no accounting; slurmctld and slurmd;
# 4. the sweep unsharded, then `sbatch --array=0-3 --wait deploy/slurm/sweep.sbatch`, then
#    `groundtruth sweep merge`;
# 5. the sorted results.csv and results.jsonl of both compared byte for byte;
# 6. examples/dataset-semantickitti.toml as a dataset, unsharded and as a 3-task array
#    (`sweep.sbatch --job dataset`) into one directory, compared with `diff -r`, then verified.
# Exits non-zero on any failure or difference. The daemons this script started are stopped at the
# end unless KEEP_SLURM=1. Work files go to $WORK (default a temporary directory, removed).
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)
sweep=$(realpath "${1:-examples/sweep-mount.toml}")
start=$(date +%s)
log() { echo "[slurm-local $(( $(date +%s) - start ))s] $*"; }
[ "$(id -u)" = 0 ] || { echo "slurm-local.sh: run as root (installs packages, starts daemons)" >&2; exit 2; }

# 1. Packages.
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null || ! command -v sbatch >/dev/null; then
  log "installing slurm-wlm and munge"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi

# 2. munge.
started=()
if [ ! -s /etc/munge/munge.key ]; then
  log "creating a munge key"
  if command -v mungekey >/dev/null; then mungekey --create --force; else
    dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key status=none; fi
fi
mkdir -p /run/munge /var/lib/munge /var/log/munge
chown -R munge:munge /etc/munge /run/munge /var/lib/munge /var/log/munge
chmod 0700 /etc/munge && chmod 0400 /etc/munge/munge.key && chmod 0755 /run/munge
running() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }
if ! running /run/munge/munged.pid; then
  log "starting munged as munge"
  runuser -u munge -- /usr/sbin/munged
  started+=(munged)
  for _ in $(seq 50); do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.1; done
  munge -n | unmunge >/dev/null || { echo "munged does not answer" >&2; exit 1; }
fi

# 3. Slurm.
host=$(hostname -s)
node=$(slurmd -C | head -n 1)   # NodeName=<host> CPUs=.. Boards=.. ... RealMemory=..
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
conf=$(cat <<CONF
# Written by groundtruth scripts/slurm-local.sh: a single-node test cluster.
ClusterName=groundtruth
SlurmctldHost=$host
AuthType=auth/munge
SlurmUser=root
SlurmdUser=root
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
$node State=UNKNOWN
PartitionName=main Nodes=$host Default=YES MaxTime=INFINITE State=UP OverSubscribe=YES
CONF
)
if [ ! -f /etc/slurm/slurm.conf ] || [ "$(cat /etc/slurm/slurm.conf)" != "$conf" ]; then
  log "writing /etc/slurm/slurm.conf"
  printf '%s\n' "$conf" > /etc/slurm/slurm.conf
  if scontrol ping >/dev/null 2>&1; then scontrol reconfigure || true; fi
fi
if ! running /run/slurmctld.pid; then
  log "starting slurmctld"
  slurmctld
  started+=(slurmctld)
fi
if ! running /run/slurmd.pid; then
  log "starting slurmd"
  slurmd
  started+=(slurmd)
fi
stop_daemons() {
  [ "${KEEP_SLURM:-0}" = 1 ] && return 0
  for d in "${started[@]}"; do
    case $d in
      slurmd) [ -f /run/slurmd.pid ] && kill "$(cat /run/slurmd.pid)" 2>/dev/null || true ;;
      slurmctld) [ -f /run/slurmctld.pid ] && kill "$(cat /run/slurmctld.pid)" 2>/dev/null || true ;;
      munged) [ -f /run/munge/munged.pid ] && kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true ;;
    esac
  done
}
work=${WORK:-$(mktemp -d)}
cleanup() {
  stop_daemons
  [ -n "${WORK:-}" ] || rm -rf "$work"
}
trap cleanup EXIT
state=
for _ in $(seq 150); do
  state=$(sinfo -h -n "$host" -o %t 2>/dev/null || true)
  case $state in idle* | mix* | alloc*) break ;; esac
  [[ $state == down* || $state == drain* ]] && scontrol update NodeName="$host" State=RESUME 2>/dev/null || true
  sleep 0.2
done
case $state in
  idle* | mix* | alloc*) log "node $host: $(sinfo -h -n "$host" -o '%t %c CPUs')" ;;
  *)
    echo "slurm-local.sh: node $host is not up after 30 s (state '$state')" >&2
    tail -n 20 /var/log/slurm/slurmctld.log /var/log/slurm/slurmd.log >&2 || true
    exit 1
    ;;
esac

# 4. The sweep: unsharded, then as a 4-task array, merged.
# GROUNDTRUTH_BIN: a built program (CI passes the test build's target/debug/groundtruth, so no
# second, optimised build of the whole program); default: the release build, built if missing.
bin=${GROUNDTRUTH_BIN:-$repo/target/release/groundtruth}
if [ -z "${GROUNDTRUTH_BIN:-}" ] && [ ! -x "$bin" ]; then cargo build --release --locked --bin groundtruth; fi
[ -x "$bin" ] || { echo "slurm-local.sh: GROUNDTRUTH_BIN=$bin is not an executable" >&2; exit 2; }
log "unsharded run of $sweep"
"$bin" sweep --config "$sweep" --out "$work/whole" 2>/dev/null
mkdir -p "$work/logs"
log "4-task job array"
GROUNDTRUTH=$bin timeout "${ARRAY_TIMEOUT_S:-900}" sbatch --wait --array=0-3 --cpus-per-task=1 --output="$work/logs/%A_%a.out" \
  deploy/slurm/sweep.sbatch "$sweep" "$work/shards"
for f in "$work"/logs/*.out; do
  grep -q '"ran"' "$f" || { echo "array task failed: $f" >&2; cat "$f" >&2; exit 1; }
done
"$bin" sweep merge "$work"/shards/shard-*-of-4 --out "$work/merged"

# 5. Compare.
status=0
for f in results.csv results.jsonl; do
  if cmp -s <(sort "$work/whole/$f") <(sort "$work/merged/$f"); then
    log "$f: sharded + merged = unsharded ($(wc -l < "$work/merged/$f") lines)"
  else
    log "$f: DIFFERS between the unsharded and the sharded + merged run"
    status=1
  fi
done
# 6. The bundled SemanticKITTI-layout dataset: unsharded, then as a 3-task array into one
# directory (no merge step); the trees must be equal byte for byte.
dataset=$repo/examples/dataset-semantickitti.toml
log "unsharded dataset $dataset"
"$bin" dataset --config "$dataset" --out "$work/dataset-whole" >/dev/null
log "3-task dataset job array"
GROUNDTRUTH=$bin timeout "${ARRAY_TIMEOUT_S:-900}" sbatch --wait --array=0-2 --cpus-per-task=1 \
  --output="$work/logs/dataset-%A_%a.out" deploy/slurm/sweep.sbatch --job dataset "$dataset" "$work/dataset-array"
for f in "$work"/logs/dataset-*.out; do
  grep -q '"frames_written"' "$f" || { echo "dataset array task failed: $f" >&2; cat "$f" >&2; exit 1; }
done
if diff -r "$work/dataset-whole" "$work/dataset-array" >/dev/null; then
  log "dataset: 3-task array = unsharded ($(find "$work/dataset-array" -name '*.bin' | wc -l) frames); verify:"
  "$bin" dataset verify "$work/dataset-array" | tail -n 1
else
  log "dataset: the 3-task array DIFFERS from the unsharded run"
  status=1
fi
log "done in $(( $(date +%s) - start )) s"
exit $status
