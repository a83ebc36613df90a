#!/usr/bin/env bash
# Drives `prism view` in a real window under Xvfb with xdotool and checks what each input
# does to the picture (ImageMagick counts colours and differing pixels):
#   - the window opens within 1 s;
#   - `=` (to 16 samples per pixel) smooths a triangle's edges: grey levels appear;
#   - dragging pans the picture; H shows the help overlay; S saves a screenshot PNG;
#   - Esc closes the window with exit code 0;
#   - a lit COLLADA scene opens within 1 s and refines by itself; dragging orbits the camera
#     (most pixels change); `2` shows the second bounce only;
#   - a cloth scene opens within 1 s and plays by itself; `P` pauses it (the picture holds
#     still); `C` changes the shader;
#   - the Whitted ray tracer opens within 1 s; a click on a pixel draws its rays; `X` clears
#     them (the picture is as before);
#   - a mesh (`--mode mesh` on a COLLADA file) opens within 1 s; hovering highlights an
#     element; `F` flips the edge under the cursor (the wireframe changes); Ctrl+Z undoes it;
#   - without a display, prism view exits 2 with a clear message.
# Needs: apt-get install -y xvfb xdotool x11-utils imagemagick libxkbcommon-x11-0
#   usage: scripts/view-check.sh [PRISM_BINARY]   (default: target/release/prism)
# Run from the repository, with ../shared beside it (the scene comes from there).
set -euo pipefail
# Every tool the checks use, named when missing (each one's Debian package in brackets).
missing=()
for tool in Xvfb:xvfb xdotool:xdotool xdpyinfo:x11-utils import:imagemagick \
    convert:imagemagick compare:imagemagick bc:bc realpath:coreutils; do
    command -v "${tool%%:*}" >/dev/null 2>&1 || missing+=("${tool%%:*} (${tool##*:})")
done
if ((${#missing[@]})); then
    echo "view-check: missing tools: ${missing[*]}; apt-get install -y xvfb xdotool x11-utils imagemagick bc libxkbcommon-x11-0" >&2
    exit 2
fi
prism=$(realpath "${1:-target/release/prism}")
if [ ! -x "$prism" ]; then
    echo "view-check: $prism is not an executable prism (build it: cargo build --release)" >&2
    exit 2
fi
scene=$(realpath ../shared/assets/pathtracer/dae/sky/CBspheres_lambertian.dae)
cloth=$(realpath ../shared/assets/clothsim/scene/pinned2.json)
teapot=$(realpath ../shared/assets/meshedit/dae/teapot.dae)
work=$(mktemp -d)
display=:$((90 + RANDOM % 9))
Xvfb "$display" -screen 0 1024x768x24 >/dev/null 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null; rm -rf "$work"' EXIT
export DISPLAY=$display
for _ in $(seq 50); do xdpyinfo >/dev/null 2>&1 && break; sleep 0.1; done
cd "$work"
cat >tri.svg <<'SVG'
<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">
  <polygon points="10,10 90,30 30,90" fill="black"/>
</svg>
SVG
shot() { sleep 0.4; import -window "$wid" "$1"; }
colours() { convert "$1" -crop 400x240+0+0 +repage -format %k info:; }
# Pixels that differ between two screenshots, in the region WxH+X+Y if one is given.
differ() {
    if (($# > 2)); then
        # Crops go through files: ImageMagick cannot read /dev/fd on every system.
        convert "$1" -crop "$3" +repage "$work/crop-a.png"
        convert "$2" -crop "$3" +repage "$work/crop-b.png"
        compare -metric AE "$work/crop-a.png" "$work/crop-b.png" null: 2>&1 || true
    else
        compare -metric AE "$1" "$2" null: 2>&1 || true
    fi
}
# Starts `prism view` with the arguments after the label, checks that its window is there
# within 1 s, and focuses it; sets pid and wid.
open_window() {
    local label=$1
    shift
    local start
    start=$(date +%s.%N)
    "$prism" view "$@" &
    pid=$!
    wid=$(xdotool search --sync --name "prism view" | head -1)
    local opened
    opened=$(echo "$(date +%s.%N) - $start" | bc)
    echo "view: $label open after $opened s"
    (($(echo "$opened < 1.0" | bc))) || { echo "view: took more than 1 s to open"; exit 1; }
    xdotool windowfocus --sync "$wid"
}

open_window "window" tri.svg -r 400 300
shot one.png
xdotool key equal equal equal
shot sixteen.png
c1=$(colours one.png)
c16=$(colours sixteen.png)
edges=$(differ one.png sixteen.png)
echo "view: colours in the picture at 1 spp: $c1, at 16 spp: $c16; $edges pixels changed"
# One sample: only black and white. Sixteen: grey levels along the edges.
((c1 <= 2 && c16 >= 5 && edges > 200)) || { echo "view: = did not smooth the edges"; exit 1; }

xdotool mousemove --window "$wid" 200 140 mousedown 1 mousemove --window "$wid" 260 140 mouseup 1
shot panned.png
moved=$(differ sixteen.png panned.png)
echo "view: dragging 60 pixels changed $moved pixels"
((moved > 500)) || { echo "view: dragging did not pan"; exit 1; }

xdotool key h
shot help.png
helped=$(differ panned.png help.png)
echo "view: the help overlay changed $helped pixels"
((helped > 2000)) || { echo "view: H did not show the help"; exit 1; }

xdotool key s
sleep 0.4
[ -f tri-screenshot-1.png ] || { echo "view: S saved no screenshot"; exit 1; }
echo "view: S saved tri-screenshot-1.png"

xdotool key Escape
for _ in $(seq 20); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
if kill -0 "$pid" 2>/dev/null; then echo "view: Esc did not close the window"; exit 1; fi
wait "$pid" || { echo "view: exit code $? after Esc"; exit 1; }
echo "view: Esc closed the window (exit 0)"

open_window "path-traced scene" "$scene" -r 256 192
shot early.png
sleep 1
shot later.png
refined=$(differ early.png later.png)
echo "view: one second of passes changed $refined pixels"
((refined > 1000)) || { echo "view: the picture does not refine"; exit 1; }
xdotool mousemove --window "$wid" 128 96 mousedown 1 mousemove --window "$wid" 170 96 mouseup 1
shot orbited.png
orbit=$(differ later.png orbited.png)
echo "view: orbiting changed $orbit pixels"
((orbit > 8000)) || { echo "view: dragging did not orbit"; exit 1; }
xdotool key 2
shot bounce.png
bounce=$(differ orbited.png bounce.png)
echo "view: the second bounce alone changed $bounce pixels"
((bounce > 8000)) || { echo "view: 2 did not show the second bounce"; exit 1; }
xdotool key Escape
wait "$pid" || { echo "view: exit code $? after Esc"; exit 1; }

open_window "cloth scene" "$cloth" -r 320 240
shot c1.png
shot c2.png
played=$(differ c1.png c2.png)
echo "view: the cloth playing changed $played pixels"
((played > 500)) || { echo "view: the cloth does not play"; exit 1; }
xdotool key p
shot p1.png
shot p2.png
# Only the status line's timing may change while paused.
held=$(differ p1.png p2.png 320x220+0+0)
echo "view: paused, $held pixels changed"
((held == 0)) || { echo "view: P did not pause"; exit 1; }
xdotool key c
shot shader.png
shaded=$(differ p2.png shader.png)
echo "view: the next shader changed $shaded pixels"
((shaded > 1000)) || { echo "view: C did not change the shader"; exit 1; }
xdotool key Escape
wait "$pid" || { echo "view: exit code $? after Esc"; exit 1; }

open_window "Whitted scene" cornell-box -r 300 300
shot w1.png
xdotool mousemove --window "$wid" 140 170 click 1
shot w2.png
rays=$(differ w1.png w2.png)
echo "view: clicking a pixel changed $rays pixels (its rays over the dimmed picture)"
((rays > 5000)) || { echo "view: a click drew no rays"; exit 1; }
xdotool key x
shot w3.png
back=$(differ w1.png w3.png 300x240+0+0)
echo "view: after X, $back pixels differ from the first picture"
((back == 0)) || { echo "view: X did not clear the rays"; exit 1; }
xdotool key Escape
wait "$pid" || { echo "view: exit code $? after Esc"; exit 1; }

open_window "mesh (a MeshEdit .dae opens as a mesh by itself)" "$teapot" -r 480 360
shot m0.png
# The picture above the status line (two rows when a message wraps it).
area() { differ "$1" "$2" 480x310+0+0; }
xdotool mousemove --window "$wid" 236 170
shot m1.png
lit=$(area m0.png m1.png)
echo "view: hovering highlighted $lit pixels"
((lit > 20)) || { echo "view: hovering highlighted nothing"; exit 1; }
# F flips only an edge: move along the teapot until the element under the cursor is one.
flipped=0
for x in $(seq 200 6 290); do
    xdotool mousemove --window "$wid" "$x" 170
    shot before-f.png
    xdotool key f
    shot after-f.png
    flipped=$(area before-f.png after-f.png)
    ((flipped > 20)) && break
done
echo "view: F changed $flipped pixels of the picture"
((flipped > 20)) || { echo "view: F flipped no edge"; exit 1; }
xdotool key ctrl+z
xdotool mousemove --window "$wid" 10 10
shot m3.png
undone=$(area m0.png m3.png)
echo "view: after Ctrl+Z, $undone pixels differ from the first picture"
((undone == 0)) || { echo "view: Ctrl+Z did not undo"; exit 1; }
xdotool key Escape
wait "$pid" || { echo "view: exit code $? after Esc"; exit 1; }

set +e
out=$(env -u DISPLAY "$prism" view tri.svg 2>&1)
code=$?
set -e
[ "$code" = 2 ] || { echo "view: without a display, exit $code: $out"; exit 1; }
echo "view: without a display, exit 2: $out"
echo "view: all checks passed"
