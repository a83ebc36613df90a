"""Type stubs of prism's native module (re-exported by ``prism``)."""

import os
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union, final

import numpy as np
import numpy.typing as npt

_Path = Union[str, "os.PathLike[str]"]
_Progress = Optional[Callable[[int, int], Any]]
_Vec3 = Tuple[float, float, float]

__version__: str
__all__ = [
    "Cloth",
    "Mesh",
    "Scene",
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
    "svg",
    "trace_pixel",
    "write_image",
]

def svg(
    path_or_text: Union[_Path, str],
    *,
    width: Optional[int] = None,
    height: Optional[int] = None,
    samples: int = 16,
    compat: Optional[str] = None,
    zoom: Optional[float] = None,
    font_dirs: Sequence[_Path] = ...,
    skip_system_fonts: bool = False,
    font_family: Optional[str] = None,
    threads: Optional[int] = None,
) -> npt.NDArray[np.uint8]:
    """Rasterizes an SVG file or text to straight-alpha RGBA, uint8[H, W, 4]."""

@final
class Mesh:
    """A polygon mesh with halfedge edits, Loop subdivision and normals."""

    def __new__(cls, vertices: npt.ArrayLike, faces: Union[npt.ArrayLike, Sequence[Sequence[int]]]) -> "Mesh": ...
    @staticmethod
    def read(path: _Path, *, strict: bool = False) -> "Mesh":
        """Reads an .obj, .ply or .dae mesh, repairing a non-manifold one unless strict."""
    @property
    def vertices(self) -> npt.NDArray[np.float64]:
        """Positions, float64[N, 3]."""
    @property
    def faces(self) -> Union[npt.NDArray[np.int64], List[List[int]]]:
        """int64[F, k] when every face has k corners, else a list of lists."""
    @property
    def edges(self) -> npt.NDArray[np.int64]:
        """The two vertices of each edge, int64[E, 2], numbered as the edits take them."""
    @property
    def vertex_count(self) -> int: ...
    @property
    def face_count(self) -> int: ...
    def normals(self) -> npt.NDArray[np.float64]:
        """Area-weighted vertex normals, float64[N, 3]."""
    def subdivide(self, levels: int = 1, weights: str = "warren", *, progress: _Progress = None) -> "Mesh":
        """A new mesh: Loop subdivision with Warren's ("warren") or Loop's ("loop") weights."""
    def flip(self, edge: Union[int, Tuple[int, int]]) -> None:
        """Flips an edge (its number, or the two vertices it joins) in place."""
    def split(self, edge: Union[int, Tuple[int, int]]) -> int:
        """Splits an edge at its midpoint in place; returns the new vertex."""
    def collapse(self, edge: Union[int, Tuple[int, int]]) -> int:
        """Collapses an edge to its midpoint in place; returns the kept vertex."""
    def write(self, path: _Path) -> None:
        """Writes .obj, .ply (binary) or .dae by the extension."""

def bezier_patch(path: _Path, resolution: int = 8) -> Mesh:
    """Tessellates the course's .bez Bezier patches into a welded triangle mesh."""

@final
class Scene:
    """A scene read and prepared for the path tracer, rendered as often as asked."""

    @property
    def resolution(self) -> Tuple[int, int]: ...
    @property
    def spp(self) -> int: ...
    @property
    def max_bounces(self) -> int: ...
    @property
    def warnings(self) -> List[str]: ...
    def render(
        self,
        *,
        spp: Optional[int] = None,
        resolution: Optional[Tuple[int, int]] = None,
        max_bounces: Optional[int] = None,
        seed: int = 0,
        integrator: str = "path",
        light_samples: int = 1,
        adaptive: Optional[float] = None,
        batch: Optional[int] = None,
        threads: Optional[int] = None,
        progress: _Progress = None,
    ) -> npt.NDArray[np.float32]:
        """Linear radiance, float32[H, W, 3]."""

def load_scene(
    path: Optional[_Path] = None,
    *,
    normals: str = "area",
    camera: str = "course",
    defines: Optional[Mapping[str, str]] = None,
    lenient: bool = False,
    sensor: int = 0,
    envmap: Optional[_Path] = None,
    lens_radius: Optional[float] = None,
    focal_distance: Optional[float] = None,
) -> Scene:
    """Reads a COLLADA, Mitsuba 3, OBJ or Delft scene (None: the built-in Cornell box)."""

def render(
    scene: Union[_Path, Scene],
    *,
    spp: Optional[int] = None,
    resolution: Optional[Tuple[int, int]] = None,
    max_bounces: Optional[int] = None,
    seed: int = 0,
    integrator: str = "path",
    light_samples: int = 1,
    adaptive: Optional[float] = None,
    batch: Optional[int] = None,
    threads: Optional[int] = None,
    progress: _Progress = None,
) -> npt.NDArray[np.float32]:
    """Path-traces a scene to linear radiance, float32[H, W, 3]."""

def raytrace(
    config_or_preset: _Path = ...,  # "cornell-box"
    *,
    resolution: Optional[Tuple[int, int]] = None,
    features: Optional[Union[Mapping[str, bool], Iterable[str]]] = None,
    camera: int = 0,
    spp: Optional[int] = None,
    light_samples: int = 16,
    max_depth: int = 3,
    seed: int = 0,
    bloom_threshold: float = 0.0,
    bloom_passes: int = 1,
    data: Optional[_Path] = None,
    threads: Optional[int] = None,
    progress: _Progress = None,
) -> npt.NDArray[np.float32]:
    """Whitted-ray-traces a Delft preset, OBJ scene or TOML config, float32[H, W, 3]."""

def trace_pixel(
    config_or_preset: _Path,
    x: int,
    y: int,
    *,
    resolution: Optional[Tuple[int, int]] = None,
    features: Optional[Union[Mapping[str, bool], Iterable[str]]] = None,
    camera: int = 0,
    spp: Optional[int] = None,
    light_samples: int = 16,
    max_depth: int = 3,
    seed: int = 0,
    data: Optional[_Path] = None,
) -> Dict[str, Any]:
    """The ray tree of one pixel, as `prism raytrace --debug-pixel` records it."""

def shade(
    mesh_or_path: Union[_Path, Mesh],
    *,
    shader: str = "phong",
    eye: Optional[_Vec3] = None,
    target: Optional[_Vec3] = None,
    up: _Vec3 = ...,  # (0, 1, 0)
    fov_y: float = 45.0,
    resolution: Tuple[int, int] = ...,  # (800, 600)
    samples: int = 1,
    light: Optional[_Vec3] = None,
    light_intensity: Optional[_Vec3] = None,
    background: _Vec3 = ...,  # black
    wireframe: Optional[_Vec3] = None,
    texture: Optional[Union[_Path, npt.NDArray[np.uint8]]] = None,
    height_map: Optional[Union[_Path, npt.NDArray[np.uint8]]] = None,
    cubemap: Optional[_Path] = None,
    data: Optional[_Path] = None,
    threads: Optional[int] = None,
) -> npt.NDArray[np.uint8]:
    """Draws a mesh with one of the course's shaders, uint8[H, W, 3]."""

@final
class Cloth:
    """The course's mass-spring cloth, stepped exactly as its algorithm."""

    def __new__(cls, scene_json_path: _Path, overrides: Optional[Mapping[str, Any]] = None) -> "Cloth": ...
    def step(self, n: int = 1, *, threads: Optional[int] = None, progress: _Progress = None) -> None:
        """Takes n time steps (1/2700 s each)."""
    def frame(self, n: int = 1, *, threads: Optional[int] = None, progress: _Progress = None) -> None:
        """Takes n frames of 30 steps."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """float64[N, 3], a view of the simulation's own buffer."""
    @property
    def triangles(self) -> npt.NDArray[np.int64]:
        """int64[T, 3], two a grid square."""
    @property
    def steps(self) -> int: ...
    @property
    def grid(self) -> Tuple[int, int]: ...
    def kinetic_energy(self) -> float: ...
    def potential_energy(self) -> float: ...

def write_image(path: _Path, image: npt.NDArray[Any]) -> None:
    """Writes .png, .jpg or .exr by the extension."""

def read_image(path: _Path) -> npt.NDArray[Any]:
    """Reads .exr/.hdr as float32[H, W, 3], PNG/JPEG as uint8[H, W, 4]."""

def encode_png(image: npt.NDArray[Any]) -> bytes:
    """PNG bytes of a picture."""

def set_memory_budget(bytes: int) -> None:
    """Sets the memory budget (at least 64 MiB; 2 GiB unless set), as --max-memory."""

def memory_budget() -> int:
    """The memory budget in bytes."""
