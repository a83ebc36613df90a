#!/usr/bin/env python3
"""prism against Mitsuba 3 (llvm_ad_rgb) on Mitsuba scene files, side by side in one run:
samples per second of the render itself (prism's `--stats` render time; Mitsuba's render
call after a warm-up render that compiles its kernels) and each process's peak memory
(`/usr/bin/time -v`), in alternating runs, medians.

Usage: python3 scripts/mitsuba_speed.py [-n RUNS] [--spp N] [--size W H] SCENE.xml ...
(each scene's film is set to W x H in a copy beside it; needs mitsuba 3.9.1 and libLLVM 19;
run from the workspace after `cargo build --release`)
"""
import argparse, os, re, statistics, subprocess, sys, tempfile

LLVM = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"
PRISM = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "target", "release", "prism")
MITSUBA = r"""
import os, sys, time
os.environ.setdefault("DRJIT_LIBLLVM_PATH", %r)
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
import drjit as dr
scene = mi.load_file(sys.argv[1])
dr.eval(mi.render(scene, spp=4, seed=1))
t = time.perf_counter()
img = mi.render(scene, spp=int(sys.argv[2]), seed=2)
dr.eval(img); dr.sync_thread()
print("render:", (time.perf_counter() - t) * 1e3, "ms")
""" % LLVM


def sized(scene, w, h):
    """A copy of `scene` beside it (file names stay relative) with its film w x h."""
    text = open(scene).read()
    text = re.sub(r'(<integer name="width" value=")[^"]*(")', rf"\g<1>{w}\g<2>", text)
    text = re.sub(r'(<integer name="height" value=")[^"]*(")', rf"\g<1>{h}\g<2>", text)
    fd, path = tempfile.mkstemp(suffix=".xml", dir=os.path.dirname(os.path.abspath(scene)))
    with os.fdopen(fd, "w") as f:
        f.write(text)
    return path


def timed(cmd):
    """(render milliseconds, peak resident kilobytes) of one run of `cmd`."""
    r = subprocess.run(["/usr/bin/time", "-v"] + cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr[-2000:]}")
    out = r.stdout + r.stderr
    ms = float(re.search(r"render: ([0-9.]+) ms", out).group(1))
    kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", out).group(1))
    return ms, kb


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("-n", type=int, default=3)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--size", type=int, nargs=2, default=[512, 384])
    ap.add_argument("scenes", nargs="+")
    o = ap.parse_args()
    w, h = o.size
    samples = w * h * o.spp
    ratios = []
    print(f"{'scene':<18} {'prism Ms/s':>10} {'Mitsuba Ms/s':>12} {'ratio':>6} {'prism MB':>9} {'Mitsuba MB':>10} {'mem':>5}")
    for scene in o.scenes:
        copy = sized(scene, w, h)
        try:
            p, m = [], []
            for _ in range(o.n):
                p.append(timed([PRISM, "render", copy, "-s", str(o.spp), "-o", "/tmp/prism_speed.exr",
                                "--stats", "-q"]))
                m.append(timed([sys.executable, "-c", MITSUBA, copy, str(o.spp)]))
        finally:
            os.remove(copy)
        pt = statistics.median(x for x, _ in p)
        mt = statistics.median(x for x, _ in m)
        pm = max(k for _, k in p) / 1024
        mm = max(k for _, k in m) / 1024
        ratio = mt / pt
        ratios.append(ratio)
        name = os.path.basename(scene)
        print(f"{name:<18} {samples / pt / 1e3:>10.2f} {samples / mt / 1e3:>12.2f} {ratio:>6.2f} {pm:>9.0f} {mm:>10.0f} {pm / mm:>5.2f}")
    geo = statistics.geometric_mean(ratios)
    print(f"geometric mean of prism / Mitsuba samples/s: {geo:.2f} (lowest {min(ratios):.2f})")


if __name__ == "__main__":
    main()
