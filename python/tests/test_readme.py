"""The README's Python example, run as a user would: from a folder holding the course's
files by their names."""

import re

from conftest import ASSETS, REPO


def test_the_readme_example_runs(tmp_path, monkeypatch):
    """Every line of the README's python block runs, and writes what it says."""
    blocks = re.findall(r"```python\n(.*?)```", (REPO / "README.md").read_text(), re.S)
    assert len(blocks) == 1
    code = blocks[0]
    for name in set(re.findall(r'"([\w.]+\.(?:svg|dae|obj|json))"', code)):
        found = sorted(p for p in ASSETS.rglob(name) if p.is_file())
        if found:
            (tmp_path / name).symlink_to(found[0])
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    for written in ("lion.png", "smooth.obj", "bunny.exr"):
        assert (tmp_path / written).stat().st_size > 0
