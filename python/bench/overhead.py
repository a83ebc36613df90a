"""What the Python package adds to the command's own work, measured side by side in one run
(alternating, medians): the path tracer's render time (`prism render --stats` against
`Scene.render`) and the cloth's time per step (`prism cloth --stats` against `Cloth.step`).

    python python/bench/overhead.py [--cli target/release/prism] [--runs 11]

Run it from a venv where `pip install .` put the package (a release build, as the
command's).
"""

import argparse
import glob
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

import prism

REPO = Path(__file__).resolve().parents[2]


def course_file(name: str) -> str:
    roots = [os.environ.get("PRISM_DATA", ""), str(REPO.parent / "shared" / "assets")]
    for root in filter(None, roots):
        found = sorted(glob.glob(f"{root}/**/{name}", recursive=True))
        if found:
            return found[0]
    sys.exit(f"{name}: not found (set PRISM_DATA to the course's files)")


def stat(stderr: str, name: str) -> float:
    return float(re.search(rf"^{name}: ([0-9.]+) ms", stderr, re.M).group(1)) / 1e3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cli", default=str(REPO / "target" / "release" / "prism"))
    ap.add_argument("--runs", type=int, default=11)
    ap.add_argument("--frames", type=int, default=20)
    a = ap.parse_args()
    bunny, sphere = course_file("CBbunny.dae"), course_file("sphere.json")
    scene = prism.load_scene(bunny)
    times = {"render cli": [], "render py": [], "cloth cli": [], "cloth py": []}
    steps = 30 * a.frames
    for _ in range(a.runs):
        done = subprocess.run(
            [a.cli, "render", bunny, "-o", "/tmp/overhead.exr", "-r", "128", "96", "-s", "16", "--stats", "-q"],
            capture_output=True, text=True, check=True,
        )
        times["render cli"].append(stat(done.stderr, "render"))
        t = time.perf_counter()
        scene.render(spp=16, resolution=(128, 96))
        times["render py"].append(time.perf_counter() - t)
        done = subprocess.run(
            [a.cli, "cloth", sphere, "--frames", str(a.frames), "--stats", "-q"],
            capture_output=True, text=True, check=True,
        )
        times["cloth cli"].append(stat(done.stderr, "simulate") / steps)
        cloth = prism.Cloth(sphere)
        t = time.perf_counter()
        cloth.step(steps)
        times["cloth py"].append((time.perf_counter() - t) / steps)
    med = {k: statistics.median(v) for k, v in times.items()}
    print(f"render CBbunny 128x96 16 spp: cli {med['render cli'] * 1e3:.1f} ms, "
          f"python {med['render py'] * 1e3:.1f} ms, ratio {med['render py'] / med['render cli']:.3f}")
    print(f"cloth sphere.json, per step over {steps} steps: cli {med['cloth cli'] * 1e6:.1f} us, "
          f"python {med['cloth py'] * 1e6:.1f} us, ratio {med['cloth py'] / med['cloth cli']:.3f}")


if __name__ == "__main__":
    main()
