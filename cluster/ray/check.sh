#!/usr/bin/env bash
# End-to-end check of the Ray driver on a local Ray instance with 2 workers: a path-traced
# render in 4 tile shares, a Whitted render in 3, and a 2-point cloth sweep must each give
# the bytes the single prism command gives.
#   usage: cluster/ray/check.sh PRISM_BINARY [PYTHON]
set -euo pipefail
prism=$(realpath "$1")
python=$(command -v "${2:-python3}")
# An absolute path that keeps a virtual environment's own interpreter (no symlinks resolved).
[[ $python == /* ]] || python="$(cd "$(dirname "$python")" && pwd)/$(basename "$python")"
here=$(cd "$(dirname "$0")" && pwd)
shared=$(cd "$here/../../../shared/assets" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

scene="$shared/pathtracer/dae/sky/CBspheres_lambertian.dae"
render=("$scene" -s 8 -r 160 120 --seed 4)
"$prism" render "${render[@]}" -q -o single.png
"$python" "$here/prism_ray.py" render --prism "$prism" --workers 2 --parts 4 \
    -o ray.png --keep parts -- "${render[@]}"
cmp single.png ray.png
[ "$(ls parts | wc -l)" = 4 ]
echo "ray: 4-share render equals the single render"

whitted=(cornell-box -r 120 90 --enable bloom)
"$prism" raytrace "${whitted[@]}" -q -o single-whitted.png
"$python" "$here/prism_ray.py" raytrace --prism "$prism" --workers 2 --parts 3 \
    -o ray-whitted.png -- "${whitted[@]}"
cmp single-whitted.png ray-whitted.png
echo "ray: 3-share Whitted render equals the single render"

cloth="$shared/clothsim/scene/pinned2.json"
"$python" "$here/prism_ray.py" sweep --prism "$prism" --workers 2 --set ks=500,5000 \
    --out-dir sweep -- cloth "$cloth" --frames 2 --obj '{out}.obj'
for k in 0 1; do
    ks=$([ $k = 0 ] && echo 500 || echo 5000)
    "$prism" cloth "$cloth" --frames 2 --set "ks=$ks" --obj "single-$k.obj" -q
    cmp "single-$k.obj" "sweep/point-$k.obj"
    grep -q "^$k	ks=$ks$" sweep/points.tsv
done
echo "ray: 2-point cloth sweep equals the single runs"
