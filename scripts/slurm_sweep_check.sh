#!/usr/bin/env bash
# A sweep on a real Slurm cluster: starts a throw-away single-node cluster (munged, slurmctld,
# slurmd, all state in a temporary folder, nothing in /etc), submits a 20-task sweep with
# `ratslam sweep submit --slurm --max-parallel 2`, waits with a bounded loop, and checks that
# every task ran once and succeeded, that at most two ran at a time, and that the collect job
# (afterany) wrote the results. Stops the daemons it started, by PID, on every exit.
#
# Needs root (the daemons run as root here) and Debian's slurm-wlm and munge, which it
# installs through scripts/setup.sh. Skips with a message where it cannot run.
#   bash scripts/slurm_sweep_check.sh [path/to/ratslam]
#
# Pitfalls met in a container without systemd (see ../shared/tools/slurm-single-node.sh):
# SLURM_CONF must point every client at our config; munged wants its socket folder (and its
# parents) world-searchable; slurmd initialises a cgroup plugin even when none is used, so
# cgroup.conf pins cgroup/v1 and the proctrack/task plugins are linuxproc/none; there is no
# slurmdbd, so no sacct (job ends are read with squeue).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
program=$(realpath "${1:-build/apps/ratslam}")

skip() {
  echo "slurm check: SKIPPED: $*"
  exit 0
}
[[ $(id -u) == 0 ]] || skip "needs root to run the Slurm daemons"
[[ -x $program ]] || { echo "slurm check: no program at $program" >&2; exit 1; }
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  bash scripts/setup.sh slurm-wlm munge >/dev/null 2>&1 || skip "slurm-wlm and munge could not be installed"
fi

work=$(mktemp -d /tmp/ratslam-slurm.XXXXXX)
chmod 0755 "$work"
mkdir -p "$work"/{munge,state,spool,log,run}
export SLURM_CONF=$work/slurm.conf
socket=$work/munge/munge.socket
host=$(hostname -s)
started=()
finish() {
  local rc=$?
  for ((i = ${#started[@]} - 1; i >= 0; i--)); do
    kill -TERM "${started[i]}" 2>/dev/null || true
    wait "${started[i]}" 2>/dev/null || true
  done
  if ((rc != 0)); then
    echo "slurm check: FAILED; daemon logs:" >&2
    tail -n 20 "$work"/log/* "$work"/munge/*.log 2>/dev/null >&2 || true
  fi
  rm -rf "$work"
  exit "$rc"
}
trap finish EXIT
trap 'exit 130' INT TERM

# Two free ports, above the defaults so that a real cluster on this host is left alone.
free_port() {
  local p=$1
  while (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null; do p=$((p + 1)); done
  echo "$p"
}
ctld_port=$(free_port 16817)
slurmd_port=$(free_port $((ctld_port + 1)))

mungekey -c -k "$work/munge/munge.key"
munged -F -S "$socket" --key-file="$work/munge/munge.key" --log-file="$work/munge/munged.log" \
  --pid-file="$work/munge/munged.pid" --seed-file="$work/munge/munged.seed" \
  >"$work/log/munged.out" 2>&1 &
started+=($!)
for _ in $(seq 100); do
  munge -n -S "$socket" 2>/dev/null | unmunge -S "$socket" >/dev/null 2>&1 && break
  sleep 0.1
done
munge -n -S "$socket" | unmunge -S "$socket" >/dev/null

echo "CgroupPlugin=cgroup/v1" >"$work/cgroup.conf"
cat >"$SLURM_CONF" <<EOF
ClusterName=ratslam
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/run/slurmctld.pid
SlurmdPidFile=$work/run/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
DependencyParameters=kill_invalid_depend
ReturnToService=2
MailProg=/bin/true
MinJobAge=3600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=$(free -m | awk '/^Mem:/{print int($2 * 0.9)}') State=UNKNOWN
PartitionName=main Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D -f "$SLURM_CONF" >"$work/log/slurmctld.out" 2>&1 &
started+=($!)
slurmd -D -f "$SLURM_CONF" >"$work/log/slurmd.out" 2>&1 &
started+=($!)
state=
for _ in $(seq 150); do
  state=$(sinfo -h -n "$host" -o %T 2>/dev/null || true)
  [[ $state == idle ]] && break
  sleep 0.2
done
[[ $state == idle ]] || { echo "slurm check: node is '$state', not idle" >&2; exit 1; }
echo "slurm check: cluster up ($(sinfo -V), ports $ctld_port/$slurmd_port)"

# The sweep: 20 thresholds of the classic camera on the built-in synthetic loop.
"$program" synthesize --out "$work/data" --laps 1 >/dev/null 2>&1
cat >"$work/sweep.toml" <<EOF
[sweep]
base_config = "$root/configs/synthetic.toml"
objective = "map_ate_m"
metrics = ["templates"]
timeout_s = 300
[[datasets]]
data = ["data"]
[parameters]
"camera.match_threshold" = {linear = [0.02, 0.06, 20]}
EOF
"$program" sweep plan "$work/sweep.toml" --out "$work/sweep"
submitted=$("$program" sweep submit "$work/sweep" --slurm --max-parallel 2 --time 10)
echo "slurm check: $submitted"
array_job=$(sed -n 's/^array job \([0-9]*\).*/\1/p' <<<"$submitted")
collect_job=$(sed -n 's/.*collect job \([0-9]*\).*/\1/p' <<<"$submitted")

# Wait (at most 10 minutes) until neither job is pending or running; count running tasks.
most_running=0
deadline=$((SECONDS + 600))
while ((SECONDS < deadline)); do
  running=$(squeue -h -j "$array_job" -t R 2>/dev/null | wc -l)
  ((running > most_running)) && most_running=$running
  if queue=$(squeue -h -j "$array_job,$collect_job" -t PD,R,CG,CF,S 2>/dev/null) && [[ -z $queue ]]; then
    break
  fi
  sleep 0.3
done
((SECONDS < deadline)) || { echo "slurm check: jobs still queued after 10 minutes" >&2; squeue; exit 1; }

fail() {
  echo "slurm check: FAILED: $*" >&2
  exit 1
}
[[ -f $work/sweep/results.json ]] || fail "the collect job wrote no results.json"
ok=$(grep -c '"status": "ok"' "$work/sweep/results.json" || true)
((ok == 20)) || fail "$ok of 20 tasks succeeded"
for i in $(seq -f %05g 0 19); do
  [[ -f $work/sweep/runs/$i/summary.json ]] || fail "task $i has no summary"
  [[ -f $work/sweep/slurm/logs/task-$((10#$i)).out ]] || fail "task $i has no Slurm log"
done
[[ -f $work/sweep/best.toml ]] || fail "no best.toml"
((most_running <= 2)) || fail "$most_running tasks ran at once (limit 2)"
# Submitting again finds nothing pending.
if "$program" sweep submit "$work/sweep" --slurm --dry-run >/dev/null 2>&1; then
  fail "a finished sweep still had pending tasks"
fi
echo "slurm check: PASSED (20 tasks ok, at most $most_running at a time, collect ran)"
