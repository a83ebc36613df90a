#!/usr/bin/env python3
"""`prism raytrace --stats` rays/s against the BVH bench's primary-ray rate on the same mesh,
side by side: per mesh, the bench's `primary` set on 2 threads (one ray per call, median of
its 5 runs) and the ray tracer's rays/s (rays of every kind over the render time) at
1024x1024 with shading, hard shadows, recursion and normal interpolation on, 2 threads, in
alternating runs; medians and their ratio.

Usage: python3 scripts/whitted_speed.py [-n RUNS] [--data DIR]
(from the workspace after `cargo build --release`; DIR is the course's files, default
../shared/assets)
"""
import argparse, os, re, statistics, subprocess, sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
PRISM = os.path.join(ROOT, "target", "release", "prism")
SCENES = [("teapot", "teapot.obj"), ("cornell-box", "CornellBox-Mirror-Rotated.obj")]


def bench(mesh):
    env = dict(os.environ, PRISM_RAYS_MESH=mesh, PRISM_RAYS_SETS="primary")
    r = subprocess.run(["cargo", "bench", "-q", "-p", "prism-accel", "--bench", "rays"],
                       cwd=ROOT, env=env, capture_output=True, text=True)
    m = re.search(r"primary +threads=2 .*Mrays/s=([0-9.]+)", r.stdout)
    if not m:
        sys.exit(f"bench failed:\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}")
    return float(m.group(1))


def raytrace(scene, data):
    r = subprocess.run([PRISM, "raytrace", scene, "--data", data, "-r", "1024", "1024", "-t", "2",
                        "-q", "--stats", "--enable", "shading,hard-shadow,recursive,normal-interp",
                        "--disable", "soft-shadow,texture,bloom,transparency,multi-rays",
                        "-o", "/tmp/prism_whitted_speed.png"], capture_output=True, text=True)
    m = re.search(r"rays/s: ([0-9]+)", r.stderr)
    if r.returncode != 0 or not m:
        sys.exit(f"prism failed:\n{r.stderr[-2000:]}")
    return float(m.group(1)) / 1e6


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("-n", type=int, default=3)
    ap.add_argument("--data", default=os.path.join(ROOT, "..", "shared", "assets"))
    o = ap.parse_args()
    print(f"{'scene':<12} {'bench Mrays/s':>13} {'raytrace Mrays/s':>16} {'ratio':>6}")
    for scene, mesh in SCENES:
        path = os.path.join(o.data, "delft-raytracer", "data", mesh)
        b, p = [], []
        for _ in range(o.n):
            b.append(bench(path))
            p.append(raytrace(scene, o.data))
        bm, pm = statistics.median(b), statistics.median(p)
        print(f"{scene:<12} {bm:>13.2f} {pm:>16.2f} {pm / bm:>6.2f}")


if __name__ == "__main__":
    main()
