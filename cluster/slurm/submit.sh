#!/usr/bin/env bash
# Submits a split prism render to Slurm: an array job of N parts, then a merge job that
# runs when all of them succeed. Or a sweep: one array task per line of a points file.
#
#   submit.sh --parts N --output OUT.png [--parts-dir DIR] [--dry-run] -- render SCENE ARGS...
#   submit.sh --sweep POINTS.txt [--parts-dir DIR] [--dry-run] -- cloth SCENE.json --obj '{out}.obj'
#
# --dry-run submits nothing: it prints the sbatch commands, then the command each array
# index would run and the merge command. Extra sbatch options go in SBATCH_ARGS.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
parts="" output="" dir=parts sweep="" dry=""
while [ $# -gt 0 ]; do
    case $1 in
    --parts) parts=$2; shift 2 ;;
    --output) output=$2; shift 2 ;;
    --parts-dir) dir=$2; shift 2 ;;
    --sweep) sweep=$2; shift 2 ;;
    --dry-run) dry=1; shift ;;
    --) shift; break ;;
    *) echo "submit.sh: unknown option $1 (see the top of this file)" >&2; exit 2 ;;
    esac
done
[ $# -ge 2 ] || { echo "submit.sh: after --, give the prism command and its scene" >&2; exit 2; }
export PRISM_COMMAND=$1
shift
export PRISM_ARGS="$*" PRISM_PARTS_DIR=$dir
if [ -n "$sweep" ]; then
    PRISM_SWEEP=$(grep -v '^[[:space:]]*$' "$sweep")
    export PRISM_SWEEP
    parts=$(printf '%s\n' "$PRISM_SWEEP" | wc -l)
else
    [[ $parts =~ ^[1-9][0-9]*$ ]] || { echo "submit.sh: --parts: expected a count of 1 or more" >&2; exit 2; }
    [ -n "$output" ] || { echo "submit.sh: --output: expected the merged picture" >&2; exit 2; }
fi
export PRISM_PARTS=$parts PRISM_OUTPUT=$output
read -r -a sbatch_args <<<"${SBATCH_ARGS:-}"
array=(sbatch --parsable --array="0-$((parts - 1))" "${sbatch_args[@]}" "$here/render.sbatch")
merge=(sbatch --parsable --dependency=afterok:JOB "${sbatch_args[@]}" "$here/merge.sbatch")
if [ -n "$dry" ]; then
    echo "${array[*]}"
    [ -n "$sweep" ] || echo "${merge[*]}"
    for ((i = 0; i < parts; i++)); do
        echo -n "index $i: "
        DRY_RUN=1 SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_MIN=0 SLURM_ARRAY_TASK_COUNT=$parts \
            SLURM_CPUS_PER_TASK=2 bash "$here/render.sbatch"
    done
    if [ -z "$sweep" ]; then
        echo -n "merge: "
        DRY_RUN=1 bash "$here/merge.sbatch"
    fi
    exit 0
fi
mkdir -p "$dir"
job=$("${array[@]}")
echo "submitted array job $job ($parts tasks)"
if [ -z "$sweep" ]; then
    merge[2]=--dependency=afterok:$job
    echo "submitted merge job $("${merge[@]}") (after $job) -> $output"
fi
