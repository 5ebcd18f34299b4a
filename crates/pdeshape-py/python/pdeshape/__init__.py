"""PDE-based shape design: exact PDE surfaces, blends, fills and solids from numpy.

Load a scene file (the TOML the ``pdeshape`` CLI reads) or build one from Python values in
the same vocabulary, change its parameters, evaluate its solved patches exactly at numpy
arrays of parameters, mesh them, and run parameter sweeps in process, on a
``concurrent.futures`` executor or on a Dask cluster::

    import numpy as np, pdeshape
    scene = pdeshape.Scene.load("examples/klein-bottle.toml").set(a=1.37)
    klein = scene.patches[0]
    points = klein.evaluate(np.array([[0.5, 0.0], [0.25, 1.0]]))   # (2, 3) float64
    mesh = klein.mesh()           # mesh.vertices, mesh.faces, mesh.normals, mesh.uvs
    report = scene.check()        # the dict `pdeshape check --json` prints
    table = pdeshape.sweep(scene, {"a": np.linspace(0.5, 2.0, 16)})

Errors in scene files raise ``pdeshape.SceneError`` with the file, line and column.
"""

from ._native import (
    Mesh,
    ModelError,
    Patch,
    Scene,
    SceneError,
    __version__,
    fill_holes,
    holes,
)
from .sweep import sweep
from .tables import (
    blend,
    bspline,
    combine,
    dynamic,
    expr,
    Interpolated,
    fill,
    hermite,
    interpolate,
    pde,
    point,
    polyline,
    solid,
    surface,
    trimline,
)

__all__ = [
    "Interpolated",
    "Mesh",
    "ModelError",
    "Patch",
    "Scene",
    "SceneError",
    "__version__",
    "blend",
    "bspline",
    "combine",
    "dynamic",
    "expr",
    "fill",
    "fill_holes",
    "hermite",
    "holes",
    "interpolate",
    "pde",
    "point",
    "polyline",
    "solid",
    "surface",
    "sweep",
    "trimline",
]
