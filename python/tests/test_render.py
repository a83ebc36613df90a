"""prism.render and prism.load_scene against `prism render`: the same EXR; threads,
progress, Ctrl-C and the GIL."""

import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import prism
from conftest import REPO, course_file, run

MITSUBA = REPO / "crates" / "prism-render" / "tests" / "golden" / "mitsuba" / "xml" / "spheres.xml"


def test_render_equals_the_commands_exr(tmp_path, cli):
    """Oracle: `prism render -o x.exr` holds the floats prism.render returns."""
    bunny = course_file("CBbunny.dae")
    ref = tmp_path / "cli.exr"
    run(cli, "render", bunny, "-o", ref, "-r", "128", "96", "-s", "16", "--seed", "3")
    image = prism.render(bunny, spp=16, resolution=(128, 96), seed=3)
    assert image.shape == (96, 128, 3) and image.dtype == np.float32
    mine = tmp_path / "py.exr"
    prism.write_image(mine, image)
    assert mine.read_bytes() == ref.read_bytes()
    assert np.array_equal(prism.read_image(ref), image)


def test_a_mitsuba_scene_uses_its_own_settings(tmp_path, cli):
    """Oracle: a Mitsuba scene renders at its film's size and sampler's count, as the
    command renders it."""
    ref = tmp_path / "cli.exr"
    run(cli, "render", MITSUBA, "-o", ref, "-s", "4", "-D", "spp=4")
    scene = prism.load_scene(MITSUBA, defines={"spp": "4"})
    image = scene.render(spp=4)
    assert image.shape[:2] == scene.resolution[::-1]
    assert np.array_equal(prism.read_image(ref), image)


def test_a_crop_window_is_kept_unless_a_size_is_given(tmp_path, cli):
    """Oracle: a Mitsuba film's crop window renders as the command renders it, and a size
    given to render replaces the film, crop and all, as `-r` does."""
    text = MITSUBA.read_text().replace(
        '<film type="hdrfilm">',
        '<film type="hdrfilm"><integer name="crop_offset_x" value="50"/>'
        '<integer name="crop_offset_y" value="10"/><integer name="crop_width" value="30"/>'
        '<integer name="crop_height" value="20"/>',
    )
    cropped = tmp_path / "cropped.xml"
    cropped.write_text(text)
    (tmp_path / "pattern.png").symlink_to(MITSUBA.parent / "pattern.png")
    scene = prism.load_scene(cropped)
    assert scene.resolution == (30, 20)
    run(cli, "render", cropped, "-o", tmp_path / "crop.exr", "-s", "2")
    assert np.array_equal(prism.read_image(tmp_path / "crop.exr"), scene.render(spp=2))
    run(cli, "render", cropped, "-o", tmp_path / "full.exr", "-s", "2", "-r", "64", "48")
    assert np.array_equal(prism.read_image(tmp_path / "full.exr"), scene.render(spp=2, resolution=(64, 48)))


def test_two_threads_render_one_scene_at_once():
    """A scene renders from two Python threads at once, each as it renders alone."""
    scene = prism.load_scene(course_file("CBspheres_lambertian.dae"))
    alone = [scene.render(spp=2, resolution=(48, 32), seed=s) for s in (0, 1)]
    out = [None, None]

    def go(i):
        out[i] = scene.render(spp=2, resolution=(48, 32), seed=i)

    threads = [threading.Thread(target=go, args=(i,)) for i in (0, 1)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(np.array_equal(a, b) for a, b in zip(alone, out))


def test_a_loaded_scene_renders_again_the_same_on_any_threads():
    """Property: a scene read once renders the same bytes again, on 1 or 2 threads, and a
    new seed gives new noise."""
    scene = prism.load_scene(course_file("CBspheres_lambertian.dae"))
    a = scene.render(spp=4, resolution=(64, 48), threads=1)
    b = scene.render(spp=4, resolution=(64, 48), threads=2)
    c = scene.render(spp=4, resolution=(64, 48), seed=1)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_progress_reaches_the_total():
    """The callback sees samples taken rise to the total."""
    seen = []
    prism.render(course_file("CBbunny.dae"), spp=8, resolution=(64, 48), progress=lambda d, t: seen.append((d, t)))
    assert seen and seen[-1] == (64 * 48 * 8, 64 * 48 * 8)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)


def test_the_gil_is_released_during_a_render():
    """A second Python thread keeps running while the path tracer works (were the GIL
    held, it could not count at all until the render ended)."""
    ticks = 0
    done = threading.Event()

    def count():
        nonlocal ticks
        while not done.is_set():
            ticks += 1
            time.sleep(0.0005)

    t = threading.Thread(target=count)
    t.start()
    seen = []
    prism.render(course_file("CBbunny.dae"), spp=256, resolution=(96, 72),
                 progress=lambda d, total: seen.append(ticks))
    done.set()
    t.join()
    assert len(seen) >= 2
    assert seen[-1] - seen[0] >= 20, seen


CHILD = r"""
import sys, prism
started = False
def progress(done, total):
    global started
    if not started:
        started = True
        print("started", flush=True)
try:
    CALL
    print("finished", flush=True)
except KeyboardInterrupt:
    print("interrupted", flush=True)
"""


@pytest.mark.parametrize(
    "call",
    [
        "prism.render(sys.argv[1], spp=100000, resolution=(256, 192), progress=progress)",
        "prism.raytrace('cornell-box', resolution=(2048, 2048), spp=4096, progress=progress)",
        "prism.Cloth(sys.argv[2]).step(10**9, progress=progress)",
    ],
)
def test_ctrl_c_stops_a_long_call(call):
    """Ctrl-C (SIGINT) raises KeyboardInterrupt within moments, not at the call's end."""
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD.replace("CALL", call), str(course_file("CBbunny.dae")),
         str(course_file("sphere.json"))],
        stdout=subprocess.PIPE,
        text=True,
    )
    assert child.stdout.readline().strip() == "started"
    time.sleep(0.3)
    sent = time.perf_counter()
    child.send_signal(2)
    out, _ = child.communicate(timeout=60)
    assert out.strip() == "interrupted"
    assert time.perf_counter() - sent < 10
    assert child.returncode == 0


def test_bad_settings_raise_argument_errors():
    """Bad arguments are ArgumentErrors (ValueErrors) naming the argument."""
    scene = prism.load_scene()
    with pytest.raises(ValueError, match="integrator"):
        scene.render(integrator="bidir")
    with pytest.raises(prism.ArgumentError, match="resolution"):
        scene.render(resolution=(0, 10))
