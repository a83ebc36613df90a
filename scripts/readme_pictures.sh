#!/usr/bin/env bash
# Makes the five pictures of the README's table (docs/svg.png, mesh.png, render.png,
# raytrace.png, cloth.png) with a prism binary, from the course's files in ../shared/assets.
#
# Usage: bash scripts/readme_pictures.sh [PRISM] [ASSETS]
#   PRISM   the prism binary (default target/release/prism)
#   ASSETS  the course's files (default ../shared/assets)
set -euo pipefail

root="$(cd "$(dirname "$0")/.." && pwd)"
prism="${1:-$root/target/release/prism}"
assets="${2:-$root/../shared/assets}"
out="$root/docs"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# 2D rasterizer: the course's lion, 16 samples per pixel.
"$prism" svg "$assets/rasterizer/svg/illustration/05_lion.svg" -o "$out/svg.png" \
    --width 256 --samples 16 -q
# Mesh editing: the course's cube after two levels of Loop subdivision, with its edges.
"$prism" mesh subdivide "$assets/meshedit/dae/cube.dae" -o "$work/cube.obj" -n 2 -q
"$prism" shade "$work/cube.obj" -o "$out/mesh.png" --shader normal --wireframe 0,0,0 \
    --eye=5,4,6.5 -r 256 192 --samples 4 -q
# Path tracer: the course's CBbunny.dae, 256 samples per pixel, up to 7 bounces.
"$prism" render "$assets/pathtracer/dae/sky/CBbunny.dae" -o "$out/render.png" \
    -s 256 -m 7 -r 256 192 -q
# Whitted ray tracer: the Delft teapot preset.
"$prism" raytrace teapot --data "$assets/delft-raytracer/data" -r 256 256 \
    -o "$out/raytrace.png" -q
# Cloth and shaders: the course's sphere scene after two simulated seconds, normal shader.
mkdir "$work/frames"
"$prism" cloth "$assets/clothsim/scene/sphere.json" --frames 180 -o "$work/frames/" \
    --shader normal -r 256 200 -q
cp "$work/frames/frame_0180.png" "$out/cloth.png"
