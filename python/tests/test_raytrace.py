"""prism.raytrace and prism.trace_pixel against `prism raytrace`."""

import json

import numpy as np

import prism
from conftest import run


def test_raytrace_equals_the_commands_exr(tmp_path, cli):
    """Oracle: `prism raytrace -o x.exr` holds the floats prism.raytrace returns."""
    ref = tmp_path / "cli.exr"
    run(cli, "raytrace", "teapot", "-o", ref, "-r", "96", "64", "--enable", "soft-shadow")
    image = prism.raytrace("teapot", resolution=(96, 64), features=["soft-shadow"])
    mine = tmp_path / "py.exr"
    prism.write_image(mine, image)
    assert mine.read_bytes() == ref.read_bytes()


def test_features_switch_off(tmp_path, cli):
    """Oracle: a dict turns features off as --disable does."""
    ref = tmp_path / "cli.exr"
    run(cli, "raytrace", "cornell-box", "-o", ref, "-r", "64", "64", "--disable", "shading,bvh")
    image = prism.raytrace("cornell-box", resolution=(64, 64), features={"shading": False, "bvh": False})
    assert np.array_equal(prism.read_image(ref), image)


def test_trace_pixel_is_the_debug_pixel_record(tmp_path, cli):
    """Oracle: `--debug-pixel X,Y` writes the record trace_pixel returns."""
    out = tmp_path / "cli.png"
    run(cli, "raytrace", "cornell-box", "-o", out, "-r", "64", "64", "--debug-pixel", "20,30")
    record = json.loads((tmp_path / "cli.rays.json").read_text())
    assert prism.trace_pixel("cornell-box", 20, 30, resolution=(64, 64)) == record
