#!/usr/bin/env bash
# Slurm smoke test for `nonsmooth study`: starts a single-node Slurm cluster on localhost,
# submits examples/studies/smoke.toml as a job array (the script printed by `study plan`),
# merges the shards and compares the merged files with an unsharded run, byte for byte.
# A second array runs without --shard (each task takes its shard from SLURM_ARRAY_TASK_*).
#
#   bash scripts/slurm-smoke.sh            # needs root on Debian/Ubuntu (apt-get, daemons)
#   SHARDS=4 KEEP=1 bash scripts/slurm-smoke.sh
#
# Installs Debian's slurm-wlm and munge if missing. Runs munged as the munge user, slurmctld
# and slurmd as root (SlurmUser=root) with proctrack/linuxproc and task/none, so no cgroups
# are needed. Stops only the daemons it started.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
SHARDS=${SHARDS:-3}
SPEC=${SPEC:-examples/studies/smoke.toml}
WORK=$(mktemp -d /tmp/nonsmooth-slurm.XXXXXX)
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$ROOT/target}
log() { echo "[slurm-smoke $(date +%T)] $*"; }

if [ "$(id -u)" -ne 0 ]; then
  echo "slurm-smoke: must run as root (installs packages, starts slurmctld/slurmd)" >&2
  exit 1
fi

# 1. Packages.
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
  || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
  log "installing slurm-wlm and munge"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi
log "$(slurmctld -V)"

# 2. The tool.
log "building nonsmooth (release, feature cli)"
cargo build --release --features cli --bin nonsmooth
BIN=$CARGO_TARGET_DIR/release/nonsmooth

# 3. Daemons (only those we start are stopped at exit).
STARTED=()
# A process is gone when it no longer exists or is a zombie.
running() { [ -r "/proc/$1/stat" ] && ! grep -q '^[0-9]* ([^)]*) Z' "/proc/$1/stat"; }
cleanup() {
  local rc=$?
  local pids=()
  for pidfile in "${STARTED[@]}"; do
    if [ -f "$pidfile" ]; then
      pid=$(cat "$pidfile")
      kill "$pid" 2>/dev/null || true
      pids+=("$pid")
    fi
  done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do running "$pid" || break; sleep 0.2; done
  done
  if [ "$rc" -ne 0 ]; then
    for f in "$WORK"/slurmctld.log "$WORK"/slurmd.log; do
      [ -f "$f" ] && { echo "--- $f (last 30 lines)"; tail -n 30 "$f"; }
    done
  fi
  [ -n "${KEEP:-}" ] || rm -rf "$WORK" 2>/dev/null || true
  exit "$rc"
}
trap cleanup EXIT

if ! pgrep -x munged >/dev/null; then
  if [ ! -s /etc/munge/munge.key ]; then
    log "creating /etc/munge/munge.key"
    mkdir -p /etc/munge
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
    chown munge:munge /etc/munge/munge.key
    chmod 400 /etc/munge/munge.key
  fi
  mkdir -p /run/munge /var/lib/munge /var/log/munge
  chown munge:munge /run/munge /var/lib/munge /var/log/munge
  log "starting munged"
  runuser -u munge -- /usr/sbin/munged --pid-file=/run/munge/smoke-munged.pid
  STARTED+=(/run/munge/smoke-munged.pid)
fi
munge -n | unmunge >/dev/null

HOST=$(hostname -s)
NCPU=$(nproc)
mkdir -p "$WORK/state" "$WORK/spool"
CONF=$WORK/slurm.conf
cat >"$CONF" <<EOF
ClusterName=smoke
SlurmctldHost=$HOST
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
SlurmctldPort=6817
SlurmdPort=6818
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/slurmctld.pid
SlurmdPidFile=$WORK/slurmd.pid
SlurmctldLogFile=$WORK/slurmctld.log
SlurmdLogFile=$WORK/slurmd.log
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
NodeName=$HOST CPUs=$NCPU State=UNKNOWN
PartitionName=smoke Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$CONF
log "starting slurmctld and slurmd on $HOST ($NCPU CPUs)"
slurmctld -c -f "$CONF"
STARTED+=("$WORK/slurmctld.pid")
slurmd -f "$CONF"
STARTED+=("$WORK/slurmd.pid")
for _ in $(seq 60); do
  state=$(sinfo -h -o %T 2>/dev/null | head -n1 || true)
  [ "$state" = "idle" ] && break
  sleep 1
done
sinfo
[ "$state" = "idle" ] || { echo "slurm-smoke: node not idle (state: $state)" >&2; exit 1; }

# 4. The reference: the whole study on this machine, unsharded.
log "unsharded run"
"$BIN" study run "$SPEC" --out "$WORK/whole" --quiet
"$BIN" study merge "$WORK/whole" --out "$WORK/whole-merged/study.csv" >/dev/null

compare() { # DIR_A DIR_B
  for f in study.csv study.sections.csv study.attractors.csv; do
    cmp "$1/$f" "$2/$f" || { echo "slurm-smoke: $f differs" >&2; exit 1; }
  done
}

# 5. A job array from `study plan` (explicit --shard I/N per task).
log "sbatch: job array of $SHARDS tasks from 'study plan'"
"$BIN" study plan "$SPEC" --shards "$SHARDS" --out "$WORK/shards" >"$WORK/study.sbatch"
cat "$WORK/study.sbatch"
timeout 900 sbatch --wait "$WORK/study.sbatch"
ls "$WORK/shards"
"$BIN" study merge "$WORK/shards" --out "$WORK/slurm-merged/study.csv"
compare "$WORK/whole-merged" "$WORK/slurm-merged"
log "array merge identical to the unsharded run"

# 6. A second array whose tasks take their shard from SLURM_ARRAY_TASK_* (no --shard).
log "sbatch --array=0-$((SHARDS - 1)): shards from the Slurm environment"
cat >"$WORK/env.sbatch" <<EOF
#!/bin/bash
#SBATCH --job-name=nonsmooth-env
#SBATCH --output=$WORK/env-%A_%a.out
exec "$BIN" study run "$ROOT/$SPEC" --out "$WORK/shards-env" --threads 1 --quiet
EOF
timeout 900 sbatch --wait --array=0-$((SHARDS - 1)) "$WORK/env.sbatch"
"$BIN" study merge "$WORK/shards-env" --out "$WORK/env-merged/study.csv" >/dev/null
compare "$WORK/whole-merged" "$WORK/env-merged"
log "environment-sharded merge identical to the unsharded run"

# 7. A lost shard is reported, its re-run restores the identical result.
rm "$WORK/shards/shard-00002-of-$(printf %05d "$SHARDS").json"
if "$BIN" study merge "$WORK/shards" --out "$WORK/x.csv" 2>"$WORK/missing.err"; then
  echo "slurm-smoke: merge with a missing shard succeeded" >&2
  exit 1
fi
cat "$WORK/missing.err"
timeout 900 sbatch --wait --array=2 "$WORK/study.sbatch"
"$BIN" study merge "$WORK/shards" --out "$WORK/rerun-merged/study.csv" >/dev/null
compare "$WORK/whole-merged" "$WORK/rerun-merged"
log "re-run of shard 2 restores the identical result"
log "PASS"
