#!/usr/bin/env bash
# A benchmark sweep as a Slurm job array: one `gpgpu-rt bench … --shard K/N` per array task,
# and a merge job that runs once all N tasks have succeeded (`--dependency=afterok`).
#
#   scripts/slurm-bench.sh N OUT PROTOCOL… [bench options]
#
# submits both jobs and prints their ids. Shard K writes OUT/shard-K (its CSV rows and
# shard.json), the merge writes OUT/merged (CSVs, summaries, plots, report.md; its machine
# section lists every shard's GPU), and the logs go to OUT/logs/. Example, every Müller 2015
# protocol at full scale on 8 GPUs:
#
#   scripts/slurm-bench.sh 8 /scratch/$USER/mueller thesis-5.1 thesis-5.2 thesis-5.3 --scale full
#
# `gpgpu-rt bench PROTOCOL… --list` shows the units of work the shards divide (unit i goes to
# shard ((i − 1) mod N) + 1), so N need not exceed their count. Settings, from the environment:
#   GPGPU_RT           the binary (default: gpgpu-rt on PATH); it must be reachable from the nodes
#   SBATCH_ARGS        more options for the array job, e.g. "--partition=gpu --time=02:00:00"
#                      (default: --gres=gpu:1 --cpus-per-task=4)
#   SBATCH_MERGE_ARGS  more options for the merge job (it needs no GPU), e.g. "--partition=cpu"
#
# The script is also what the jobs run: `--task N OUT …` (one shard, K = $SLURM_ARRAY_TASK_ID)
# and `--merge N OUT`.
set -euo pipefail

GPGPU_RT=${GPGPU_RT:-gpgpu-rt}

usage() {
    sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//' >&2
    exit 2
}

shard_dirs() { # N OUT
    for ((k = 1; k <= $1; k++)); do echo "$2/shard-$k"; done
}

case "${1:-}" in
--task)
    [[ $# -ge 4 && -n "${SLURM_ARRAY_TASK_ID:-}" ]] || usage
    n=$2 out=$3
    shift 3
    exec "$GPGPU_RT" bench "$@" --quiet --shard "$SLURM_ARRAY_TASK_ID/$n" \
        --out "$out/shard-$SLURM_ARRAY_TASK_ID"
    ;;
--merge)
    [[ $# -eq 3 ]] || usage
    mapfile -t dirs < <(shard_dirs "$2" "$3")
    exec "$GPGPU_RT" bench merge "${dirs[@]}" --out "$3/merged"
    ;;
"" | -h | --help)
    usage
    ;;
esac

[[ $# -ge 3 && "$1" =~ ^[1-9][0-9]*$ ]] || usage
n=$1 out=$2
shift 2
command -v sbatch >/dev/null || { echo "slurm-bench.sh: sbatch not found (is this a Slurm cluster?)" >&2; exit 1; }
# the unit list first: a protocol or option the binary refuses fails here, not in N jobs
"$GPGPU_RT" bench "$@" --list >/dev/null
mkdir -p "$out/logs"
# shellcheck disable=SC2086 # the SBATCH_*ARGS are lists of options
array=$(sbatch --parsable --job-name=gpgpu-rt-bench --array="1-$n" ${SBATCH_ARGS:---gres=gpu:1 --cpus-per-task=4} \
    --output="$out/logs/shard-%a.out" "$0" --task "$n" "$out" "$@")
array=${array%%;*}
# shellcheck disable=SC2086
merge=$(sbatch --parsable --job-name=gpgpu-rt-merge --dependency="afterok:$array" ${SBATCH_MERGE_ARGS:-} \
    --output="$out/logs/merge.out" "$0" --merge "$n" "$out")
echo "array job $array ($n shards), merge job ${merge%%;*}: the report will be $out/merged/report.md"
