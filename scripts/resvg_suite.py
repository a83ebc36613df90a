#!/usr/bin/env python3
"""Runs resvg's test suite through `prism svg` and prints the pass rate per category.

A test passes when at most 1% of its pixels differ from resvg's reference PNG by more than
8/255 in some channel, both images composited over white. Each file is drawn as resvg's
own test harness draws it: 300 pixels wide, with the suite's fonts only (Noto Serif, Noto
Sans, Noto Mono, Yellowtail, Sedgwick Ave Display for the generic families).

Needs numpy and Pillow (`pip install numpy pillow`) and a checkout of the suite, which is
not part of prism: fetch linebender/resvg into a scratch folder, then

    python3 scripts/resvg_suite.py --suite SCRATCH/resvg/crates/resvg/tests

`--failures FILE` writes the names of the failing tests, one per line.
"""

import argparse
import collections
import os
import subprocess
import sys
import tempfile

import numpy as np
from PIL import Image


def over_white(path):
    img = np.asarray(Image.open(path).convert("RGBA"), dtype=np.float64) / 255.0
    rgb, a = img[..., :3], img[..., 3:4]
    return rgb * a + (1.0 - a)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--suite", required=True, help="resvg's crates/resvg/tests folder")
    ap.add_argument("--prism", default="target/release/prism")
    ap.add_argument("--spp", default="16")
    ap.add_argument("--out", help="folder for prism's PNGs (default: a temporary one)")
    ap.add_argument("--failures", help="write failing test names here")
    args = ap.parse_args()
    tests = os.path.join(args.suite, "tests")
    fonts = os.path.join(args.suite, "fonts")
    out = args.out or tempfile.mkdtemp(prefix="prism-resvg-")
    os.makedirs(out, exist_ok=True)
    cmd = [
        args.prism, "svg", tests, "-o", out, "--width", "300", "--spp", args.spp, "-q",
        "--font-dir", fonts, "--skip-system-fonts",
        "--serif-family", "Noto Serif", "--sans-serif-family", "Noto Sans",
        "--cursive-family", "Yellowtail", "--fantasy-family", "Sedgwick Ave Display",
        "--monospace-family", "Noto Mono",
    ]
    subprocess.run(cmd, stderr=subprocess.DEVNULL)
    passed = collections.Counter()
    total = collections.Counter()
    failing = []
    for root, _, files in os.walk(tests):
        for f in sorted(files):
            if not f.endswith(".svg"):
                continue
            rel = os.path.relpath(os.path.join(root, f), tests)
            category = rel.split(os.sep)[0]
            total[category] += 1
            ref = os.path.join(root, f[:-4] + ".png")
            got = os.path.join(out, rel[:-4] + ".png")
            ok = False
            if os.path.exists(ref) and os.path.exists(got):
                a, b = over_white(ref), over_white(got)
                if a.shape == b.shape:
                    bad = (np.abs(a - b).max(axis=2) > 8.0 / 255.0).mean()
                    ok = bad <= 0.01
            if ok:
                passed[category] += 1
            else:
                failing.append(rel)
    print(f"{'category':<16}{'passed':>8}{'total':>8}{'rate':>9}")
    for c in sorted(total):
        print(f"{c:<16}{passed[c]:>8}{total[c]:>8}{100.0 * passed[c] / total[c]:>8.1f}%")
    p, t = sum(passed.values()), sum(total.values())
    print(f"{'all':<16}{p:>8}{t:>8}{100.0 * p / t:>8.1f}%")
    if args.failures:
        with open(args.failures, "w") as fh:
            fh.write("\n".join(sorted(failing)) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
