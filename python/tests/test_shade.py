"""prism.shade against `prism shade`: the same PNG bytes."""

import numpy as np
import pytest

import prism
from conftest import course_file, run


@pytest.mark.parametrize(
    "shader, args, kwargs",
    [
        ("phong", [], {}),
        ("normal", ["--eye", "0,0.5,3", "--target", "0,0.3,0", "--fov-y", "30"],
         {"eye": (0, 0.5, 3), "target": (0, 0.3, 0), "fov_y": 30}),
        ("texture", ["-s", "4"], {"samples": 4}),
        ("mirror", [], {}),
    ],
)
def test_shade_equals_the_command(tmp_path, cli, assets, shader, args, kwargs):
    """Oracle: `prism shade -o x.png` writes the bytes of write_image of the array."""
    teapot = course_file("teapot.obj")
    ref = tmp_path / "cli.png"
    run(cli, "shade", teapot, "-o", ref, "--shader", shader, "-r", "160", "120", "--data", assets, *args)
    image = prism.shade(teapot, shader=shader, resolution=(160, 120), data=assets, **kwargs)
    assert image.shape == (120, 160, 3) and image.dtype == np.uint8
    mine = tmp_path / "py.png"
    prism.write_image(mine, image)
    assert mine.read_bytes() == ref.read_bytes()


def test_a_mesh_object_shades_as_its_file(tmp_path):
    """Property: a prism.Mesh draws as the file it was read from (a format without uvs)."""
    cow = course_file("cow.dae")
    assert np.array_equal(
        prism.shade(prism.Mesh.read(cow), resolution=(80, 60)),
        prism.shade(cow, resolution=(80, 60)),
    )
