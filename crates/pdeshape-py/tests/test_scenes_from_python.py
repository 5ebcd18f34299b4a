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
