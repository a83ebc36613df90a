#!/usr/bin/env python3
"""Run prism across a Ray cluster: a split render (one task per tile share, then
`prism merge`) or a parameter sweep (one task per point).

Each task runs the `prism` binary on its worker and sends its output files back to the
driver, so workers need no shared file system, only `prism` on their PATH (or --prism).
Without --address a local Ray instance with --workers worker processes is started.

    prism_ray.py render   --parts 8 -o cornell.png -- scene.dae -s 1024
    prism_ray.py raytrace --parts 8 -o teapot.png  -- teapot --enable bloom
    prism_ray.py sweep --set ks=100,500,5000 --set density=10,15 --out-dir sweep \\
        -- cloth scene.json --frames 90 --obj {out}.obj

A render task that fails is re-run by Ray (parts are written atomically and are the same
bytes every time); a task that prism refuses (exit 2: bad input) is not, and its message is
shown.
"""

import argparse
import itertools
import os
import subprocess
import sys
import tempfile

import ray


class PrismCrash(Exception):
    """prism died or could not start: worth running the task again."""


class PrismRefused(Exception):
    """prism refused its input (exit 2): running it again gives the same answer."""


def run_prism(cmd, cwd=None):
    """Runs one prism command (in `cwd` if this machine has that folder, so that relative
    paths mean what they meant to the driver); raises PrismRefused on exit 2, PrismCrash
    on any other failure."""
    cwd = cwd if cwd and os.path.isdir(cwd) else None
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd)
    except OSError as e:
        raise PrismCrash(f"{cmd[0]}: {e}") from None
    if done.returncode == 2:
        raise PrismRefused(done.stderr.strip())
    if done.returncode != 0:
        raise PrismCrash(f"exit {done.returncode}: {done.stderr.strip()}")


@ray.remote(max_retries=3, retry_exceptions=[PrismCrash])
def render_part(prism, command, args, index, count, threads, cwd):
    """Share `index` of `count` of a render: the part file's bytes."""
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, f"part-{index}-of-{count}.exr")
        run_prism([prism, command, *args, "--tile", f"{index}/{count}",
                   "-t", str(threads), "-q", "-o", out], cwd)
        with open(out, "rb") as f:
            return f.read()


@ray.remote(max_retries=3, retry_exceptions=[PrismCrash])
def sweep_point(prism, args, settings, cwd):
    """One sweep point: `args` with `--set K=V` for each setting and `{out}` replaced by a
    path stem; every file the run wrote under that stem, by suffix."""
    with tempfile.TemporaryDirectory() as d:
        stem = os.path.join(d, "out")
        cmd = [prism, *[a.replace("{out}", stem) for a in args], "-q"]
        for s in settings:
            cmd += ["--set", s]
        run_prism(cmd, cwd)
        files = {}
        for name in sorted(os.listdir(d)):
            path = os.path.join(d, name)
            if os.path.isfile(path):
                with open(path, "rb") as f:
                    files[name[len("out"):]] = f.read()
        return files


def write_atomic(path, data):
    """Writes bytes to path through a temporary file in the same folder."""
    tmp = f"{path}.tmp-{os.getpid()}"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def split_render(a, command):
    """Renders every share on the cluster, keeps the parts, merges them."""
    parts_dir = a.keep or tempfile.mkdtemp(prefix="prism-parts-")
    os.makedirs(parts_dir, exist_ok=True)
    tasks = [render_part.options(num_cpus=a.threads).remote(
        a.prism, command, a.args, i, a.parts, a.threads, os.getcwd()) for i in range(a.parts)]
    paths = []
    for i, task in enumerate(tasks):
        path = os.path.join(parts_dir, f"part-{i}-of-{a.parts}.exr")
        write_atomic(path, ray.get(task))
        paths.append(path)
    cmd = [a.prism, "merge", *paths, "-o", a.output, "-q"]
    if a.exr:
        cmd += ["--exr", a.exr]
    run_prism(cmd)
    if not a.keep:
        for p in paths:
            os.remove(p)
        os.rmdir(parts_dir)
    print(f"prism_ray: {a.parts} parts -> {a.output}")


def sweep(a):
    """Runs every point of the grid the --set lists span; writes point-K<suffix> files and
    points.tsv (K and its settings) into --out-dir."""
    axes = []
    for s in a.set:
        key, _, values = s.partition("=")
        if not key or not values:
            sys.exit(f"prism_ray: --set {s}: expected KEY=V1,V2,...")
        axes.append([f"{key}={v}" for v in values.split(",")])
    points = list(itertools.product(*axes))
    os.makedirs(a.out_dir, exist_ok=True)
    tasks = [sweep_point.options(num_cpus=a.threads).remote(
        a.prism, a.args, list(p), os.getcwd()) for p in points]
    lines = []
    for k, (point, task) in enumerate(zip(points, tasks)):
        for suffix, data in ray.get(task).items():
            write_atomic(os.path.join(a.out_dir, f"point-{k}{suffix}"), data)
        lines.append(f"{k}\t{' '.join(point)}\n")
    write_atomic(os.path.join(a.out_dir, "points.tsv"), "".join(lines).encode())
    print(f"prism_ray: {len(points)} sweep points -> {a.out_dir}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("mode", choices=["render", "raytrace", "sweep"],
                   help="a split `prism render` or `prism raytrace`, or a sweep")
    p.add_argument("--address", help="a running Ray cluster (default: start a local one)")
    p.add_argument("--workers", type=int, default=2,
                   help="CPUs of the local Ray instance (default 2)")
    p.add_argument("--threads", type=int, default=1,
                   help="CPUs (prism threads) per task (default 1)")
    p.add_argument("--prism", default="prism", help="the prism binary on the workers")
    p.add_argument("--parts", type=int, default=4, help="tile shares of a render")
    p.add_argument("-o", "--output", help="the merged picture of a render")
    p.add_argument("--exr", help="also write the merged linear picture here")
    p.add_argument("--keep", metavar="DIR", help="keep the part files in DIR")
    p.add_argument("--set", action="append", default=[], metavar="KEY=V1,V2",
                   help="a sweep axis (repeat for a grid)")
    p.add_argument("--out-dir", default="sweep", help="where a sweep's files go")
    p.epilog = "After --: the prism arguments (the scene and options)."
    argv = sys.argv[1:]
    cut = argv.index("--") if "--" in argv else len(argv)
    a = p.parse_args(argv[:cut])
    a.args = argv[cut + 1:]
    if a.mode != "sweep" and (not a.output or a.parts < 1):
        p.error("a render needs -o OUT and --parts of at least 1")
    if a.mode == "sweep" and not a.set:
        p.error("a sweep needs at least one --set KEY=V1,V2,...")
    if a.address:
        ray.init(address=a.address, log_to_driver=False)
    else:
        ray.init(num_cpus=a.workers, include_dashboard=False, log_to_driver=False)
    try:
        if a.mode == "sweep":
            sweep(a)
        else:
            split_render(a, a.mode)
    except (PrismRefused, PrismCrash, ray.exceptions.RayTaskError) as e:
        # A task's exception arrives wrapped; its cause is prism's own message.
        cause = getattr(e, "cause", None) or e
        print(f"prism_ray: {cause}", file=sys.stderr)
        sys.exit(2 if isinstance(cause, PrismRefused) else 1)
    finally:
        ray.shutdown()


if __name__ == "__main__":
    main()
