#!/usr/bin/env python3
"""Loop subdivision of the staged meshes (cow, teapot, beetle from ../shared/assets/meshedit/dae)
by prism and by its peers, compared vertex by vertex with ../shared/bench/mesh/compare.py's
helpers (matched by position; goal max |dv| <= 1e-12 and identical face sets).

  python3 crates/prism-mesh/benches/compare_staged.py [--prism ./target/release/prism] [--levels 1 2]

The .dae files are converted to OBJ by `prism mesh convert` (node transforms applied, Y up) and
both sides subdivide that same OBJ.
"""
import argparse, os, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.normpath(os.path.join(HERE, "..", "..", "..", "..", "shared"))
sys.path.insert(0, os.path.join(SHARED, "bench", "mesh"))
import compare  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--prism", default="./target/release/prism")
    ap.add_argument("--om", default="/tmp/om_loop")
    ap.add_argument("--levels", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--meshes", nargs="+", default=["cow", "teapot", "beetle"])
    a = ap.parse_args()
    peers = {"warren": ["libigl"], "loop": ["pymeshlab"] + (["openmesh"] if os.path.exists(a.om) else [])}
    worst = 0.0
    with tempfile.TemporaryDirectory() as d:
        for name in a.meshes:
            obj = os.path.join(d, name + ".obj")
            dae = os.path.join(SHARED, "assets", "meshedit", "dae", name + ".dae")
            subprocess.run([a.prism, "mesh", "convert", dae, "-o", obj], check=True)
            V, F = compare.read_obj(obj)
            for L in a.levels:
                for w, names in peers.items():
                    mine, _ = compare.prism(a.prism, V, F, L, w)
                    for n in names:
                        theirs, _ = compare.peer(n, V, F, L, a.om)
                        dist, same = compare.distance(mine, theirs)
                        worst = max(worst, dist)
                        print(f"{name:8s} {len(F):6d} faces L{L} weights={w:6s} vs {n:9s} "
                              f"max|dv|={dist:.3e} faces_match={same}", flush=True)
    print(f"worst max|dv| = {worst:.3e}")


if __name__ == "__main__":
    main()
