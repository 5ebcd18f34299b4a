"""Parameter sweeps: one scene solved at many settings, in process or on an executor.

A setting is a dict of parameter values. Each worker receives the scene's state (its text
and load options, a few kilobytes), solves the scene once per setting and returns that
setting's figures; so a sweep runs the same on a ``concurrent.futures`` executor, a Dask
``distributed.Client`` or Ray's executor, and its table equals the serial one (solves are
deterministic and independent of the thread count).
"""

import importlib
import itertools
import math
import os
import sys
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union, cast

import numpy as np

from . import _native

Setting = Dict[str, float]
Measure = Callable[["_native.Scene"], Mapping[str, Any]]


def report_figures(scene: "_native.Scene") -> Dict[str, Any]:
    """The default measure: every number of ``scene.check()`` per patch, flattened to
    columns ``PATCH.KEY.SUBKEY`` (lists and strings left out)."""
    out: Dict[str, Any] = {}

    def walk(prefix: str, v: Any) -> None:
        if isinstance(v, dict):
            for k, x in v.items():
                walk(f"{prefix}.{k}", x)
        elif isinstance(v, bool) or isinstance(v, (int, float)):
            out[prefix] = v

    for p in scene.check()["patches"]:
        walk(p["name"], {k: x for k, x in p.items() if k != "name"})
    return out


def settings_of(values: Union[Mapping[str, Iterable[float]], Sequence[Mapping[str, float]]]) -> List[Setting]:
    """The settings of a sweep: a dict of value lists is their Cartesian product (in the
    dict's key order, the last key varying fastest); a list of dicts is taken as it is."""
    if isinstance(values, Mapping):
        names = list(values)
        grids = [[float(x) for x in np.asarray(values[n], dtype=np.float64).ravel()] for n in names]
        return [dict(zip(names, combo)) for combo in itertools.product(*grids)]
    return [{str(k): float(x) for k, x in s.items()} for s in values]


def _state(scene: "_native.Scene") -> Dict[str, Any]:
    _, (state,) = scene.__reduce__()
    return dict(state)


def _run_chunk(
    state: Dict[str, Any],
    first: int,
    settings: List[Setting],
    measure: Optional[Measure],
    mesh_dir: Optional[str],
    mesh_resolution: Optional[Tuple[int, int]] = None,
) -> List[Dict[str, Any]]:
    """Solves the scene at each setting of one chunk (this runs on the worker)."""
    measure = measure or report_figures
    rows = []
    for k, setting in enumerate(settings):
        params = dict(state["params"])
        params.update(setting)
        try:
            scene = _native._scene_from_state(dict(state, params=params))
        except _native.SceneError as e:
            raise _native.SceneError(f"sweep setting {first + k} {setting}: {e}") from e
        row: Dict[str, Any] = dict(measure(scene))
        if mesh_dir is not None:
            path = os.path.join(mesh_dir, f"{first + k:06d}.npz")
            row["mesh_file"] = _write_meshes(scene, path, mesh_resolution)
        rows.append(row)
    return rows


def _write_meshes(scene: "_native.Scene", path: str, resolution: Optional[Tuple[int, int]] = None) -> str:
    """Every patch's mesh as arrays ``PATCH/vertices``, ``PATCH/faces`` (and normals, uvs)
    of one npz file, written atomically."""
    arrays: Dict[str, np.ndarray] = {}
    for patch in scene.patches:
        m = patch.mesh(resolution=resolution)
        arrays[f"{patch.name}/vertices"] = m.vertices
        arrays[f"{patch.name}/faces"] = m.faces
        if m.normals is not None:
            arrays[f"{patch.name}/normals"] = m.normals
        if m.uvs is not None:
            arrays[f"{patch.name}/uvs"] = m.uvs
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "wb") as f:
        # (numpy's stubs read a key of **arrays as its allow_pickle flag)
        cast(Any, np.savez)(f, **arrays)
    os.replace(tmp, path)
    return path


def _progress(show: Union[bool, Callable[[int, int], None], None], total: int) -> Callable[[int], None]:
    if callable(show):
        report = show
        return lambda done: report(done, total)
    if show is None:
        show = sys.stderr.isatty()
    if not show:
        return lambda done: None

    def bar(done: int) -> None:
        end = "\n" if done == total else ""
        print(f"\rsweep: {done}/{total} settings", end=end, file=sys.stderr, flush=True)

    return bar


def sweep(
    scene: "_native.Scene",
    values: Union[Mapping[str, Iterable[float]], Sequence[Mapping[str, float]]],
    *,
    measure: Optional[Measure] = None,
    executor: Any = None,
    meshes: Optional[Union[str, "os.PathLike[str]"]] = None,
    mesh_resolution: Optional[Tuple[int, int]] = None,
    chunksize: Optional[int] = None,
    progress: Union[bool, Callable[[int, int], None], None] = None,
    table: str = "pandas",
) -> Any:
    """Solves ``scene`` at every setting of ``values`` and tables the figures.

    - ``values``: ``{"a": [...], "k": [...]}`` (their Cartesian product) or a list of
      settings ``[{"a": 1.0, "k": 2.0}, ...]``.
    - ``measure(scene) -> dict``: the figures of one solved setting (default: every number
      of ``scene.check()``, as ``PATCH.KEY`` columns). On an executor it must pickle (a
      module-level function).
    - ``executor``: ``None`` (this process), a ``concurrent.futures`` executor, a Dask
      ``distributed.Client``, or anything with ``submit(fn, *args)`` returning futures
      with ``result()``. Settings go in chunks of ``chunksize`` (about 32 chunks unless
      given).
    - ``meshes``: a directory; each setting's meshes go to ``NNNNNN.npz`` there (arrays
      ``PATCH/vertices``, ``PATCH/faces``, ``PATCH/normals``, ``PATCH/uvs``) and the
      table gets a ``mesh_file`` column. Workers write the files: on a cluster the
      directory must be one they share. ``mesh_resolution=(nu, nv)`` meshes every patch
      at that resolution instead of its own.
    - ``progress``: ``True`` prints a counter on stderr (default: when stderr is a
      terminal), or a callable ``(done, total)``.
    - ``table``: ``"pandas"`` (a DataFrame), ``"pyarrow"`` (a Table) or ``"dict"`` (column
      name → list). Rows are in the order of the settings; parameters come first.

    A setting whose scene fails to solve raises its ``SceneError`` (naming the setting).
    """
    if table not in ("pandas", "pyarrow", "dict"):
        raise ValueError(f"table = {table!r}: 'pandas', 'pyarrow' or 'dict'")
    settings = settings_of(values)
    known = scene.parameters
    for i, s in enumerate(settings):
        for name, x in s.items():
            if name not in known:
                raise KeyError(f"settings[{i}]: no parameter `{name}` (parameters: {', '.join(known) or 'none'})")
            if not math.isfinite(x):
                raise ValueError(f"settings[{i}]: {name} = {x} is not finite")
    mesh_dir = None
    if mesh_resolution is not None:
        if meshes is None:
            raise TypeError("sweep(): `mesh_resolution` is for the meshes written with `meshes=DIR`")
        nu, nv = mesh_resolution
        mesh_resolution = (int(nu), int(nv))
    if meshes is not None:
        mesh_dir = os.fspath(meshes)
        os.makedirs(mesh_dir, exist_ok=True)
    n = len(settings)
    size = chunksize if chunksize is not None else max(1, math.ceil(n / 32))
    if size < 1:
        raise ValueError(f"chunksize = {size}: 1 or more")
    state = _state(scene)
    starts = list(range(0, n, size))
    tick = _progress(progress, n)
    rows: List[Dict[str, Any]] = []
    if executor is None:
        for first in starts:
            rows.extend(_run_chunk(state, first, settings[first : first + size], measure, mesh_dir, mesh_resolution))
            tick(len(rows))
    else:
        futures = [
            executor.submit(_run_chunk, state, first, settings[first : first + size], measure, mesh_dir, mesh_resolution)
            for first in starts
        ]
        for f in futures:
            rows.extend(f.result())
            tick(len(rows))
    return _table(settings, rows, table)


def _table(settings: List[Setting], rows: List[Dict[str, Any]], kind: str) -> Any:
    names: Dict[str, None] = {}
    for s in settings:
        names.update(dict.fromkeys(s))
    for r in rows:
        names.update(dict.fromkeys(k for k in r if k not in names))
    columns: Dict[str, List[Any]] = {k: [] for k in names}
    for s, r in zip(settings, rows):
        for k in names:
            columns[k].append(s[k] if k in s else r.get(k))
    if kind == "dict":
        return columns
    if kind == "pyarrow":
        # an optional dependency
        return importlib.import_module("pyarrow").table(columns)
    try:
        pandas = importlib.import_module("pandas")
    except ImportError as e:
        raise ImportError("sweep(table='pandas') needs pandas (pip install pandas), or pass table='dict'") from e
    return pandas.DataFrame(columns)
