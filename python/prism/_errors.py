"""prism's exceptions: one base class, one subclass per kind of failure."""

from typing import Optional


class Error(Exception):
    """Anything prism refuses. ``file`` and ``line`` say where in an input, when known."""

    def __init__(self, message: str, file: Optional[str] = None, line: Optional[int] = None):
        super().__init__(message)
        self.file = file
        self.line = line


class InputError(Error):
    """A malformed or unsupported input: a bad SVG, mesh, scene, config or JSON file."""


class FileError(Error, OSError):
    """A file that cannot be read or written (missing, a folder, no permission)."""


class LimitError(Error):
    """A request over a limit: a file too large, a picture over the memory budget."""


class TopologyError(Error):
    """A mesh edit the mesh refuses (a boundary edge to flip, a collapse that would fold)."""


class ArgumentError(Error, ValueError):
    """A bad argument to a prism function."""
