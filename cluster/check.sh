#!/usr/bin/env bash
# Checks the cluster drivers as far as one machine allows, each against the single prism
# command's bytes:
#   Slurm       bash -n, the dry run's commands, then submit.sh run for real with a
#               stand-in sbatch that runs the array tasks and the dependent merge here;
#   Kubernetes  the manifests validated (PyYAML) and their pods' commands run here, the
#               volume's /data mapped to a folder;
#   Ray         ray/check.sh on a local Ray instance with 2 workers.
#   usage: cluster/check.sh PRISM_BINARY PYTHON_WITH_RAY_AND_PYYAML
set -euo pipefail
prism=$(realpath "$1")
python=$(command -v "${2:-python3}")
# An absolute path that keeps a virtual environment's own interpreter (no symlinks resolved).
[[ $python == /* ]] || python="$(cd "$(dirname "$python")" && pwd)/$(basename "$python")"
here=$(cd "$(dirname "$0")" && pwd)
shared=$(cd "$here/../../shared/assets" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for f in "$here"/*/*.sh "$here"/*/*.sbatch; do bash -n "$f"; done
echo "cluster: shell scripts parse"

scene="$shared/pathtracer/dae/sky/CBspheres_lambertian.dae"
"$prism" render "$scene" -s 6 -r 96 64 -q -o "$work/single.png"

# Slurm.
dry=$("$here/slurm/submit.sh" --parts 3 --output out.png --dry-run -- render s.dae -s 8)
expected="index 1: prism render s.dae -s 8 --tile 1/3 -t 2 -q -o parts/part-1-of-3.exr"
grep -qxF "$expected" <<<"$dry" || { echo "slurm dry run: no line '$expected' in:"; echo "$dry"; exit 1; }
mkdir -p "$work/bin" "$work/slurm"
cat >"$work/bin/sbatch" <<'STUB'
#!/usr/bin/env bash
# Stand-in sbatch: runs an array job's tasks (or a job) here, at once, in order.
array="" script=""
for a in "$@"; do
    case $a in
    --array=*) array=${a#--array=} ;;
    --*) ;;
    *) script=$a ;;
    esac
done
if [ -n "$array" ]; then
    last=${array#*-}
    for ((i = 0; i <= last; i++)); do
        SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_MIN=0 SLURM_ARRAY_TASK_COUNT=$((last + 1)) \
            SLURM_CPUS_PER_TASK=1 bash "$script" >&2
    done
else
    bash "$script" >&2
fi
echo $RANDOM
STUB
chmod +x "$work/bin/sbatch"
(cd "$work/slurm" && PATH="$work/bin:$PATH" PRISM="$prism" "$here/slurm/submit.sh" --parts 3 \
    --output merged.png -- render "$scene" -s 6 -r 96 64 >/dev/null)
cmp "$work/single.png" "$work/slurm/merged.png"
echo "cluster: Slurm scripts (3 parts through a stand-in sbatch) give the single render"

# Kubernetes.
k8s=$("$python" "$here/kubernetes/pods.py" --dry-run "$here"/kubernetes/*-job.yaml)
grep -q '^prism-render\[3\]: prism render /data/scene.dae .* --tile 3/4 ' <<<"$k8s"
grep -q '^prism-merge: prism merge /data/parts/part-0-of-4.exr .* -o /data/render.png$' <<<"$k8s"
mkdir -p "$work/data"
cp "$scene" "$work/data/scene.dae"
"$python" "$here/kubernetes/pods.py" --data "$work/data" --prism "$prism" \
    --env "PRISM_ARGS=/data/scene.dae -s 6 -r 96 64" --env THREADS=1 \
    "$here/kubernetes/render-job.yaml" "$here/kubernetes/merge-job.yaml"
cmp "$work/single.png" "$work/data/render.png"
echo "cluster: Kubernetes manifests valid; their 4 pods and merge give the single render"

# Ray.
bash "$here/ray/check.sh" "$prism" "$python"
