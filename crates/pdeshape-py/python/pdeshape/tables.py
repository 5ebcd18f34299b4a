"""Builders of scene tables: dicts in the scene file's vocabulary, for ``Scene(...)``.

Each function returns the table a scene file would hold, so ``curves={"c": bspline(pts)}``
is ``[curves.c] bspline = [...]`` and the scene built from Python is the scene its
``to_toml()`` text describes, bit for bit. Arrays stay numpy arrays here; ``Scene`` writes
them (shortest round-trip floats) and names the argument and the index of a value it cannot
take. Keys a builder does not list go through ``**keys`` unchanged, under the scene file's
names (see examples/*.toml).
"""

import builtins
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
    degree: Optional[Union[int, Tuple[int, int]]] = None,
    closed: Optional[bool] = None,
    range: Optional[Tuple[Number, Number]] = None,
    knots: Optional[Any] = None,
    weights: Optional[npt.ArrayLike] = None,
) -> Table:
    """A B-spline: a curve from control points (N, 3), a surface from a net (Nu, Nv, 3).

    Curve (``[curves.NAME]``): uniform, clamped when open and periodic when ``closed``;
    ``degree`` 1…7 (3 unless given), ``range`` its parameter interval (``[0, 2π]`` closed,
    ``[0, 1]`` open). An open curve takes its whole knot vector (``knots``, N + degree + 1
    non-decreasing values: the knot is then the curve's parameter and the degree what the
    knots imply unless given) and ``weights`` (N positive values: a rational curve).

    Surface (``[surfaces.NAME]``, a primary surface ``S(s, v)``): the net's rows run along
    ``s``; ``degree=(ps, pv)``, ``knots=(ks, kv)`` whole knot vectors (default clamped
    uniform on ``[0, 1]²``), ``weights`` (Nu, Nv).
    """
    a = _net(points)
    if a is not None:
        if a.shape[2] != 3 or a.shape[0] < 2 or a.shape[1] < 2:
            raise ValueError(f"bspline net: an array of shape (Nu ≥ 2, Nv ≥ 2, 3), got {a.shape}")
        if closed is not None or range is not None:
            raise TypeError("bspline net: `closed` and `range` are for curves (a net's domain is its knot range)")
        net: Table = {"bspline": a}
        if knots is not None:
            ks, kv = knots
            net["knots"] = [np.asarray(ks, dtype=np.float64), np.asarray(kv, dtype=np.float64)]
        if weights is not None:
            w = np.asarray(weights, dtype=np.float64)
            if w.shape != a.shape[:2]:
                raise ValueError(f"bspline net weights: an array of shape {a.shape[:2]}, got {w.shape}")
            net["weights"] = w
        return _with(net, degree=list(degree) if isinstance(degree, (tuple, list)) else degree)
    table = _with({"bspline": _points(points, 3, "bspline points")}, degree=degree, closed=closed, range=range)
    if knots is not None:
        table["knots"] = np.asarray(knots, dtype=np.float64)
    if weights is not None:
        table["weights"] = np.asarray(weights, dtype=np.float64)
    return table


def _net(x: Any) -> "Optional[npt.NDArray[np.float64]]":
    """``x`` as a float array when it is three-dimensional (a net), else None (curves' rows
    may hold expression strings)."""
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        return None
    return a if a.ndim == 3 else None


class Interpolated(Dict[str, Any]):
    """The table of a B-spline curve through given points (``interpolate``), with
    ``nodes`` (the curve's parameter at each point) and ``residual`` (the largest distance
    between a point and the curve's value at its node, in the solve's arithmetic)."""

    nodes: "npt.NDArray[np.float64]"
    residual: float


def _cardinal(p: int, t: float) -> float:
    """The uniform B-spline of degree ``p`` on the knots 0 … p + 1 at ``t`` (the
    recurrence ``b_p(t) = (t b_{p−1}(t) + (p + 1 − t) b_{p−1}(t − 1))/p``)."""
    if p == 0:
        return 1.0 if 0.0 <= t < 1.0 else 0.0
    return (t * _cardinal(p - 1, t) + (p + 1 - t) * _cardinal(p - 1, t - 1.0)) / p


def _basis(knots: "npt.NDArray[np.float64]", p: int, x: float) -> "npt.NDArray[np.float64]":
    """All ``N_{i,p}(x)`` on a clamped knot vector (Cox–de Boor, The NURBS Book A2.2; the
    last span taken at the right end)."""
    n = len(knots) - p - 1
    span = int(np.searchsorted(knots, x, side="right")) - 1
    span = min(max(span, p), n - 1)
    out = np.zeros(n)
    left = np.zeros(p + 1)
    right = np.zeros(p + 1)
    b = np.zeros(p + 1)
    b[0] = 1.0
    for j in range(1, p + 1):
        left[j] = x - knots[span + 1 - j]
        right[j] = knots[span + j] - x
        saved = 0.0
        for r in range(j):
            tmp = b[r] / (right[r + 1] + left[j - r])
            b[r] = saved + right[r + 1] * tmp
            saved = left[j - r] * tmp
        b[j] = saved
    out[span - p : span + 1] = b
    return out


def interpolate(
    points: npt.ArrayLike,
    *,
    periodic: bool = True,
    degree: int = 3,
    range: Optional[Tuple[float, float]] = None,
    parameters: str = "chord",
) -> Interpolated:
    """A B-spline curve through the points (N, 3), as the table ``bspline`` returns.

    Periodic (default): a closed uniform B-spline of odd ``degree`` (1, 3, 5, 7) with one
    control point per point, through point ``k`` at ``v = v₀ + (v₁ − v₀) k/N`` (``range``
    ``[v₀, v₁]``, default ``[0, 2π]``); the circulant system is solved by FFT. Open: a
    clamped B-spline with the knots averaged from the points' ``parameters``
    (``"chord"`` lengths, ``"centripetal"`` or ``"uniform"`` on ``[0, 1]``, The NURBS Book
    §9.2.1), a dense solve (fine for a few thousand points).

    Returns the table with ``.nodes`` and ``.residual`` (see :class:`Interpolated`).
    """
    q = np.asarray(points, dtype=np.float64)
    if q.ndim != 2 or q.shape[1] != 3:
        raise ValueError(f"interpolate points: an array of shape (N, 3), got {q.shape}")
    if not np.isfinite(q).all():
        i = int(np.argwhere(~np.isfinite(q))[0][0])
        raise ValueError(f"interpolate points[{i}] is not finite")
    n = len(q)
    if not (isinstance(degree, (int, np.integer)) and 1 <= degree <= 7):
        raise ValueError(f"interpolate degree: 1 … 7, got {degree}")
    p = int(degree)
    if periodic:
        if p % 2 == 0:
            raise ValueError(f"interpolate degree {p}: a periodic interpolant needs an odd degree (1, 3, 5, 7)")
        if n < max(p + 1, 3):
            raise ValueError(f"interpolate points: {n} points, a closed curve of degree {p} needs {max(p + 1, 3)}")
        a0, a1 = (0.0, 2.0 * np.pi) if range is None else (float(range[0]), float(range[1]))
        # point k = Σₘ wₘ P_{k+m}, wₘ = b_p(p − m): a cross-correlation, diagonal in Fourier
        w = np.array([_cardinal(p, float(p - m)) for m in builtins.range(p + 1)])
        first = np.zeros(n)
        first[: p + 1] = w
        ctrl = np.fft.ifft(np.fft.fft(q, axis=0) / np.conj(np.fft.fft(first))[:, None], axis=0).real
        back = sum(w[m] * np.roll(ctrl, -m, axis=0) for m in builtins.range(p + 1))
        given = None if range is None else (a0, a1)
        table = Interpolated(bspline(ctrl, degree=p, closed=True, range=given))
        table.nodes = a0 + (a1 - a0) * (np.arange(n) / n)
    else:
        if range is not None:
            raise TypeError("interpolate: an open interpolant's parameter is its knots ([0, 1]); `range` is for periodic ones")
        if n < 2:
            raise ValueError(f"interpolate points: {n} points, an open curve needs 2")
        p = min(p, n - 1)
        step = np.linalg.norm(np.diff(q, axis=0), axis=1)
        if parameters == "chord":
            d = step
        elif parameters == "centripetal":
            d = np.sqrt(step)
        elif parameters == "uniform":
            d = np.ones(n - 1)
        else:
            raise ValueError(f"interpolate parameters: 'chord', 'centripetal' or 'uniform', got {parameters!r}")
        if not (d > 0).all():
            i = int(np.argwhere(~(d > 0))[0][0])
            raise ValueError(f"interpolate points[{i + 1}] repeats points[{i}]")
        t = np.concatenate([[0.0], np.cumsum(d)]) / d.sum()
        t[-1] = 1.0
        inner = [t[j : j + p].sum() / p for j in builtins.range(1, n - p)]
        knots = np.concatenate([np.zeros(p + 1), inner, np.ones(p + 1)])
        m = np.array([_basis(knots, p, float(x)) for x in t])
        ctrl = np.linalg.solve(m, q)
        back = m @ ctrl
        table = Interpolated(bspline(ctrl, degree=p, knots=knots))
        table.nodes = t
    table.residual = float(np.max(np.linalg.norm(back - q, axis=1)))
    return table


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
