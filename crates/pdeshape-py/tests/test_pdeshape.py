"""The Python module against the CLI, closed forms and itself (run by .ci/run in a venv).

The CLI binary is found at $PDESHAPE_BIN, else target/release/pdeshape or
target/debug/pdeshape (built by `cargo test`); a missing binary fails the tests that need it.
"""

import json
import math
import os
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import pdeshape
from helpers import random_params

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))


def cli():
    env = os.environ.get("PDESHAPE_BIN")
    candidates = [Path(env)] if env else [ROOT / "target/release/pdeshape", ROOT / "target/debug/pdeshape"]
    for c in candidates:
        if c.is_file():
            return str(c)
    pytest.fail(f"no pdeshape binary at {candidates}: run `cargo build` first or set PDESHAPE_BIN")


def test_examples_exist():
    assert len(EXAMPLES) >= 20, EXAMPLES


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_every_example_loads_and_meshes(path):
    scene = pdeshape.Scene.load(path)
    assert len(scene) == len(scene.patches) > 0
    for patch in scene.patches:
        mesh = patch.mesh()
        v, f = mesh.vertices, mesh.faces
        assert v.dtype == np.float64 and v.ndim == 2 and v.shape[1] == 3 and v.shape[0] > 0
        assert f.dtype == np.uint32 and f.ndim == 2 and f.shape[1] == 3 and f.shape[0] > 0
        assert np.isfinite(v).all()
        assert int(f.max()) < v.shape[0]
        if mesh.normals is not None:
            assert mesh.normals.shape == v.shape and mesh.normals.dtype == np.float64
            # unit normals to round-off (normalised in f64)
            assert np.abs(np.linalg.norm(mesh.normals, axis=1) - 1).max() < 1e-12
        if mesh.uvs is not None:
            assert mesh.uvs.shape == (v.shape[0], 2) and mesh.uvs.dtype == np.float64
        for name, values in mesh.fields.items():
            assert values.shape == (v.shape[0],), name


@pytest.mark.parametrize(
    "name, time",
    [("klein-bottle", None), ("bloor-wilson-blend", None), ("dynamic-sine", 0.35), ("solid-cylinders", None),
     ("trim-circle", None), ("blend-cone-cylinder", None)],
)
def test_evaluate_equals_the_cli_sample_bit_for_bit(name, time):
    path = ROOT / "examples" / f"{name}.toml"
    scene = pdeshape.Scene.load(path)
    patch = scene.patches[0]
    uv = random_params(patch, 200, seed=7)
    got = patch.evaluate(uv, t=time)
    assert got.shape == (200, 3) and got.dtype == np.float64
    cmd = [cli(), "sample", str(path), "--patch", patch.name]
    if time is not None:
        cmd += ["--time", repr(time)]
    text = "\n".join(",".join(repr(float(x)) for x in row) for row in uv)
    out = subprocess.run(cmd, input=text, capture_output=True, text=True, check=True).stdout.splitlines()
    want = np.array([[float(x) for x in line.split(",")[-3:]] for line in out[1:]])
    # %.17e round-trips every f64: equality is bit for bit
    assert want.shape == got.shape
    assert np.array_equal(got, want), np.abs(got - want).max()


def klein_section(s, v, alpha=6.0, beta=16.0):
    """The analytic Klein-bottle section the example interpolates (its `expr`)."""
    g = 4 * (1 - math.cos(s) / 2)
    if math.pi - s > 0:
        x = alpha * math.cos(s) * (1 + math.sin(s)) + g * math.cos(s) * math.cos(v)
        y = beta * math.sin(s) + g * math.sin(s) * math.cos(v)
    else:
        x = alpha * math.cos(s) * (1 + math.sin(s)) + g * math.cos(v + math.pi)
        y = beta * math.sin(s)
    return np.array([x, y, g * math.sin(v)])


def klein_section_dv(s, v):
    """Its v-derivative, by hand."""
    g = 4 * (1 - math.cos(s) / 2)
    if math.pi - s > 0:
        return np.array([-g * math.cos(s) * math.sin(v), -g * math.sin(s) * math.sin(v), g * math.cos(v)])
    return np.array([-g * math.sin(v + math.pi), 0.0, g * math.cos(v)])


def test_klein_slider_sweep_meets_the_analytic_sections():
    base = pdeshape.Scene.load(ROOT / "examples/klein-bottle.toml")
    a_range = base.parameters["a"]
    assert (a_range["min"], a_range["max"]) == (0.3, 3.0)
    v = np.linspace(0, 2 * math.pi, 37)
    for a in np.linspace(a_range["min"], a_range["max"], 5):
        patch = base.set(a=float(a)).patches[0]
        for i in (0, 7, 20, 33, 39):
            u = (1 - math.cos(math.pi * i / 39)) / 2  # Chebyshev-spaced section i
            s = 2 * math.pi * i / 39
            got = patch.evaluate(np.column_stack([np.full_like(v, u), v]))
            want = np.array([klein_section(s, vv) for vv in v])
            # the interpolation conditions hold to round-off of coordinates of size ~20
            assert np.abs(got - want).max() <= 1e-10 * np.abs(want).max(), (a, i)
            # and so do their exact v-derivatives (the sections' derivative by hand)
            d = patch.derivatives(np.column_stack([np.full_like(v, u), v]), du=0, dv=1)
            assert d.shape == (len(v), 1, 2, 3)
            dv = np.array([klein_section_dv(s, vv) for vv in v])
            assert np.abs(d[:, 0, 1, :] - dv).max() <= 1e-10 * np.abs(dv).max(), (a, i)
            assert np.array_equal(d[:, 0, 0, :], got) or np.abs(d[:, 0, 0, :] - got).max() < 1e-12


def test_set_returns_a_new_scene_and_leaves_the_old_one():
    s1 = pdeshape.Scene.load(ROOT / "examples/klein-bottle.toml")
    s2 = s1.set(a=2.0)
    assert s1.parameters["a"]["value"] == 1.0 and s2.parameters["a"]["value"] == 2.0
    uv = np.array([[0.3, 1.0]])
    assert not np.array_equal(s1.patches[0].evaluate(uv), s2.patches[0].evaluate(uv))


def test_check_is_the_cli_report():
    path = ROOT / "examples/bloor-wilson-blend.toml"
    got = pdeshape.Scene.load(path).check()
    want = json.loads(subprocess.run([cli(), "check", "--json", str(path)], capture_output=True, text=True, check=True).stdout)
    assert got == want


def test_export_writes_what_build_writes(tmp_path):
    path = ROOT / "examples/hermite-ruled.toml"
    ours = tmp_path / "ours.ply"
    pdeshape.Scene.load(path).export(ours)
    theirs = tmp_path / "theirs.ply"
    subprocess.run([cli(), "build", "-q", str(path), "-o", str(theirs)], check=True)
    assert ours.read_bytes() == theirs.read_bytes()
    with pytest.raises(ValueError, match="unknown format"):
        pdeshape.Scene.load(path).export(tmp_path / "x.nope")
    assert not (tmp_path / "x.nope").exists()


def test_export_writes_into_a_fifo_without_replacing_it(tmp_path):
    """An existing FIFO is written into (its reader gets the file) and stays a FIFO; the
    atomic rename used to put a regular file in its place."""
    import stat
    import threading

    fifo = tmp_path / "pipe.obj"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()))
    reader.start()
    pdeshape.Scene.load(ROOT / "examples/hermite-ruled.toml").export(fifo)
    reader.join(timeout=60)
    assert not reader.is_alive()
    assert got and got[0].startswith(b"# ") and b"\nv " in got[0], got[0][:40]
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)


MEMORY_CHILD = """
import resource, sys
import numpy as np
import pdeshape
resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))
patch = pdeshape.Scene.load(sys.argv[1]).patches[0]
uv = np.zeros((10_000_000, 2))
uv[:, 0] = 0.5
try:
    patch.derivatives(uv, 2, 4)  # 3.6 GB of output
except MemoryError as e:
    print("MemoryError:", e)
"""


def test_an_output_too_large_for_the_machine_raises_memory_error():
    """Under a 3 GiB address-space limit, 10^7 rows of derivatives up to (2, 4) (3.6 GB)
    killed the interpreter with SIGABRT; now they raise MemoryError."""
    r = subprocess.run(
        [os.sys.executable, "-c", MEMORY_CHILD, str(ROOT / "examples/hermite-ruled.toml")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, (r.returncode, r.stderr[-2000:])
    assert "MemoryError: the array of derivatives: cannot allocate" in r.stdout, (r.stdout, r.stderr[-2000:])


def test_the_memory_cap_bounds_output_arrays_and_caps_are_set_from_python():
    scene = pdeshape.Scene.load(ROOT / "examples/hermite-ruled.toml", limits={"memory": 1})
    patch = scene.patches[0]
    assert patch.evaluate(np.full((40_000, 2), 0.5)).shape == (40_000, 3)  # 0.9 MiB
    with pytest.raises(MemoryError) as e:
        patch.evaluate(np.full((50_000, 2), 0.5))  # 1.1 MiB
    msg = str(e.value)
    assert "limits={'memory': 2}" in msg and "--limit" not in msg, msg
    with pytest.raises(ValueError, match="unknown cap"):
        pdeshape.Scene.load(ROOT / "examples/hermite-ruled.toml", limits={"nope": 1})
    # from_toml's text is held to the scene cap like a file (it took 20 MB); 17 MiB and a
    # scene are 18 MiB rounded up
    text = (ROOT / "examples/hermite-ruled.toml").read_text() + "#" * (17 << 20) + "\n"
    with pytest.raises(pdeshape.SceneError) as e:
        pdeshape.Scene.from_toml(text)
    assert "limits={'scene': 18}" in str(e.value) and "--limit" not in str(e.value), str(e.value)
    # a cap hit while loading is worded for Python too
    with pytest.raises(pdeshape.SceneError) as e:
        pdeshape.Scene.load(ROOT / "examples/klein-bottle.toml", limits={"modes": 2})
    assert "limits={'modes': 6}" in str(e.value) and "--limit" not in str(e.value), str(e.value)


def test_a_mesh_past_the_time_limit_raises_timeout_error():
    """mesh(resolution=(2, 2_000_000)) (within the vertex cap) ran for minutes with no
    bound; with time_limit=0.5 it stops at a checkpoint and raises TimeoutError."""
    import time

    scene = pdeshape.Scene.load(ROOT / "examples/hermite-ruled.toml", time_limit=0.5)
    t = time.perf_counter()
    with pytest.raises(TimeoutError, match="time limit of 0.5 s"):
        scene.patches[0].mesh(resolution=(2, 2_000_000))
    assert time.perf_counter() - t < 10
    # the scene is still usable, and a small mesh is within the limit
    assert scene.patches[0].mesh(resolution=(3, 30)).vertices.shape == (90, 3)
    with pytest.raises(ValueError, match="time_limit"):
        pdeshape.Scene.load(ROOT / "examples/hermite-ruled.toml", time_limit=-1)


def test_a_time_outside_a_dynamic_blend_raises_in_mesh_as_in_evaluate():
    patch = pdeshape.Scene.load(ROOT / "examples/dynamic-linear.toml").patches[0]
    with pytest.raises(RuntimeError) as e1:
        patch.evaluate(np.array([[0.5, 0.0]]), t=1e308)
    with pytest.raises(RuntimeError) as e2:
        patch.mesh(t=1e308)
    assert str(e1.value) == str(e2.value)


def test_bad_scenes_raise_with_the_place():
    text = '[patches.p]\nkind = "hermite"\nconditions = [\n  { u = 0, curve = "nope" },\n]\n'
    with pytest.raises(pdeshape.SceneError) as e:
        pdeshape.Scene.from_toml(text, "bad.toml")
    err = e.value
    assert err.file == "bad.toml"
    assert err.line == 4 and isinstance(err.column, int) and err.column > 1, (err.line, err.column, str(err))
    assert "nope" in str(err)
    with pytest.raises(pdeshape.SceneError) as e:
        pdeshape.Scene.load(ROOT / "examples/does-not-exist.toml")
    assert "cannot read the scene file" in str(e.value) and e.value.line is None
    with pytest.raises(pdeshape.SceneError, match="parameter"):
        pdeshape.Scene.load(ROOT / "examples/klein-bottle.toml", nosuch=1.0)


def test_bad_arguments_raise_value_errors():
    patch = pdeshape.Scene.load(ROOT / "examples/bloor-wilson-blend.toml").patches[0]
    with pytest.raises(ValueError, match="shape"):
        patch.evaluate(np.zeros((4, 3)))
    with pytest.raises(ValueError, match="outside"):
        patch.evaluate(np.array([[1.5, 0.0]]))
    with pytest.raises(ValueError, match="not finite"):
        patch.evaluate(np.array([[0.5, np.nan]]))
    with pytest.raises(ValueError, match="takes no t"):
        patch.evaluate(np.array([[0.5, 0.0]]), t=0.5)
    with pytest.raises(ValueError, match="at most"):
        patch.derivatives(np.array([[0.5, 0.0]]), du=3)
    with pytest.raises(KeyError):
        pdeshape.Scene.load(ROOT / "examples/bloor-wilson-blend.toml")["nope"]


def test_non_contiguous_input_is_evaluated_like_contiguous():
    patch = pdeshape.Scene.load(ROOT / "examples/four-curve-patch.toml").patches[0]
    uv = random_params(patch, 50, seed=3)
    wide = np.zeros((50, 4))
    wide[:, 0], wide[:, 2] = uv[:, 0], uv[:, 1]
    assert np.array_equal(patch.evaluate(wide[:, ::2]), patch.evaluate(uv))


def test_threads_get_the_same_arrays():
    patch = pdeshape.Scene.load(ROOT / "examples/klein-bottle.toml").patches[0]
    uv = random_params(patch, 20000, seed=11)  # above the parallel threshold
    want = patch.evaluate(uv)
    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(lambda _: patch.evaluate(uv), range(8)))
    for r in results:
        assert np.array_equal(r, want)


def test_help_is_useful():
    assert "Scene.load" in pdeshape.__doc__ and "evaluate" in pdeshape.__doc__
    assert "bit for bit" in pdeshape.Patch.evaluate.__doc__


def test_the_sweep_example_runs_and_plots(tmp_path):
    import runpy

    out = tmp_path / "sweep.png"
    runpy.run_path(str(ROOT / "examples/python/sweep.py"), run_name="sweep")["main"](str(out))
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 10_000


STEP = Path(__file__).resolve().parents[2] / "pdeshape" / "tests" / "data" / "step"


def test_holes_and_fill_holes_of_a_step_model(tmp_path):
    """The cylinder without its top: one hole of one closed edge of length 2π; filled at
    order 6 the written model has no hole left and the seam figures are those of the CLI
    (the seam's bounds: gap 1e-9 of the model's size ~3.5, 1e-8 rad; the curvature across
    the rim matches to round-off)."""
    r = pdeshape.holes(STEP / "cylinder-open.step")
    assert r["unit"] == "millimetre"
    assert [h["edges"] for h in r["holes"]] == [[21]]
    assert abs(r["holes"][0]["length"] - 2 * math.pi) < 1e-13
    out = tmp_path / "c.step"
    done = pdeshape.fill_holes(STEP / "cylinder-open.step", out, order=6)
    assert [d["index"] for d in done] == [1]
    seam = done[0]["seam"]
    assert seam["gap"] < 3.4e-9 and seam["angle"] < 1e-8 and seam["relative_curvature_gap"] < 1e-10
    assert pdeshape.holes(out)["holes"] == []


def test_a_replaced_face_of_a_step_model(tmp_path):
    """``replace_faces``: the cylinder's bottom disc (#93) out, both rims are holes of the
    wall (#17); filled, the written model has none left. A mesh has no faces to replace."""
    r = pdeshape.holes(STEP / "cylinder-open.step", replace_faces=[93])
    assert [h["faces"] for h in r["holes"]] == [[17], [17]]
    out = tmp_path / "closed.step"
    done = pdeshape.fill_holes(STEP / "cylinder-open.step", out, replace_faces=[93])
    assert [d["index"] for d in done] == [1, 2]
    assert pdeshape.holes(out)["holes"] == []
    with pytest.raises(pdeshape.ModelError, match="#31 is a"):
        pdeshape.holes(STEP / "cylinder-open.step", replace_faces=[31])
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    with pytest.raises(ValueError, match="a mesh has none"):
        pdeshape.fill_holes(v, np.array([[0, 1, 2]]), replace_faces=[1])


def test_scene_importing_a_step_model(tmp_path, monkeypatch):
    """`[import.NAME] step = …` in a scene loaded from Python: paths relative to the scene
    file (Scene.load) or to the current directory (from_toml); the hole's fill lies on the
    cylinder's rim; pickles carry the import's folder to workers in another directory."""
    import pickle

    (tmp_path / "part.step").write_bytes((STEP / "cylinder-open.step").read_bytes())
    text = '[import.part]\nstep = "part.step"\n\n[patches.top]\nkind = "fill"\nhole = "part.hole1"\norder = 6\n'
    (tmp_path / "top.toml").write_text(text)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    scene = pdeshape.Scene.load(tmp_path / "top.toml")
    top = scene["top"]
    uv = np.array([[0.1 * k, 0.6 * k] for k in range(10)])
    points = top.evaluate(uv)
    # the fill's boundary is the rim of the cylinder of radius 1 at z = 2 (the file's
    # circle), to the round-off of the patch's sum over its modes: measured 7.1e-15 off
    # the radius, 0 off the height
    rim = top.evaluate(np.array([[0.0, v] for v in np.linspace(0, 6, 7)]))
    assert np.max(np.abs(np.hypot(rim[:, 0], rim[:, 1]) - 1)) < 5e-14
    assert np.max(np.abs(rim[:, 2] - 2)) < 5e-14
    # unpickled in another directory: the same file read, the same bits
    restored = pickle.loads(pickle.dumps(scene))
    assert np.array_equal(restored["top"].evaluate(uv), points)
    # scene text: relative to the current directory
    with pytest.raises(pdeshape.SceneError, match="cannot read the model"):
        pdeshape.Scene.from_toml(text)
    monkeypatch.chdir(tmp_path)
    assert np.array_equal(pdeshape.Scene.from_toml(text)["top"].evaluate(uv), points)


def test_bad_models_and_arguments_raise(tmp_path):
    bad = tmp_path / "bad.step"
    bad.write_text((STEP / "cylinder-open.step").read_text().replace("#31 = CYLINDRICAL_SURFACE('',#32,1.);", "#31 = CYLINDRICAL_SURFACE('',#32,-1.);"))
    with pytest.raises(pdeshape.ModelError, match=r"bad.step:\d+: #31 CYLINDRICAL_SURFACE"):
        pdeshape.holes(bad)
    with pytest.raises(ValueError, match="4 \\(G1\\) or 6"):
        pdeshape.fill_holes(STEP / "cylinder-open.step", tmp_path / "o.step", order=5)
    with pytest.raises(pdeshape.ModelError, match="hole 2 does not exist"):
        pdeshape.fill_holes(STEP / "cylinder-open.step", tmp_path / "o.step", holes=[2])
    with pytest.raises(pdeshape.ModelError, match="limits=\\{'entities'"):
        pdeshape.holes(STEP / "cylinder-open.step", limits={"entities": 10})
    assert not (tmp_path / "o.step").exists()


def _height_field_with_hole(k=40, r=0.35):
    """A grid mesh of z = f(x, y) on [-1, 1]² with the triangles near the origin removed."""
    f = lambda x, y: 0.3 * (x * x - 0.5 * y * y) + 0.1 * x * y  # noqa: E731
    t = np.linspace(-1.0, 1.0, k + 1)
    x, y = np.meshgrid(t, t)
    v = np.column_stack([x.ravel(), y.ravel(), f(x, y).ravel()])
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    a = (i * (k + 1) + j).ravel()
    tris = np.concatenate([np.column_stack([a, a + 1, a + k + 2]), np.column_stack([a, a + k + 2, a + k + 1])])
    c = v[tris].mean(axis=1)
    return v, tris[np.hypot(c[:, 0], c[:, 1]) >= r], f


def test_fill_holes_of_numpy_arrays():
    """A height field's hole filled at order 6 from arrays: the input rows come back first
    and unchanged, only the outer rim (4 × 40 edges) stays open, the fill meets its collar
    G1/G2 to round-off and lies near the true surface."""
    v, f, height = _height_field_with_hole()
    v2, f2, figs = pdeshape.fill_holes(v, f, order=6, max_edges=100)
    assert np.array_equal(v2[: len(v)], v) and np.array_equal(f2[: len(f)], f)
    assert v2.dtype == np.float64 and f2.shape[1] == 3
    edges = np.sort(np.concatenate([f2[:, [0, 1]], f2[:, [1, 2]], f2[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert counts.max() == 2 and (counts == 1).sum() == 160
    assert len(figs) == 1 and figs[0]["g1"] < 1e-12 and figs[0]["g2"] < 1e-10
    new = v2[len(v):]
    off = np.abs(new[:, 2] - height(new[:, 0], new[:, 1])).max()
    assert off < 5e-3, off
    with pytest.raises(ValueError, match=r"faces\[0, 2\] = 5000"):
        pdeshape.fill_holes(v, np.array([[0, 1, 5000]]))
    with pytest.raises(ValueError, match=r"vertices: shape \(3, 2\)"):
        pdeshape.fill_holes(np.zeros((3, 2)), np.array([[0, 1, 2]]))


def _check_and_evaluate(scene):
    p = scene.patches[0]
    uv = np.column_stack([np.linspace(0, 1, 5000), np.linspace(0, 6, 5000)])
    return scene.check()["patches"][0]["condition_error"]["max_abs"], p.evaluate(uv)


def test_a_forked_child_computes_after_its_parent_did():
    """Regression: a child forked after the parent's first parallel loop (the default
    start method of multiprocessing on Linux) waited for ever on the inherited rayon pool,
    which has no threads in the child."""
    import multiprocessing

    scene = pdeshape.Scene.load(ROOT / "examples/bloor-wilson-blend.toml")
    here = _check_and_evaluate(scene)  # the parent's pools start here
    with multiprocessing.get_context("fork").Pool(1) as pool:
        there = pool.apply_async(_check_and_evaluate, (scene,)).get(timeout=120)
    assert there[0] == here[0]
    assert there[1].tobytes() == here[1].tobytes()


def test_the_module_pool_takes_rayon_num_threads():
    """Regression: the module's own pool (made for forked children) had one thread per
    core whatever RAYON_NUM_THREADS said, so one-thread measurements ran on all cores.

    A pool's threads exist once it is built but name themselves when they first run, so the
    count is read until it reaches `n` (it never exceeds the pool's size) or 10 s pass: an
    evaluation that returns before the last thread ran (the blend's data are proved
    trigonometric and cost 0.1 µs a point) read 2 of 3. A thread that ends between the
    listing of /proc/self/task and the reading of its name is skipped (no pool thread ends;
    CI once failed on that race, 1 run in 40 when repeated)."""
    import sys

    code = (
        "import glob, os, time, numpy as np, pdeshape\n"
        "def comm(f):\n"
        "    try:\n"
        "        return open(f).read().strip()\n"
        "    except FileNotFoundError:\n"
        "        return ''\n"
        f"p = pdeshape.Scene.load({str(ROOT / 'examples/bloor-wilson-blend.toml')!r}).patches[0]\n"
        "p.evaluate(np.column_stack([np.linspace(0, 1, 10000), np.zeros(10000)]))\n"
        "want, end = int(os.environ['RAYON_NUM_THREADS']), time.monotonic() + 10\n"
        "while True:\n"
        "    names = [comm(f) for f in glob.glob('/proc/self/task/*/comm')]\n"
        "    count = sum(n.startswith('pdeshape-py-') for n in names)\n"
        "    if count >= want or time.monotonic() > end:\n"
        "        break\n"
        "    time.sleep(0.01)\n"
        "print(count)\n"
    )
    if not Path("/proc/self/task").is_dir():
        pytest.skip("threads are counted in /proc")
    for n in (1, 3):
        env = dict(os.environ, RAYON_NUM_THREADS=str(n))
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
        assert out.stdout.strip() == str(n), (n, out.stdout, out.stderr)
