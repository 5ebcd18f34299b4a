"""Scenes built from Python values, their scene text, pickling and pictures.

The references are the example files read by the scene parser (`Scene.load`): a scene built
from Python values must solve to the same arrays bit for bit, since both are meant to be
the same scene text.
"""

import io
import pickle
import tomllib
from pathlib import Path

import numpy as np
import pytest

import pdeshape
from helpers import random_params

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))


def assert_same_scene(a, b, n=200):
    """Every patch of `a` and `b` evaluates to the same bits at n random parameters."""
    assert [p.name for p in a.patches] == [p.name for p in b.patches]
    for k, (p, q) in enumerate(zip(a.patches, b.patches)):
        uv = random_params(p, n, seed=k)
        x, y = p.evaluate(uv), q.evaluate(uv)
        assert x.tobytes() == y.tobytes(), f"{p.name}: max |diff| {np.max(np.abs(x - y))}"


def first_parameter_moved(scene):
    """A setting of the scene's first plain parameter off its value (None: no parameter)."""
    for name, p in scene.parameters.items():
        if p["expr"] is None:
            lo = p["min"] if p["min"] is not None else p["value"] - 0.1
            hi = p["max"] if p["max"] is not None else p["value"] + 0.1
            # a value with a long binary expansion, inside the slider's range
            return {name: lo + (hi - lo) * (1 / 3)}
    return None


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_every_example_built_from_python_values_equals_its_file(path):
    loaded = pdeshape.Scene.load(path)
    with open(path, "rb") as f:
        tables = tomllib.load(f)
    built = pdeshape.Scene(**tables, name=path.stem)
    assert_same_scene(loaded, built)
    # the text written from Python values parses back to the same tables
    assert tomllib.loads(built.to_toml()) == tables


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_to_toml_and_pickle_round_trip_every_example(path):
    scene = pdeshape.Scene.load(path)
    setting = first_parameter_moved(scene)
    if setting is not None:
        scene = scene.set(**setting)
    again = pdeshape.Scene.from_toml(scene.to_toml())
    assert_same_scene(scene, again)
    unpickled = pickle.loads(pickle.dumps(scene))
    assert_same_scene(scene, unpickled)
    assert unpickled.parameters == scene.parameters
    assert unpickled.to_toml() == scene.to_toml()
    patch = pickle.loads(pickle.dumps(scene.patches[-1]))
    assert patch.name == scene.patches[-1].name
    uv = random_params(patch, 50, seed=7)
    assert patch.evaluate(uv).tobytes() == scene.patches[-1].evaluate(uv).tobytes()


def test_a_patch_built_from_numpy_arrays_equals_the_example():
    """Paper 004's eighth-order vase from a (8, 8, 3) array of control rings."""
    with open(ROOT / "examples/order8-patch.toml", "rb") as f:
        t = tomllib.load(f)
    rings = np.array([t["curves"][f"k{i}"]["bspline"] for i in range(8)], dtype=np.float64)
    built = pdeshape.Scene(
        scene=t["scene"],
        parameters={"a": {"value": 0.8, "min": 0.2, "max": 3.0}},
        curves={f"k{i}": pdeshape.bspline(rings[i], closed=True) for i in range(8)},
        patches={
            "vase": pdeshape.pde(
                a="a",
                resolution=(113, 97),
                conditions=[{"u": 0 if i == 0 else 1 if i == 7 else f"{i}/7", "curve": f"k{i}"} for i in range(8)],
            )
        },
        render=t["render"],
    )
    assert_same_scene(pdeshape.Scene.load(ROOT / "examples/order8-patch.toml"), built, n=1000)
    # numpy scalars and arrays of other dtypes are their Python values
    s = pdeshape.Scene(
        parameters={"a": np.float32(0.5), "n": np.int64(3)},
        curves={"c": pdeshape.bspline(rings[0].astype(np.float32), degree=np.int32(3), closed=np.bool_(True))},
    )
    t2 = tomllib.loads(s.to_toml())
    assert t2["parameters"] == {"a": 0.5, "n": 3}
    assert t2["curves"]["c"]["closed"] is True and t2["curves"]["c"]["degree"] == 3
    assert t2["curves"]["c"]["bspline"][1] == [float(np.float32(0.7)), float(np.float32(0.7)), 0.0]


def test_floats_are_written_to_the_same_bits():
    values = {"x": 0.1 + 0.2, "y": 1e300, "z": 5e-324, "q": -0.0, "big": np.finfo(float).max, "tiny": 1e-6}
    s = pdeshape.Scene(parameters=values)
    text = s.to_toml()
    assert "1e300" in text, text  # not 301 digits
    back = tomllib.loads(text)["parameters"]
    for k, v in values.items():
        assert np.float64(back[k]).tobytes() == np.float64(v).tobytes(), k
        assert np.float64(s.parameters[k]["value"]).tobytes() == np.float64(v).tobytes(), k


def test_bad_values_name_the_argument_and_the_index():
    pts = np.zeros((6, 3))
    pts[4, 1] = np.nan
    with pytest.raises(ValueError, match=r"curves\.c\.bspline\[4\]\[1\] = NaN is not finite"):
        pdeshape.Scene(curves={"c": pdeshape.bspline(pts)})
    with pytest.raises(ValueError, match=r"patches\.p\.a = inf is not finite"):
        pdeshape.Scene(patches={"p": pdeshape.pde(a=float("inf"))})
    with pytest.raises(TypeError, match=r"parameters\.a: a NoneType cannot go into a scene"):
        pdeshape.Scene(parameters={"a": None})
    with pytest.raises(TypeError, match=r"patches\.p\.conditions\[1\]: a object cannot go into a scene"):
        pdeshape.Scene(patches={"p": pdeshape.pde(conditions=[{"u": 0}, object()])})
    with pytest.raises(ValueError, match=r"parameters\.a = 1267650600228229401496703205376: an integer beyond 64 bits"):
        pdeshape.Scene(parameters={"a": 2**100})
    with pytest.raises(ValueError, match=r"bspline points\[1\]: 2 coordinates, not 3"):
        pdeshape.bspline([[0, 0, "r"], [1, 0], [2, 0, 0], [3, 0, 0]])
    with pytest.raises(ValueError, match=r"bspline points: an array of shape \(N, 3\), got \(4, 2\)"):
        pdeshape.bspline(np.zeros((4, 2)))
    # what the scene rejects comes with its key, as from a file
    with pytest.raises(pdeshape.SceneError) as e:
        pdeshape.Scene(curves={"c": pdeshape.bspline(np.zeros((6, 3)), degree=9)})
    assert e.value.key == "curves.c.degree", e.value
    with pytest.raises(pdeshape.SceneError, match=r"unknown field `sufaces`"):
        pdeshape.Scene(sufaces={})
    with pytest.raises(TypeError, match="`kind` is given by the builder"):
        pdeshape.pde(kind="blend")


def test_expressions_stay_expressions_in_control_points():
    s = pdeshape.Scene(
        parameters={"r": 2.0},
        curves={"c": pdeshape.bspline([["r", 0, 0], [0, "r", 0], ["-r", 0, 0], [0, "-r", 0]], closed=True)},
    )
    assert tomllib.loads(s.to_toml())["curves"]["c"]["bspline"][0] == ["r", 0, 0]


def png_pixels(data):
    matplotlib_image = pytest.importorskip("matplotlib.image")
    return matplotlib_image.imread(io.BytesIO(data), format="png")


def test_pictures_for_notebooks_show_the_shape():
    scene = pdeshape.Scene.load(ROOT / "examples/klein-bottle.toml")
    for obj in (scene, scene.patches[0], scene.patches[0].mesh(resolution=(41, 33))):
        img = png_pixels(obj._repr_png_())
        assert img.shape[:2] == (600, 800), (obj, img.shape)
        background = img[0, 0, :3]
        drawn = np.any(np.abs(img[:, :, :3] - background) > 0.05, axis=2)
        # the bottle covers a fair part of the picture, and not all of it
        assert 0.05 < drawn.mean() < 0.9, (obj, drawn.mean())
        rows, cols = np.nonzero(drawn)
        assert rows.max() - rows.min() > 200 and cols.max() - cols.min() > 200, obj


def test_meshes_from_arrays_check_them_and_pickle():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    m = pdeshape.Mesh(v, f, fields={"h": v[:, 2]}, name="tet")
    assert m.faces.dtype == np.uint32 and m.vertices.dtype == np.float64
    back = pickle.loads(pickle.dumps(m))
    assert back.name == "tet" and np.array_equal(back.vertices, v) and np.array_equal(back.faces, f)
    assert np.array_equal(back.fields["h"], v[:, 2]) and back.normals is None
    with pytest.raises(ValueError, match=r"faces\[1, 2\] = 4: out of range for 4 vertices"):
        pdeshape.Mesh(v, [[0, 1, 2], [0, 1, 4]])
    bad = v.copy()
    bad[2, 0] = np.inf
    with pytest.raises(ValueError, match=r"vertices\[2, 0\] = inf is not finite"):
        pdeshape.Mesh(bad, f)
    with pytest.raises(ValueError, match=r"normals: 3 rows for 4 vertices"):
        pdeshape.Mesh(v, f, normals=v[:3])
    with pytest.raises(ValueError, match=r"fields\['h'\]: 2 values for 4 vertices"):
        pdeshape.Mesh(v, f, fields={"h": [1.0, 2.0]})


def load_tool(name):
    """A generator script of examples/tools as a module (its numpy arrays)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(name, ROOT / "examples/tools" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_fill_on_a_nurbs_sheet_built_from_numpy_equals_the_example():
    """The rational bicubic sheet (net, knots, weights as numpy arrays) and its G2 fill."""
    tool = load_tool("bspline_hole")
    net, ks, kv, weights = tool.sheet()
    with open(ROOT / "examples/fill-bspline-hole.toml", "rb") as f:
        t = tomllib.load(f)
    built = pdeshape.Scene(
        scene=t["scene"],
        parameters={"fullness": {"value": 1.0, "min": 0.3, "max": 2.0, "description": "cross-tangent length / loop radius"}},
        surfaces={
            "sheet": {
                **pdeshape.bspline(net, knots=(ks, kv), weights=weights),
                "s_range": np.array([0.0, 0.3]),
                "resolution": (33, 33),
            }
        },
        patches={
            "fill": pdeshape.fill(
                order=6, fullness="fullness", a=1.0, modes=12, resolution=(41, 161), edges=tool.arcs(), color=[0.35, 0.6, 0.85]
            )
        },
        render=t["render"],
    )
    loaded = pdeshape.Scene.load(ROOT / "examples/fill-bspline-hole.toml")
    assert_same_scene(loaded, built, n=1000)
    report = built.check()
    fill = report["patches"][0]["fill"]
    # G2 to round-off on NURBS data: exact derivatives through the quotient rule (3.6e-15 rad
    # and 5e-15 relative seen)
    assert fill["g1_max_radians"] < 1e-13 and fill["g2_max_relative"] < 1e-12, fill


def test_a_paper_001_blend_built_with_numpy_values_equals_the_example():
    """The cone-to-cylinder blends of paper 001 with every number a numpy scalar."""
    path = ROOT / "examples/blend-cone-cylinder.toml"
    with open(path, "rb") as f:
        t = tomllib.load(f)
    params = {k: {**v, "value": np.float64(v["value"])} for k, v in t["parameters"].items()}
    surfaces = {
        "cone": pdeshape.surface("R*s*cos(v)", "Rv*s*sin(v)", "h0*s", s_range=("u0", "1.8")),
        "cylinder": pdeshape.surface(
            "x0 + a*cos(alpha)*cos(v) + h1*s*sin(alpha)",
            "b*sin(v)",
            "z0 - a*sin(alpha)*cos(v) + h1*s*cos(alpha)",
            s_range=("u1", "u1 + 1.2"),
        ),
    }
    patches = {}
    for name, p in t["patches"].items():
        keys = {k: v for k, v in p.items() if k != "kind"}
        keys["orders"] = np.array(p["orders"], dtype=np.int64)
        keys["resolution"] = np.array(p["resolution"], dtype=np.int64)
        keys["color"] = np.array(p["color"])
        patches[name] = pdeshape.blend(**keys)
    built = pdeshape.Scene(scene=t["scene"], parameters=params, surfaces=surfaces, patches=patches, render=t["render"])
    assert_same_scene(pdeshape.Scene.load(path), built, n=1000)


def test_the_klein_bottle_with_numpy_section_places_equals_the_example():
    """The Klein bottle with its 40 sections placed at u from a numpy array (the Chebyshev
    points (1 − cos(πi/39))/2 the file's `spacing = "chebyshev"` places them at)."""
    path = ROOT / "examples/klein-bottle.toml"
    with open(path, "rb") as f:
        t = tomllib.load(f)
    u = (1.0 - np.cos(np.pi * np.arange(40) / 39.0)) / 2.0
    sections = {k: v for k, v in t["patches"]["klein"]["sections"].items() if k != "spacing"}
    klein = pdeshape.pde(a="a", modes=np.int64(6), resolution=np.array([161, 65]), sections={**sections, "u": u})
    params = {"alpha": np.float64(6), "beta": np.float64(16), "a": {"value": np.float64(1.0), "min": 0.3, "max": 3.0}}
    built = pdeshape.Scene(scene=t["scene"], parameters=params, patches={"klein": klein}, render=t["render"])
    assert_same_scene(pdeshape.Scene.load(path), built, n=1000)


def klein_section(s, v):
    """The analytic bottle's cross section at s (examples/klein-bottle.toml's expressions)."""
    g = 4.0 * (1.0 - np.cos(s) / 2.0)
    if s <= np.pi:
        return np.stack([6 * np.cos(s) * (1 + np.sin(s)) + g * np.cos(s) * np.cos(v), 16 * np.sin(s) + g * np.sin(s) * np.cos(v), g * np.sin(v)], 1)
    return np.stack([6 * np.cos(s) * (1 + np.sin(s)) + g * np.cos(v + np.pi), 16 * np.sin(s) + 0 * v, g * np.sin(v)], 1)


def test_the_klein_bottle_from_sampled_sections_is_near_the_exact_one():
    """The researcher's case: each section known only as 48 points, interpolated
    (periodic cubic) and placed at numpy u: the PDE surface through the data lies near the
    one through the exact sections, within the sections' own interpolation error times the
    PDE's amplification (measured below)."""
    exact = pdeshape.Scene.load(ROOT / "examples/klein-bottle.toml").patches[0]
    n = 48
    v = 2 * np.pi * np.arange(n) / n
    curves, conds = {}, []
    u = (1.0 - np.cos(np.pi * np.arange(40) / 39.0)) / 2.0
    for i in range(40):
        c = pdeshape.interpolate(klein_section(2 * np.pi * i / 39, v))
        assert c.residual < 1e-13, c.residual
        # the nodes are 2πk/n up to the rounding of the affine map
        assert np.max(np.abs(c.nodes - v)) < 1e-15
        curves[f"c{i}"] = c
        conds.append({"u": u[i], "curve": f"c{i}"})
    built = pdeshape.Scene(parameters={"a": 1.0}, curves=curves, patches={"klein": pdeshape.pde(a="a", modes=6, conditions=conds)})
    p = built.patches[0]
    uv = random_params(exact, 2000, seed=7)
    dist = np.max(np.linalg.norm(p.evaluate(uv) - exact.evaluate(uv), axis=1))
    # on the sections themselves the data are through the samples to round-off
    on = np.column_stack([np.repeat(u, n), np.tile(v, 40)])
    samples = np.concatenate([klein_section(2 * np.pi * i / 39, v) for i in range(40)])
    assert np.max(np.linalg.norm(p.evaluate(on) - samples, axis=1)) < 1e-9
    print(f"Klein bottle from 48 samples a section: max distance {dist:.2e}")
    # cubic interpolation of 48 samples: 4.6e-6 seen on a bottle of size ~20
    assert dist < 2e-5, dist


def test_interpolated_curves_go_through_their_points():
    """Periodic (odd degrees) and open (chord, centripetal, uniform parameters)
    interpolants: the scene's own curve, evaluated by the Rust side at the nodes (the
    patch's edge u = 0), passes through the points to round-off; the residual is the
    solve's."""
    rng = np.random.default_rng(3)
    th = np.sort(rng.random(23)) * 2 * np.pi
    pts = np.column_stack([np.cos(th) * (1 + 0.2 * np.sin(3 * th)), np.sin(th), 0.3 * np.cos(2 * th)])
    cases = [dict(periodic=True, degree=d) for d in (1, 3, 5, 7)]
    cases += [dict(periodic=True, range=(-1.0, 2.5))]
    cases += [dict(periodic=False, parameters=w, degree=d) for w in ("chord", "centripetal", "uniform") for d in (1, 2, 3, 5)]
    for kw in cases:
        c = pdeshape.interpolate(pts, **kw)
        periodic = kw["periodic"]
        lo, hi = kw.get("range", (0.0, 2 * np.pi)) if periodic else (0.0, 1.0)
        v = "periodic" if periodic and "range" not in kw else [lo, hi]
        s = pdeshape.Scene(curves={"c": c}, patches={"p": pdeshape.hermite(v=v, conditions=[{"u": 0, "curve": "c"}, {"u": 1, "point": [0, 0, 5]}])})
        x = s.patches[0].evaluate(np.column_stack([np.zeros(len(pts)), c.nodes]))
        err = np.max(np.linalg.norm(x - pts, axis=1))
        # values ≤ 1.2, well-conditioned solves: a few ulps (≤ 3e-15 seen)
        assert err < 2e-14 and c.residual < 2e-14, (kw, err, c.residual)
        assert c.nodes[0] == lo and np.all(np.diff(c.nodes) > 0)
        if not periodic:
            assert c.nodes[-1] == 1.0 and len(c["knots"]) == len(pts) + min(kw["degree"], len(pts) - 1) + 1
    with pytest.raises(ValueError, match=r"odd degree"):
        pdeshape.interpolate(pts, degree=2)
    with pytest.raises(ValueError, match=r"points\[3\] repeats points\[2\]"):
        pdeshape.interpolate(np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 0, 0]], dtype=float), periodic=False)
    bad = pts.copy()
    bad[5, 2] = np.nan
    with pytest.raises(ValueError, match=r"points\[5\] is not finite"):
        pdeshape.interpolate(bad)
    with pytest.raises(ValueError, match=r"shape \(N, 3\)"):
        pdeshape.interpolate(pts[:, :2])


def test_knots_weights_and_nets_from_numpy_equal_their_text():
    """A rational curve with knots and a net from numpy arrays are the scene text written by
    hand with the same numbers."""
    w = float(np.sqrt(0.5))
    ctrl = np.array([[1, 0, 0], [1, 1, 0], [0, 1, 0], [-1, 1, 0], [-1, 0, 0]], dtype=float)
    knots = np.array([0, 0, 0, 0.5, 0.5, 1, 1, 1])
    weights = np.array([1, w, 1, w, 1])
    net = np.array([[[0, 0, 0], [0, 1, 0.5]], [[1, 0, 0.25], [1, 1, 2]]], dtype=float)
    hermite = pdeshape.hermite(v=[0, 1], conditions=[{"u": 0, "curve": "c"}, {"u": 1, "surface": "n", "s": 0.5}])
    built = pdeshape.Scene(
        curves={"c": pdeshape.bspline(ctrl, knots=knots, weights=weights)},
        surfaces={"n": pdeshape.bspline(net, degree=(1, 1), knots=([0, 0, 1, 1], [0, 0, 1, 1]), weights=[[1, 1], [1, 3]])},
        patches={"p": hermite},
    )
    text = f"""
[curves.c]
bspline = [[1, 0, 0], [1, 1, 0], [0, 1, 0], [-1, 1, 0], [-1, 0, 0]]
knots = [0, 0, 0, 0.5, 0.5, 1, 1, 1]
weights = [1, {w!r}, 1, {w!r}, 1]

[surfaces.n]
bspline = [[[0, 0, 0], [0, 1, 0.5]], [[1, 0, 0.25], [1, 1, 2]]]
degree = [1, 1]
knots = [[0, 0, 1, 1], [0, 0, 1, 1]]
weights = [[1, 1], [1, 3]]

[patches.p]
kind = "hermite"
v = [0, 1]
conditions = [{{ u = 0, curve = "c" }}, {{ u = 1, surface = "n", s = 0.5 }}]
"""
    assert_same_scene(pdeshape.Scene.from_toml(text), built, n=500)
    # the half circle, on the unit circle at u = 0 (a rational quadratic, exact to round-off)
    edge = built.patches[0].evaluate(np.column_stack([np.zeros(101), np.linspace(0, 1, 101)]))
    assert np.max(np.abs(np.linalg.norm(edge, axis=1) - 1)) < 1e-15
    with pytest.raises(ValueError, match=r"net weights: an array of shape \(2, 2\)"):
        pdeshape.bspline(net, weights=[1, 2])
    with pytest.raises(pdeshape.SceneError) as e:
        pdeshape.Scene(curves={"c": pdeshape.bspline(ctrl, degree=2, knots=knots[:-1])})
    assert e.value.key == "curves.c.knots", e.value


def test_a_huge_array_is_refused_by_the_scene_cap_before_it_becomes_text():
    """10⁸ values: refused by their count (2 bytes each at least) at once, naming the
    argument; a smaller cap refuses a smaller array."""
    import time

    big = np.broadcast_to(np.zeros(3), (10**8 // 3, 3))
    t0 = time.perf_counter()
    with pytest.raises(pdeshape.SceneError, match=r"curves\.c\.bspline.*over the `scene` cap of 16 MiB"):
        pdeshape.Scene(curves={"c": pdeshape.bspline(big)})
    # no list of 10⁸ Python floats was made (that takes tens of seconds and gigabytes)
    assert time.perf_counter() - t0 < 5.0
    pts = np.zeros((300_000, 3))
    with pytest.raises(pdeshape.SceneError, match=r"limits=\{'scene': "):
        pdeshape.Scene(curves={"c": pdeshape.bspline(pts)}, limits={"scene": 1})
