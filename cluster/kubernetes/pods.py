#!/usr/bin/env python3
"""Runs the pods of prism's Kubernetes Jobs on this machine, without a cluster: for each
completion index, the container's command with the environment Kubernetes gives it
(its env values and JOB_COMPLETION_INDEX), the volume's /data mapped to a local folder.

    pods.py --dry-run render-job.yaml merge-job.yaml     # print each pod's prism command
    pods.py --data DIR --prism BIN render-job.yaml merge-job.yaml   # run them for real

Also checks each manifest as Kubernetes would need it (an Indexed Job with completions,
a container with a command); needs PyYAML.
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile

import yaml


def check_job(doc, path):
    """The fields the pods rely on, with a message naming the manifest on failure."""
    def need(ok, what):
        if not ok:
            sys.exit(f"{path}: {what}")
    need(doc.get("apiVersion") == "batch/v1" and doc.get("kind") == "Job",
         "expected apiVersion batch/v1, kind Job")
    spec = doc.get("spec", {})
    pod = spec.get("template", {}).get("spec", {})
    need(pod.get("restartPolicy") in ("Never", "OnFailure"),
         "a Job's pods need restartPolicy Never or OnFailure")
    containers = pod.get("containers", [])
    need(len(containers) == 1 and containers[0].get("command"),
         "expected one container with a command")
    if spec.get("completionMode") == "Indexed":
        need(isinstance(spec.get("completions"), int) and spec["completions"] >= 1,
             "an Indexed Job needs completions of 1 or more")
        env = {e["name"]: e["value"] for e in containers[0].get("env", [])}
        need(env.get("PARTS") == str(spec["completions"]),
             f"env PARTS ({env.get('PARTS')}) must equal completions ({spec['completions']})")
    return spec, containers[0]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("manifests", nargs="+")
    p.add_argument("--dry-run", action="store_true", help="print the commands only")
    p.add_argument("--data", help="the local folder that stands for the volume's /data")
    p.add_argument("--prism", default="prism", help="the prism binary")
    p.add_argument("--env", action="append", default=[], metavar="NAME=VALUE",
                   help="override a container env value (e.g. a smaller PRISM_ARGS)")
    a = p.parse_args()
    stubs = tempfile.mkdtemp()
    try:
        prism = a.prism
        if a.dry_run:
            stub = os.path.join(stubs, "prism")
            with open(stub, "w") as f:
                f.write('#!/bin/sh\necho prism "$@"\n')
            os.chmod(stub, 0o755)
            mkdir = os.path.join(stubs, "mkdir")
            with open(mkdir, "w") as f:
                f.write("#!/bin/sh\n")
            os.chmod(mkdir, 0o755)
            prism = stub
        elif not a.data:
            p.error("give --data DIR (or --dry-run)")
        for path in a.manifests:
            with open(path) as f:
                docs = [d for d in yaml.safe_load_all(f) if d]
            for doc in docs:
                spec, container = check_job(doc, path)
                name = doc["metadata"]["name"]
                indexed = spec.get("completionMode") == "Indexed"
                for index in range(spec["completions"] if indexed else 1):
                    env = dict(os.environ)
                    env["PATH"] = stubs + os.pathsep + env["PATH"]
                    env.update({e["name"]: e["value"] for e in container.get("env", [])})
                    env.update(dict(kv.split("=", 1) for kv in a.env))
                    if indexed:
                        env["JOB_COMPLETION_INDEX"] = str(index)
                    cmd = [*container["command"], *container.get("args", [])]
                    if a.data:
                        cmd = [c.replace("/data", a.data) for c in cmd]
                        env = {k: v.replace("/data", a.data) for k, v in env.items()}
                    if not a.dry_run:
                        cmd = [c.replace("exec prism ", f"exec {prism} ") for c in cmd]
                    label = f"{name}[{index}]" if indexed else name
                    out = subprocess.run(cmd, env=env, capture_output=True, text=True)
                    if out.returncode != 0:
                        sys.exit(f"{label}: exit {out.returncode}: {out.stderr.strip()}")
                    if a.dry_run:
                        print(f"{label}: {out.stdout.strip()}")
    finally:
        shutil.rmtree(stubs)


if __name__ == "__main__":
    main()
