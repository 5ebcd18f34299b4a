"""Builders of scene tables: dicts in the scene file's vocabulary, for ``Scene(...)``.

Each function returns the table a scene file would hold, so ``curves={"c": bspline(pts)}``
is ``[curves.c] bspline = [...]`` and the scene built from Python is the scene its
``to_toml()`` text describes, bit for bit. Arrays stay numpy arrays here; ``Scene`` writes
them (shortest round-trip floats) and names the argument and the index of a value it cannot
take. Keys a builder does not list go through ``**keys`` unchanged, under the scene file's
names (see examples/*.toml).
"""

from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

Number = Union[float, int, str]
"""A number or an expression in the scene's parameters (``"2*r"``)."""

Table = Dict[str, Any]


def _points(points: Any, dim: int, what: str) -> Any:
    """Points (N, dim): a float array, or rows of numbers and expressions as given."""
    try:
        a = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError):
        rows = [list(r) for r in points]
        for i, r in enumerate(rows):
            if len(r) != dim:
                raise ValueError(f"{what}[{i}]: {len(r)} coordinates, not {dim}") from None
        return rows
    if a.ndim != 2 or a.shape[1] != dim:
        raise ValueError(f"{what}: an array of shape (N, {dim}), got {a.shape}")
    return a


def _with(table: Table, **optional: Any) -> Table:
    table.update({k: v for k, v in optional.items() if v is not None})
    return table


# --- curves: [curves.NAME] -------------------------------------------------------------


def bspline(
    points: npt.ArrayLike,
    *,
    degree: Optional[int] = None,
    closed: Optional[bool] = None,
    range: Optional[Tuple[Number, Number]] = None,
) -> Table:
    """A uniform B-spline curve through control points (N, 3): clamped when open, periodic
    when ``closed``; ``degree`` 1…7 (3 unless given), ``range`` its parameter interval
    (``[0, 2π]`` closed, ``[0, 1]`` open, unless given)."""
    return _with({"bspline": _points(points, 3, "bspline points")}, degree=degree, closed=closed, range=range)


def polyline(
    points: npt.ArrayLike, *, closed: Optional[bool] = None, range: Optional[Tuple[Number, Number]] = None
) -> Table:
    """A polyline through vertices (N, 3)."""
    return _with({"polyline": _points(points, 3, "polyline points")}, closed=closed, range=range)


def point(p: Sequence[Number]) -> Table:
    """A constant curve (a pole)."""
    return {"point": list(p)}


def expr(x: Number, y: Number, z: Number) -> Table:
    """A curve of three expressions in ``v`` (and ``t``)."""
    return {"expr": [x, y, z]}


def combine(expression: str) -> Table:
    """A linear combination of named curves, e.g. ``"alpha*(d1 - p2)"``."""
    return {"combine": expression}


def trimline(surface: str, s: Number, *, derivative: Optional[int] = None, scale: Optional[Number] = None) -> Table:
    """The curve ``∂ᵏS/∂sᵏ(s, v)`` (``k = derivative``, 0 unless given) of the primary
    surface ``surface``, times ``scale``ᵏ."""
    return _with({"surface": surface, "s": s}, derivative=derivative, scale=scale)


# --- primary surfaces: [surfaces.NAME] -------------------------------------------------


def surface(
    x: Number,
    y: Number,
    z: Number,
    *,
    s_range: Optional[Tuple[Number, Number]] = None,
    v: Optional[Union[str, Tuple[Number, Number]]] = None,
    resolution: Optional[Tuple[int, int]] = None,
) -> Table:
    """A primary surface S(s, v[, t]) of three expressions; ``s_range`` draws it in
    context, ``v`` is ``"periodic"`` (default) or ``[v0, v1]``."""
    return _with({"expr": [x, y, z]}, s_range=s_range, v=v, resolution=resolution)


# --- patches: [patches.NAME] -----------------------------------------------------------


def _patch(kind: str, keys: Dict[str, Any]) -> Table:
    if "kind" in keys:
        raise TypeError(f"{kind}(): `kind` is given by the builder")
    return {"kind": kind, **keys}


def pde(**keys: Any) -> Table:
    """A PDE surface ``(∂u² + a²∂v²)^N X = 0`` (``conditions``, ``a``, ``modes``,
    ``sections``, ``resolution``, ...)."""
    return _patch("pde", keys)


def hermite(**keys: Any) -> Table:
    """Hermite interpolation in u between conditions (no PDE)."""
    return _patch("hermite", keys)


def blend(**keys: Any) -> Table:
    """A static blend of 2nd, 4th, 6th or mixed order (``orders``, ``coefficients``,
    ``start``/``end`` trimlines, ``solver``, ...)."""
    return _patch("blend", keys)


def dynamic(**keys: Any) -> Table:
    """A time-dependent C1 blend (``time``, ``terms``, ``frames``, ...)."""
    return _patch("dynamic", keys)


def solid(**keys: Any) -> Table:
    """A solid blend between two solids (``lmn``, ``cells``, ...)."""
    return _patch("solid", keys)


def fill(**keys: Any) -> Table:
    """An N-sided fill meeting its neighbours G1 (order 4) or G2 (order 6) (``edges``,
    ``pole``, ``fullness``, ``order``, ...)."""
    return _patch("fill", keys)
