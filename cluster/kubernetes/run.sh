#!/usr/bin/env bash
# Runs a split prism render on the cluster kubectl points at: the Indexed Job of
# render-job.yaml, then, once it is complete, the merge Job. With --dry-run, applies
# nothing and prints each pod's prism command instead (needs python3 with PyYAML).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if [ "${1:-}" = --dry-run ]; then
    exec python3 "$here/pods.py" --dry-run "$here/render-job.yaml" "$here/merge-job.yaml"
fi
kubectl apply -f "$here/render-job.yaml"
kubectl wait --for=condition=complete --timeout=24h job/prism-render
kubectl apply -f "$here/merge-job.yaml"
kubectl wait --for=condition=complete --timeout=1h job/prism-merge
