"""Errors: one exception class per kind, with the file and line the library names."""

import numpy as np
import pytest

import prism


def test_a_malformed_file_names_its_line(tmp_path):
    """A bad OBJ line is an InputError with .file and .line."""
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n")
    with pytest.raises(prism.InputError) as e:
        prism.Mesh.read(bad)
    assert e.value.file == str(bad) and e.value.line == 4


def test_malformed_svg_text_names_its_line():
    """Malformed XML in SVG text is an InputError at its line."""
    with pytest.raises(prism.InputError) as e:
        prism.svg("<svg xmlns='http://www.w3.org/2000/svg'>\n<rect>\n")
    assert e.value.line is not None and e.value.file == "<string>"


def test_a_missing_file_is_an_os_error(tmp_path):
    """A missing file is a FileError, which is also an OSError."""
    with pytest.raises(OSError) as e:
        prism.svg(tmp_path / "none.svg")
    assert isinstance(e.value, prism.FileError)
    assert e.value.file == str(tmp_path / "none.svg")


def test_over_the_budget_is_a_limit_error():
    """A picture too large for the memory budget is refused before it is allocated; a
    larger budget lets a bigger request through, as --max-memory does."""
    scene = prism.load_scene()
    with pytest.raises(prism.LimitError):
        scene.render(resolution=(16384, 16384), spp=1)
    before = prism.memory_budget()
    try:
        prism.set_memory_budget(64 << 20)
        with pytest.raises(prism.LimitError):
            scene.render(resolution=(2048, 2048), spp=1)
        with pytest.raises(prism.LimitError):
            prism.Mesh(np.eye(3), [[0, 1, 2]]).subdivide(12)
    finally:
        prism.set_memory_budget(before)
    with pytest.raises(prism.ArgumentError):
        prism.set_memory_budget(1000)


def test_bad_arrays_are_argument_errors(tmp_path):
    with pytest.raises(prism.ArgumentError):
        prism.write_image(tmp_path / "x.png", np.zeros((4, 4, 2), dtype=np.uint8))
    with pytest.raises(ValueError):
        prism.write_image(tmp_path / "x.exr", np.zeros((4, 4, 3), dtype=np.uint8))


def test_a_tiny_png_asking_for_gigabytes_is_refused(tmp_path):
    """Hostile input: a PNG header declaring 60000 x 60000 pixels (14 GB decoded) is refused
    as over the budget before anything is allocated."""
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", 60000, 60000, 8, 6, 0, 0, 0)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"\0" * 64)) + chunk(b"IEND", b"")
    path = tmp_path / "huge.png"
    path.write_bytes(png)
    assert len(png) < 600
    with pytest.raises(prism.LimitError):
        prism.read_image(path)


def test_an_oversized_picture_is_a_limit_error():
    with pytest.raises(prism.LimitError):
        prism.svg('<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"/>', width=10**6)
    with pytest.raises(prism.ArgumentError):
        prism.svg('<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"/>', samples=3)


def test_a_hostile_thread_count_is_clamped():
    """threads=10**6 starts at most four threads a core (at least 16), with a warning, as
    the command's -t does; threads=0 is refused."""
    with pytest.warns(UserWarning, match="more than four a core"):
        image = prism.svg('<svg xmlns="http://www.w3.org/2000/svg" width="4" height="4"/>', threads=10**6)
    assert image.shape == (4, 4, 4)
    with pytest.raises(prism.ArgumentError):
        prism.svg('<svg xmlns="http://www.w3.org/2000/svg" width="4" height="4"/>', threads=0)
