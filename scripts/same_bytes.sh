#!/usr/bin/env bash
# Runs two prism binaries on one fixed set of inputs and compares every output file byte for
# byte (cmp): the gallery, every course SVG (both dialects), path-traced scenes (PNG and EXR,
# on every instruction-set level the processor has), Whitted presets (every level), meshes
# (subdivision, normals, conversion, Bezier), shaded meshes, cloth scenes (PNG and OBJ
# frames) and a split render merged. Prints one line per difference and a count; exits 1 if
# any output differs.
#
# Usage: bash scripts/same_bytes.sh BEFORE AFTER [ASSETS]
set -uo pipefail

before="$(realpath "$1")"
after="$(realpath "$2")"
root="$(cd "$(dirname "$0")/.." && pwd)"
assets="$(realpath "${3:-$root/../shared/assets}")"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

isa=""
levels="sse"
grep -q ' avx ' /proc/cpuinfo && levels="$levels avx"
grep -q ' avx2 ' /proc/cpuinfo && levels="$levels avx2"
grep -q ' avx512vl ' /proc/cpuinfo && levels="$levels avx512"

# run NAME ARGS...: runs both binaries in $work/{before,after}/NAME with ARGS (the word OUT
# stands for that folder).
run() {
    local name="$1"
    shift
    for side in before after; do
        local bin="$before"
        [ "$side" = after ] && bin="$after"
        local out="$work/$side/$name"
        mkdir -p "$out"
        local args=()
        for a in "$@"; do args+=("${a//OUT/$out}"); done
        (cd "$out" && PRISM_ISA="${isa:-}" "$bin" "${args[@]}" >/dev/null 2>"$out.stderr") ||
            echo "$side $name: exit $? ($(head -c 300 "$out.stderr"))"
    done
}

run demo demo -o OUT/gallery -q --assets "$assets"
for dialect in svg cs184; do
    compat=""
    [ "$dialect" = cs184 ] && compat="--compat cs184"
    run "svg-$dialect" svg "$assets/rasterizer/svg" -o OUT/ --samples 4 $compat -q
done
for isa in $levels; do
    for scene in CBspheres_lambertian CBbunny CBspheres CBspheres_microfacet_al_ag bunny; do
        run "render-$isa-$scene" render "$assets/pathtracer/dae/sky/$scene.dae" \
            -o OUT/out.png --exr OUT/out.exr -s 8 -m 5 -r 160 120 -q
    done
    for preset in cornell-box teapot monkey cube-textured spheres; do
        run "raytrace-$isa-$preset" raytrace "$preset" \
            --data "$assets/delft-raytracer/data" -r 160 160 -o OUT/out.png -q
    done
done
isa=""
for mesh in cube teapot beetle; do
    run "mesh-$mesh" mesh subdivide "$assets/meshedit/dae/$mesh.dae" -o OUT/sub.obj -n 1 -q
    run "normals-$mesh" mesh normals "$assets/meshedit/dae/$mesh.dae" -o OUT/n.obj
    run "convert-$mesh" mesh convert "$assets/meshedit/dae/$mesh.dae" -o OUT/c.ply
    run "shade-$mesh" shade "$assets/meshedit/dae/$mesh.dae" -o OUT/s.png --shader phong \
        -r 160 120 --samples 4 -q
done
run "shade-obj" shade "$assets/delft-raytracer/data/teapot.obj" -o OUT/s.png --shader normal \
    -r 160 120 -q
run "bezier" bezier "$assets/meshedit/bez/teapot.bez" -o OUT/teapot.obj --resolution 8
for scene in sphere pinned2 pinned4; do
    run "cloth-$scene" cloth "$assets/clothsim/scene/$scene.json" --frames 30 -o OUT/ \
        -r 120 100 --obj-sequence OUT/ -q
done
for part in 0 1 2; do
    run "split" render "$assets/pathtracer/dae/sky/CBbunny.dae" -s 8 -r 160 120 \
        --tile $part/3 -o OUT/part-$part.exr -q
done
for side in before after; do
    bin="$before"
    [ "$side" = after ] && bin="$after"
    "$bin" merge "$work/$side"/split/part-*.exr -o "$work/$side/split/merged.png" -q
done

count=0
differ=0
while IFS= read -r -d '' f; do
    rel="${f#"$work/before/"}"
    count=$((count + 1))
    if ! cmp -s "$f" "$work/after/$rel"; then
        echo "differs: $rel"
        differ=$((differ + 1))
    fi
done < <(find "$work/before" -type f ! -name '*.stderr' -print0)
extra=$(cd "$work/after" && find . -type f ! -name '*.stderr' | wc -l)
echo "$count files before, $extra after; $differ differ"
[ "$differ" -eq 0 ] && [ "$count" -eq "$extra" ]
