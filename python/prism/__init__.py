"""prism: a computer-graphics toolkit on the CPU, from Python.

Every system of the ``prism`` command, with NumPy arrays in and out:

- :func:`svg`: the 2D rasterizer (standard SVG, or the CS184 course's dialect);
- :class:`Mesh` and :func:`bezier_patch`: the halfedge mesh, Loop subdivision, Bezier patches;
- :func:`render` and :func:`load_scene`: the path tracer (COLLADA, Mitsuba 3, OBJ scenes);
- :func:`raytrace` and :func:`trace_pixel`: the Whitted ray tracer and its ray trees;
- :func:`shade`: a mesh drawn with one of the course's shaders;
- :class:`Cloth`: the mass-spring cloth, stepped exactly as the course's algorithm;
- :func:`write_image`, :func:`read_image` and :func:`show`: pictures to files and notebooks.

Long calls release the GIL, take an optional ``progress(done, total)`` callback, and stop
on Ctrl-C with ``KeyboardInterrupt``. Failures raise :class:`Error` subclasses.
"""

from ._errors import ArgumentError, Error, FileError, InputError, LimitError, TopologyError
from ._prism import (
    Cloth,
    Mesh,
    Scene,
    __version__,
    bezier_patch,
    encode_png,
    load_scene,
    memory_budget,
    raytrace,
    read_image,
    render,
    set_memory_budget,
    shade,
    svg,
    trace_pixel,
    write_image,
)


class Picture:
    """A picture shown by Jupyter (through ``_repr_png_``); ``array`` is the NumPy array."""

    def __init__(self, array):
        self.array = array

    def _repr_png_(self) -> bytes:
        return encode_png(self.array)

    def __repr__(self) -> str:
        shape = "x".join(str(n) for n in self.array.shape)
        return f"<prism.Picture {shape} {self.array.dtype}>"


def show(array) -> Picture:
    """Wraps a picture array (``uint8[H, W, 3 or 4]``, or linear ``float32[H, W, 3]``,
    shown sRGB-encoded) so that a notebook cell displays it."""
    return Picture(array)


__all__ = [
    "ArgumentError",
    "Cloth",
    "Error",
    "FileError",
    "InputError",
    "LimitError",
    "Mesh",
    "Picture",
    "Scene",
    "TopologyError",
    "__version__",
    "bezier_patch",
    "encode_png",
    "load_scene",
    "memory_budget",
    "raytrace",
    "read_image",
    "render",
    "set_memory_budget",
    "shade",
    "show",
    "svg",
    "trace_pixel",
    "write_image",
]
