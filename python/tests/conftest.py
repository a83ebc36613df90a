"""Shared fixtures: the repository, the course's files, and the `prism` command, the oracle
every test compares the package against."""

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def _assets() -> Path:
    given = os.environ.get("PRISM_DATA")
    if given:
        return Path(given)
    for up in [REPO, *REPO.parents]:
        for candidate in (up / "shared" / "assets", up.parent / "shared" / "assets"):
            if candidate.is_dir():
                return candidate
    pytest.exit("the course's files (shared/assets beside the checkout) were not found", 2)


ASSETS = _assets()


@pytest.fixture(scope="session")
def assets() -> Path:
    """The course's files (`shared/assets`)."""
    return ASSETS


def course_file(name: str) -> Path:
    """A course file by name: the first in path order, as the README names them."""
    found = sorted(p for p in ASSETS.rglob(name) if p.is_file())
    assert found, f"{name} is not among the course's files"
    return found[0]


@pytest.fixture(scope="session")
def cli() -> Path:
    """The `prism` command built from this checkout (PRISM_CLI, else target/release)."""
    path = Path(os.environ.get("PRISM_CLI", REPO / "target" / "release" / "prism"))
    if not path.is_file():
        pytest.exit(f"{path} is missing: build it with `cargo build --release -p prism-cli`", 2)
    return path


def run(cli: Path, *args, **kwargs) -> subprocess.CompletedProcess:
    """Runs the command; fails the test with its stderr if it fails."""
    done = subprocess.run(
        [str(cli), *map(str, args)], capture_output=True, text=True, **kwargs
    )
    assert done.returncode == 0, done.stderr
    return done


@pytest.fixture(autouse=True)
def _course_data(monkeypatch):
    """Presets and default textures are found in the course's files."""
    monkeypatch.setenv("PRISM_DATA", str(ASSETS))
