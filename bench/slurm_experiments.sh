#!/bin/bash
# A study over many moduli as a Slurm job array: one share of the plan per array task, then
# one merge job. Submit from the catkin workspace (devel/setup.bash sourced), e.g.
#
#   N=16 OUT=$PWD/study sbatch --array=1-16 bench/slurm_experiments.sh --model my/model.yaml -e practical rest_shape
#   sbatch --dependency=afterok:<array job id> --wrap \
#     "btr_experiments --merge $PWD/study/share_* --out $PWD/study/merged"
#
# Every task runs the same plan (same arguments) and keeps only its share, so the shares are
# deterministic: the merged CSV equals one unsharded run's rows (a core test checks it).
#SBATCH --job-name=btr_experiments
#SBATCH --cpus-per-task=2
#SBATCH --time=04:00:00
set -euo pipefail
: "${N:?set N, the number of shares (the array size)}"
: "${OUT:?set OUT, the study folder}"
K=${SLURM_ARRAY_TASK_ID:?run as a job array: sbatch --array=1-N}
exec btr_experiments -q --shard "$K/$N" --out "$OUT/share_$K" "$@"
