#!/usr/bin/env bash
# A sharded `reachc simulate` through a real Slurm: installs slurm-wlm and munge (Debian
# packages) if missing, starts munged, slurmctld and slurmd for a one-node cluster on localhost
# (everything in a temporary directory, ports 16817/16818), builds reachc (release), runs the
# same simulation unsharded and as a job array of K shards plus the dependent merge
# (scripts/slurm/submit.sh), and checks that the reports are byte for byte the same (a failed
# coverage check, exit status 1, is compared too: both runs must agree on it), and, up to 10^6
# paths, the same as the interpreter backend's unsharded report. Stops
# every daemon it started and removes the directory on exit, also on failure. Runs as root
# (apt-get, SlurmUser=root); idempotent, by hand or from .ci/run.
#
#   tests/slurm.sh                                   # K = 4, 10^5 paths of the linear example
#   SHARDS=8 PATHS=10000000 tests/slurm.sh           # prints the wall times (docs/benchmarks.md)
#
# Environment: SHARDS (K, default 4), PATHS (default 100000), SPEC (default specs/linear.sde),
# ANALYSIS (default amgf_rule), SEED (default 1), CARGO_TARGET_DIR (where cargo builds reachc),
# KEEP=1 keeps the temporary directory (logs) after a failure.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
shards=${SHARDS:-4} paths=${PATHS:-100000} spec=${SPEC:-specs/linear.sde}
analysis=${ANALYSIS:-amgf_rule} seed=${SEED:-1}

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    echo "== installing slurm-wlm and munge"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi

work=$(mktemp -d /tmp/reachc-slurm.XXXXXX)
pids=()
cleanup() {
    local status=$?
    # Only the daemons this script started, by their process ids.
    for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
    for pid in "${pids[@]}"; do
        for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -9 "$pid" 2>/dev/null || true
    done
    if [ $status -ne 0 ]; then
        echo "FAILED (status $status); daemon logs:" >&2
        tail -n 20 "$work"/*.log >&2 2>/dev/null || true
    fi
    if [ $status -ne 0 ] && [ "${KEEP:-0}" = 1 ]; then
        echo "kept $work" >&2
    else
        rm -rf "$work"
    fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM

echo "== munge and a one-node Slurm in $work"
mkdir -p "$work/state" "$work/spool" "$work/munge"
chmod 700 "$work/munge"
head -c 1024 /dev/urandom >"$work/munge/munge.key"
chmod 400 "$work/munge/munge.key"
socket=$work/munge/munge.socket
munged --foreground --force --key-file="$work/munge/munge.key" --socket="$socket" \
    --pid-file="$work/munge/munged.pid" --log-file="$work/munged.log" \
    --seed-file="$work/munge/munged.seed" >>"$work/munged.log" 2>&1 &
pids+=($!)
for _ in $(seq 50); do [ -S "$socket" ] && break; sleep 0.1; done
[ -S "$socket" ] || { echo "munged did not start" >&2; exit 1; }

# The node as slurmd sees it (CPUs, sockets, cores, memory), named localhost.
node=$(slurmd -C | head -n 1 | sed 's/^NodeName=[^ ]*/NodeName=localhost/')
cat >"$work/slurm.conf" <<CONF
ClusterName=reachc-test
SlurmctldHost=localhost
SlurmUser=root
SlurmdUser=root
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
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
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=local Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$work/slurm.conf
slurmctld -D -i -f "$SLURM_CONF" >>"$work/slurmctld.log" 2>&1 &
pids+=($!)
slurmd -D -N localhost -f "$SLURM_CONF" >>"$work/slurmd.log" 2>&1 &
pids+=($!)
state=""
for _ in $(seq 100); do
    state=$(sinfo -h -N -o %T 2>/dev/null | head -n 1 || true)
    [ "$state" = idle ] && break
    sleep 0.2
done
[ "$state" = idle ] || { echo "the node is not idle (state: ${state:-no answer})" >&2; exit 1; }
sinfo -N -o "%N %T %c %m"

echo "== reachc (release)"
cargo build --release --locked -q -p reachc
reachc=${CARGO_TARGET_DIR:-$root/target}/release/reachc
export REACHC=$reachc
run=("$spec" --analysis "$analysis" --paths "$paths" --seed "$seed")
# The generated crate is built once here (cached), before any timing.
"$reachc" simulate "$spec" --analysis "$analysis" --paths 1 -q -o "$work/warm" >/dev/null

echo "== unsharded: reachc simulate ${run[*]}"
# Exit status 1 is a failed coverage check (the report is written): compared all the same.
start=$(date +%s%N)
status=0
"$reachc" simulate "${run[@]}" -q -o "$work/whole" || status=$?
unsharded=$((($(date +%s%N) - start) / 1000000))
[ $status -le 1 ] || exit $status

echo "== $shards shards through Slurm (a job array and the dependent merge)"
start=$(date +%s%N)
submitted=$(scripts/slurm/submit.sh "$shards" "$work/sharded" "${run[@]}")
echo "$submitted"
merge_job=$(sed -n 's/^merge: job \([0-9]*\).*/\1/p' <<<"$submitted")
# Polled every 0.2 s (`sbatch --wait` backs off to seconds between polls).
deadline=$((SECONDS + 3600))
while :; do
    job=$(scontrol show job -o "$merge_job")
    case $(grep -o 'JobState=[A-Z_]*' <<<"$job") in
        JobState=PENDING | JobState=RUNNING | JobState=CONFIGURING | JobState=COMPLETING) ;;
        *) break ;;
    esac
    [ $SECONDS -lt $deadline ] || { echo "the merge did not end within an hour" >&2; exit 1; }
    sleep 0.2
done
sharded=$((($(date +%s%N) - start) / 1000000))
merged=$(grep -o 'ExitCode=[0-9]*' <<<"$job" | cut -d= -f2)
[ "$merged" = "$status" ] || { echo "merge: $job (unsharded exit status $status)" >&2; exit 1; }
cat "$work/sharded/logs/merge.out"
echo "== the shards (their own time lines, and Slurm's start and end times)"
for log in "$work"/sharded/logs/shard-*.out; do
    echo "$(basename "$log" .out): $(grep -h 'time:' "$log" | sed 's/^ *//')"
done
scontrol show job -o | while read -r line; do
    echo "$(grep -o '^JobId=[0-9]*\|ArrayTaskId=[0-9]*\|JobName=[^ ]*\|SubmitTime=[^ ]*\|StartTime=[^ ]*\|EndTime=[^ ]*' <<<"$line" | tr '\n' ' ')"
done
[ "$(ls "$work/sharded/parts" | wc -l)" -eq "$shards" ]
cmp "$work/whole/$analysis.sim.json" "$work/sharded/$analysis.sim.json"
if [ "$paths" -le 1000000 ]; then
    # The compiled shards' report is also the interpreter's (the backends agree to the bit).
    "$reachc" simulate "${run[@]}" --backend interp -q -o "$work/interp" || [ $? -eq 1 ]
    cmp "$work/sharded/$analysis.sim.json" "$work/interp/$analysis.sim.json"
fi
echo "wall time: unsharded ${unsharded} ms, $shards shards through Slurm ${sharded} ms" \
    "(submission to merged report)"
echo "ok: the merged report of $shards shards is the unsharded one, byte for byte"
