#!/usr/bin/env bash
# Submits a sharded `reachc simulate` to Slurm: a job array of K shards (shard.sbatch) and,
# depending on it (afterok), the merge (merge.sbatch). See docs/cluster.md.
#
#   scripts/slurm/submit.sh [--wait] K OUT_DIR SPEC [reachc simulate options...]
#
# e.g. scripts/slurm/submit.sh 8 out specs/linear.sde --analysis amgf_rule --paths 10000000
#
# The parts go to OUT_DIR/parts (which must not hold parts already), the Slurm logs to
# OUT_DIR/logs, the reports to OUT_DIR. Prints the two job ids. With --wait, returns when the
# merge has ended, with its exit status. Environment: REACHC (the reachc binary, default: reachc
# on PATH; exported to the jobs), SBATCH_OPTIONS (more sbatch options for both jobs, e.g.
# "--partition=short --cpus-per-task=4").
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
wait=()
if [ "${1:-}" = "--wait" ]; then wait=(--wait); shift; fi
if [ $# -lt 3 ]; then
    sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
fi
shards=$1 out=$2 spec=$3
shift 3
case $shards in
    '' | *[!0-9]* | 0) echo "error: K must be a whole number >= 1, not \`$shards\`" >&2; exit 2 ;;
esac
[ -f "$spec" ] || { echo "error: no spec $spec" >&2; exit 2; }
mkdir -p "$out/parts" "$out/logs"
out=$(cd "$out" && pwd)
spec=$(cd "$(dirname "$spec")" && pwd)/$(basename "$spec")
if compgen -G "$out/parts/*.part" >/dev/null; then
    echo "error: $out/parts already holds parts (of an earlier run?): remove them first" >&2
    exit 2
fi
if [ -n "${REACHC:-}" ]; then
    REACHC=$(cd "$(dirname "$REACHC")" && pwd)/$(basename "$REACHC")
    export REACHC
fi
read -r -a extra <<<"${SBATCH_OPTIONS:-}"
array=$(sbatch --parsable "${extra[@]}" --array="0-$((shards - 1))" \
    --output="$out/logs/shard-%a.out" "$here/shard.sbatch" "$shards" "$out/parts" "$spec" "$@")
array=${array%%;*}
echo "shards: job array $array (0-$((shards - 1)))"
merge=$(sbatch --parsable "${extra[@]}" "${wait[@]}" --dependency="afterok:$array" \
    --kill-on-invalid-dep=yes --output="$out/logs/merge.out" "$here/merge.sbatch" "$out/parts" "$out")
echo "merge: job ${merge%%;*} (after $array; reports in $out)"
