"""prism.svg against `prism svg`: the same PNG bytes."""

import numpy as np
import pytest

import prism
from conftest import REPO, course_file, run

FEATURES = REPO / "docs" / "examples" / "svg" / "features.svg"


@pytest.mark.parametrize(
    "name, args, kwargs",
    [
        ("features", ["-s", "16"], {}),
        ("features-zoom", ["-s", "4", "--zoom", "1.5"], {"samples": 4, "zoom": 1.5}),
        ("lion-width", ["-s", "16", "--width", "300"], {"width": 300}),
    ],
)
def test_svg_equals_the_command(tmp_path, cli, name, args, kwargs):
    """Oracle: `prism svg` writes the same PNG bytes as write_image of the array."""
    src = FEATURES if name.startswith("features") else course_file("05_lion.svg")
    ref = tmp_path / "cli.png"
    run(cli, "svg", src, "-o", ref, *args)
    image = prism.svg(src, **kwargs)
    assert image.dtype == np.uint8 and image.ndim == 3 and image.shape[2] == 4
    mine = tmp_path / "py.png"
    prism.write_image(mine, image)
    assert mine.read_bytes() == ref.read_bytes()


def test_course_dialect_equals_the_command(tmp_path, cli):
    """Oracle: `prism svg --compat cs184` (an RGB PNG) and the array's colour channels."""
    src = course_file("test4.svg")
    ref = tmp_path / "cli.png"
    run(cli, "svg", src, "-o", ref, "--compat", "cs184", "--width", "256", "--height", "256")
    image = prism.svg(src, compat="cs184", width=256, height=256, samples=1)
    assert image.shape == (256, 256, 4)
    mine = tmp_path / "py.png"
    prism.write_image(mine, np.ascontiguousarray(image[:, :, :3]))
    assert mine.read_bytes() == ref.read_bytes()


def test_text_and_file_give_the_same_pixels():
    """Property: SVG text rasterizes as its file does; the size rules hold."""
    text = FEATURES.read_text()
    from_file = prism.svg(FEATURES, samples=4)
    from_text = prism.svg(text, samples=4)
    assert np.array_equal(from_file, from_text)
    wide = prism.svg('<svg xmlns="http://www.w3.org/2000/svg" width="40" height="10"/>', height=5)
    assert wide.shape == (5, 20, 4)


def test_the_array_is_owned_by_numpy_without_a_copy():
    """The pixels move from Rust into the array: it is writeable and C-contiguous."""
    image = prism.svg(FEATURES, samples=1)
    assert image.flags.c_contiguous and image.flags.writeable


def test_the_picture_shows_in_a_notebook(tmp_path):
    """prism.show's PNG is write_image's PNG."""
    image = prism.svg(FEATURES, samples=1)
    path = tmp_path / "x.png"
    prism.write_image(path, image)
    assert prism.show(image)._repr_png_() == path.read_bytes()
    assert np.array_equal(prism.read_image(path), image)
