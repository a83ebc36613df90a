"""The wheel installs and runs where no Rust toolchain is: `pip wheel .`, then a fresh
venv with cargo and rustc out of reach."""

import os
import shutil
import subprocess
import sys

from conftest import REPO

PROGRAM = """
import prism
a = prism.svg('<svg xmlns="http://www.w3.org/2000/svg" width="8" height="4"><rect width="4" height="4" fill="red"/></svg>', samples=1)
assert a.shape == (4, 8, 4) and tuple(a[0, 0]) == (255, 0, 0, 255) and a[0, 7, 3] == 0, a
print(prism.__version__)
"""


def test_the_wheel_runs_without_a_rust_toolchain(tmp_path):
    """A wheel built from the checkout installs into a fresh venv and works there with no
    cargo, rustc or rustup on the PATH."""
    wheels = tmp_path / "wheels"
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", str(REPO), "--no-deps", "-q", "-w", str(wheels)],
        check=True,
    )
    (wheel,) = wheels.glob("prism-*.whl")
    assert "abi3" in wheel.name
    venv = tmp_path / "fresh"
    bare = {
        "PATH": f"{venv / 'bin'}:/usr/bin:/bin",
        "HOME": str(tmp_path),
        "CARGO_HOME": str(tmp_path / "no-cargo"),
        "RUSTUP_HOME": str(tmp_path / "no-rustup"),
        "PIP_CACHE_DIR": os.environ.get("PIP_CACHE_DIR", os.path.expanduser("~/.cache/pip")),
    }
    for tool in ("cargo", "rustc", "rustup"):
        assert shutil.which(tool, path=bare["PATH"]) is None, f"{tool} is on the bare PATH"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    subprocess.run(
        [str(venv / "bin" / "python"), "-m", "pip", "install", "-q", "--disable-pip-version-check", str(wheel)],
        check=True,
        env=bare,
    )
    done = subprocess.run(
        [str(venv / "bin" / "python"), "-c", PROGRAM],
        cwd=tmp_path,
        env=bare,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr


def test_the_stubs_match_the_module():
    """mypy's stubtest: every function and class of the native module is in the stubs with
    the signature it has at run time (editors complete from these)."""
    done = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "prism._prism"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stdout + done.stderr
