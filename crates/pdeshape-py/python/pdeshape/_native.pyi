"""The Rust extension of `pdeshape` (the package re-exports it)."""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

class SceneError(Exception):
    """A scene that cannot be loaded; ``str(e)`` is the CLI's message."""

    file: str
    line: Optional[int]
    column: Optional[int]
    key: str
    message: str

class ModelError(Exception):
    """A model file (STEP or mesh) that cannot be read or whose holes cannot be filled;
    ``str(e)`` names the file, line and entity (or element)."""

def holes(
    path: Union[str, PathLike[str]],
    *,
    replace_faces: Optional[List[int]] = None,
    limits: Optional[Dict[str, int]] = None,
) -> Dict[str, Any]:
    """The holes of a STEP model or a triangle mesh (.obj, .ply, .stl): the dict
    ``pdeshape holes MODEL --json`` prints; ``replace_faces`` (STEP) takes faces out first
    by their ``#id``."""
    ...

@overload
def fill_holes(
    model: Union[str, PathLike[str]],
    out: Union[str, PathLike[str]],
    *,
    order: int = 4,
    holes: Optional[List[int]] = None,
    max_edges: Optional[int] = None,
    relative_tolerance: float = 1e-7,
    replace_faces: Optional[List[int]] = None,
    limits: Optional[Dict[str, int]] = None,
    time_limit: Optional[float] = None,
) -> List[Dict[str, Any]]:
    """Fills the holes of a STEP model or mesh file (order 4: G1, 6: G2) and writes it to
    ``out``; one dict of figures per filled hole."""
    ...

@overload
def fill_holes(
    model: Union[npt.NDArray[Any], Sequence[Sequence[float]]],
    out: Union[npt.NDArray[Any], Sequence[Sequence[int]]],
    *,
    order: int = 4,
    holes: Optional[List[int]] = None,
    max_edges: Optional[int] = None,
    relative_tolerance: float = 1e-7,
    limits: Optional[Dict[str, int]] = None,
    time_limit: Optional[float] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32], List[Dict[str, Any]]]:
    """Fills the holes of a mesh given as arrays (vertices (N, 3), faces (M, 3)); returns
    the vertices and faces with the fills appended, and one dict per filled hole."""
    ...

class Mesh:
    """A triangle mesh as numpy arrays (trimesh, pyvista, libigl take them directly)."""

    name: str
    vertices: npt.NDArray[np.float64]  # (N, 3)
    faces: npt.NDArray[np.uint32]  # (M, 3), counter-clockwise about the normal
    normals: Optional[npt.NDArray[np.float64]]  # (N, 3), unit
    uvs: Optional[npt.NDArray[np.float64]]  # (N, 2), parameters scaled to [0, 1]
    fields: Dict[str, npt.NDArray[np.float64]]  # name -> (N,)
    def __init__(
        self,
        vertices: npt.ArrayLike,
        faces: npt.ArrayLike,
        normals: Optional[npt.ArrayLike] = None,
        uvs: Optional[npt.ArrayLike] = None,
        fields: Optional[Dict[str, npt.ArrayLike]] = None,
        name: str = "mesh",
    ) -> None:
        """A mesh from arrays (copied to float64 / uint32); errors name the array and index."""
    def _repr_png_(self) -> bytes: ...
    def show(self, *, resolution: Optional[Tuple[int, int]] = None, width: int = 800, height: int = 600) -> Any:
        """An interactive 3D view in Jupyter (a pythreejs widget)."""

class Patch:
    """One solved patch of a scene."""

    @property
    def name(self) -> str: ...
    @property
    def kind(self) -> str:
        """'hermite', 'pde', 'blend', 'dynamic' or 'solid'."""
    @property
    def resolution(self) -> Tuple[int, int]: ...
    @property
    def v_domain(self) -> Tuple[float, float, bool]:
        """(start, end, periodic)."""
    @property
    def times(self) -> Optional[Tuple[float, float]]:
        """A dynamic blend's time range, else None."""
    def evaluate(self, uv: npt.NDArray[np.float64], t: Optional[float] = None) -> npt.NDArray[np.float64]:
        """Exact points (N, 3) at parameters (N, 2) — (N, 3) of (u, v, w) for a solid.

        Equal bit for bit to ``pdeshape sample``. ``t`` selects a dynamic blend's frame.
        """
    def derivatives(
        self, uv: npt.NDArray[np.float64], du: int = 1, dv: int = 1, t: Optional[float] = None
    ) -> npt.NDArray[np.float64]:
        """Exact partials (N, du+1, dv+1, 3); ``[k, i, j]`` is d^(i+j)X/du^i dv^j at uv[k]."""
    def mesh(self, resolution: Optional[Tuple[int, int]] = None, t: Optional[float] = None) -> Mesh:
        """The patch's mesh as the exporters write it."""
    def _repr_png_(self) -> bytes: ...
    def show(self, *, resolution: Optional[Tuple[int, int]] = None, width: int = 800, height: int = 600) -> Any:
        """An interactive 3D view in Jupyter (a pythreejs widget)."""

class Scene:
    """A loaded, solved scene (immutable: ``set`` returns a new one)."""

    def __init__(
        self,
        *,
        name: str = "scene",
        solver: Optional[str] = None,
        terms: Optional[int] = None,
        limits: Optional[Dict[str, int]] = None,
        time_limit: Optional[float] = None,
        **tables: Any,
    ) -> None:
        """A scene from Python values in the scene file's vocabulary: each keyword is a
        top-level table (scene, parameters, curves, surfaces, patches, render, output,
        studies); ``Scene(**tomllib.load(f))`` is the scene of file ``f``."""
    def to_toml(self) -> str:
        """The scene text solved, with ``set``'s values written in."""
    def __reduce__(self) -> Tuple[Any, Tuple[Dict[str, Any]]]:
        """Pickling: ``(restore, (state,))``, the state a dict of the text and options."""
    def _repr_png_(self) -> bytes: ...
    def show(self, *, resolution: Optional[Tuple[int, int]] = None, width: int = 800, height: int = 600) -> Any:
        """An interactive 3D view in Jupyter (a pythreejs widget)."""

    @staticmethod
    def load(
        path: Union[str, PathLike[str]],
        *,
        solver: Optional[str] = None,
        terms: Optional[int] = None,
        limits: Optional[Dict[str, int]] = None,
        time_limit: Optional[float] = None,
        **params: float,
    ) -> Scene:
        """Loads and solves a scene file; `limits` sets caps as the CLI's `--limit` does
        (order, modes, collocation, vertices, memory and scene in MiB); the memory cap also
        bounds the arrays that `evaluate` and `derivatives` return (MemoryError).
        `time_limit` (seconds, default 600, 0: none) bounds the solve and every mesh
        (TimeoutError)."""
    @staticmethod
    def from_toml(
        text: str,
        name: str = "scene",
        *,
        solver: Optional[str] = None,
        terms: Optional[int] = None,
        limits: Optional[Dict[str, int]] = None,
        time_limit: Optional[float] = None,
        **params: float,
    ) -> Scene:
        """Parses and solves scene text, held to the `scene` cap (16 MiB by default)."""
    def set(self, **values: float) -> Scene:
        """A new scene with parameters changed, solved again."""
    @property
    def parameters(self) -> Dict[str, Dict[str, Any]]:
        """name -> {value, min, max, step, expr, description}, in file order."""
    @property
    def patches(self) -> List[Patch]: ...
    @property
    def file(self) -> str: ...
    @property
    def title(self) -> Optional[str]: ...
    def patch(self, name: str) -> Patch: ...
    def __getitem__(self, name: str) -> Patch: ...
    def __len__(self) -> int: ...
    def check(self) -> Dict[str, Any]:
        """The report ``pdeshape check --json`` prints."""
    def export(self, path: Union[str, PathLike[str]], format: Optional[str] = None) -> None:
        """Writes every patch's mesh (obj, ply, stl, gltf, glb, vtu, ...) or a png picture."""

def _scene_from_state(state: Dict[str, Any]) -> Scene: ...
def _patch_from_state(state: Dict[str, Any], index: int) -> Patch: ...
