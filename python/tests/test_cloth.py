"""prism.Cloth against `prism cloth --obj`, and its positions a view of the simulation."""

import numpy as np
import pytest

import prism
from conftest import course_file, run


def obj_rows(path, tag):
    return [line.split()[1:] for line in path.read_text().splitlines() if line.startswith(tag + " ")]


@pytest.mark.parametrize("scene, frames", [("sphere.json", 3), ("pinned2.json", 2)])
def test_cloth_equals_the_commands_obj(tmp_path, cli, scene, frames):
    """Oracle: `prism cloth --frames N --obj` writes the positions after .frame(N), and the
    triangles .triangles holds (from 1, with uvs and normals)."""
    path = course_file(scene)
    out = tmp_path / "cli.obj"
    run(cli, "cloth", path, "--frames", frames, "--obj", out, "--set", "ks=6000")
    cloth = prism.Cloth(path, overrides={"ks": 6000})
    cloth.frame(frames)
    assert cloth.steps == 30 * frames
    v = np.array(obj_rows(out, "v"), dtype=float)
    assert np.array_equal(cloth.positions, v)
    f = np.array([[int(c.split("/")[0]) - 1 for c in row] for row in obj_rows(out, "f")])
    assert np.array_equal(cloth.triangles, f)


def test_steps_add_up_to_frames():
    """Property: 30 steps are a frame, on any number of threads."""
    a = prism.Cloth(course_file("sphere.json"))
    b = prism.Cloth(course_file("sphere.json"))
    a.step(60, threads=1)
    b.frame(2, threads=2)
    assert np.array_equal(a.positions, b.positions)


def test_positions_are_the_simulations_own_buffer():
    """No copy: the array's base is the cloth, and a step is seen through it."""
    cloth = prism.Cloth(course_file("sphere.json"))
    p = cloth.positions
    assert p.base is cloth
    assert np.shares_memory(p, cloth.positions)
    before = p.copy()
    cloth.step()
    assert not np.array_equal(p, before)
    assert np.array_equal(p, cloth.positions)
    nw, nh = cloth.grid
    assert p.shape == (nw * nh, 3)


def test_bad_overrides_name_the_setting():
    """A bad override is an InputError naming it."""
    with pytest.raises(prism.InputError, match="nonsense"):
        prism.Cloth(course_file("sphere.json"), overrides={"nonsense": 1})
