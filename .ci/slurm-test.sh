#!/usr/bin/env bash
# The cluster path of docs/sweeps.md on a real scheduler: start a one-node SLURM
# cluster on this machine (munged, slurmctld, slurmd, all private to this
# script: own socket, ports, spool and state directories), run
# `cdyn sweep --shard $SLURM_ARRAY_TASK_ID/N` as an `sbatch --array` job,
# merge the shards, and check the result is byte-identical to one run.
# Installs Debian's slurm-wlm and munge when missing. Skips (exit 0, one
# line) where that cannot work: not root, no apt-get or no package registry.
# Stops the daemons it started, whatever happens.
set -euo pipefail
cd "$(dirname "$0")/.."

skip() { echo "slurm-test: skipped: $*"; exit 0; }
fail() {
  echo "slurm-test: FAILED: $*" >&2
  [ -n "${work:-}" ] && [ -f "$work/daemons.log" ] && tail -20 "$work/daemons.log" >&2
  exit 1
}

[ "$(id -u)" = 0 ] || skip "needs root to start slurmctld, slurmd and munged"
if ! command -v sbatch >/dev/null || ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
  || ! command -v munged >/dev/null; then
  command -v apt-get >/dev/null || skip "slurm-wlm and munge are missing and there is no apt-get"
  # Keep the packages' scripts from starting system services: this test
  # starts (and stops) its own daemons.
  policy=""
  if [ ! -e /usr/sbin/policy-rc.d ]; then
    printf '#!/bin/sh\nexit 101\n' > /usr/sbin/policy-rc.d && chmod +x /usr/sbin/policy-rc.d && policy=1
  fi
  ok=1
  { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      slurm-wlm munge; } >/tmp/slurm-test-apt.log 2>&1 || ok=""
  [ -n "$policy" ] && rm -f /usr/sbin/policy-rc.d
  [ -n "$ok" ] || skip "cannot install slurm-wlm and munge (no package registry?): $(tail -1 /tmp/slurm-test-apt.log)"
fi

cdyn="$(.ci/cdyn-binary.sh)"
[ -x "$cdyn" ] || fail "no cdyn binary at $cdyn"

work="$(mktemp -d /tmp/cdyn-slurm.XXXXXX)"
chmod 755 "$work"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

# munge: a private key and socket, so a system munged (if any) is untouched.
mkdir -p "$work/munge"
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chmod 700 "$work/munge" && chmod 400 "$work/munge/munge.key"
munged --foreground --force --key-file="$work/munge/munge.key" --socket="$work/munge/socket" \
  --pid-file="$work/munge/pid" --log-file="$work/munge/log" --seed-file="$work/munge/seed" 2>>"$work/daemons.log" &
pids+=($!)

host="$(hostname -s)"
cpus="$(nproc)"
mkdir -p "$work/state" "$work/spool"
export SLURM_CONF="$work/slurm.conf"
cat > "$SLURM_CONF" <<CONF
ClusterName=cdyntest
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
AuthInfo=socket=$work/munge/socket
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
MailProg=/bin/true
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF

for _ in $(seq 50); do [ -S "$work/munge/socket" ] && break; sleep 0.1; done
[ -S "$work/munge/socket" ] || fail "munged did not start: $(tail -3 "$work/munge/log" 2>/dev/null)"
slurmctld -D -i -f "$SLURM_CONF" 2>>"$work/daemons.log" &
pids+=($!)
slurmd -D -f "$SLURM_CONF" -N "$host" 2>>"$work/daemons.log" &
pids+=($!)
for _ in $(seq 100); do
  sinfo -h -o %T 2>/dev/null | grep -qx idle && break
  sleep 0.2
done
sinfo -h -o %T 2>/dev/null | grep -qx idle \
  || fail "the node did not come up: $(tail -3 "$work/slurmctld.log" "$work/slurmd.log" 2>/dev/null | tr '\n' ' ')"

# A small grid: 3 × 2 points in 3 shards.
shards=3
cat > "$work/grid.toml" <<TOML
[model]
kind = "pendulum"
[method]
geometric = "cvsgf"
alpha_g = 40.0
apply = "forward_euler"
[integrator]
scheme = "ab3"
h = 0.01
t_end = 2.0
[sweep]
alpha_g = [10.0, 40.0, 160.0]
h = [0.01, 0.02]
TOML
cat > "$work/job.sh" <<JOB
#!/bin/sh
cd "$work" && exec "$cdyn" sweep grid.toml --shard "\$SLURM_ARRAY_TASK_ID/$shards" --out "part\$SLURM_ARRAY_TASK_ID" --quiet
JOB
chmod +x "$work/job.sh"
timeout 90 sbatch --wait --array="0-$((shards - 1))" --output="$work/job-%a.log" --chdir="$work" "$work/job.sh" \
  >"$work/sbatch.log" 2>&1 || fail "sbatch --array: $(tr '\n' ' ' <"$work/sbatch.log") $(cat "$work"/job-*.log 2>/dev/null | tr '\n' ' ')"
for i in $(seq 0 $((shards - 1))); do
  [ -s "$work/part$i/sweep.json" ] || fail "shard $i wrote no sweep.json: $(tr '\n' ' ' <"$work/job-$i.log")"
done
(cd "$work" && "$cdyn" sweep grid.toml --out single --quiet >/dev/null)
(cd "$work" && "$cdyn" merge $(seq -f 'part%g' 0 $((shards - 1))) --out merged --quiet >/dev/null)
cmp "$work/merged/sweep.json" "$work/single/sweep.json" \
  || fail "merged shards from the job array differ from a single run"
echo "slurm-test: ok: $shards array tasks on $host ($cpus CPUs) merged byte-identical to one run"
