"""Parameter sweeps: serial, on concurrent.futures executors and on a Dask cluster, all
equal to the serial sweep and to scenes solved one by one."""

import os
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import pdeshape
from pdeshape.sweep import report_figures, settings_of

ROOT = Path(__file__).resolve().parents[3]
BLEND = ROOT / "examples/bloor-wilson-blend.toml"


def point_height(scene):
    """A measure: the height of the blend's point at (u, v) = (0.5, 0), and its area."""
    p = scene.patches[0]
    x = p.evaluate(np.array([[0.5, 0.0]]))[0]
    return {"z_mid": float(x[2]), "condition_error": scene.check()["patches"][0]["condition_error"]["max_abs"]}


def test_settings_are_the_product_in_key_order():
    s = settings_of({"a": [1, 2], "k0": np.array([0.5, 1.0, 1.5])})
    assert s[:4] == [{"a": 1.0, "k0": 0.5}, {"a": 1.0, "k0": 1.0}, {"a": 1.0, "k0": 1.5}, {"a": 2.0, "k0": 0.5}]
    assert len(s) == 6
    assert settings_of([{"a": 1}, {"a": 3}]) == [{"a": 1.0}, {"a": 3.0}]


def test_a_serial_sweep_equals_scenes_solved_one_by_one(tmp_path):
    scene = pdeshape.Scene.load(BLEND)
    values = {"k1": [0.5, 1.25, 2.0], "k0": [1.0, 2.0]}
    table = pdeshape.sweep(scene, values, meshes=tmp_path / "meshes", table="dict", progress=False)
    assert list(table)[:2] == ["k1", "k0"]
    assert len(table["k1"]) == 6
    for i, setting in enumerate(settings_of(values)):
        one = scene.set(**setting)
        expected = report_figures(one)
        for k, v in expected.items():
            assert table[k][i] == v, (i, k)
        assert table["k1"][i] == setting["k1"] and table["k0"][i] == setting["k0"]
        with np.load(table["mesh_file"][i]) as f:
            m = one.patches[0].mesh()
            assert np.array_equal(f["blend/vertices"], m.vertices)
            assert np.array_equal(f["blend/faces"], m.faces)
            assert np.array_equal(f["blend/normals"], m.normals)
    assert sorted(os.listdir(tmp_path / "meshes")) == [f"{i:06d}.npz" for i in range(6)]


def test_sweeps_on_executors_equal_the_serial_sweep():
    pd = pytest.importorskip("pandas")
    scene = pdeshape.Scene.load(BLEND)
    # (the blend's z is mode 0 alone, which `a` does not change; the measured height z_mid
    # moves with the tangent length k0)
    values = {"k0": np.linspace(0.3, 2.5, 10)}
    serial = pdeshape.sweep(scene, values, measure=point_height, progress=False)
    assert isinstance(serial, pd.DataFrame) and list(serial.columns) == ["k0", "z_mid", "condition_error"]
    with ThreadPoolExecutor(2) as ex:
        threads = pdeshape.sweep(scene, values, measure=point_height, executor=ex, chunksize=3, progress=False)
    with ProcessPoolExecutor(2) as ex:
        procs = pdeshape.sweep(scene, values, measure=point_height, executor=ex, progress=False)
    pd.testing.assert_frame_equal(serial, threads, check_exact=True)
    pd.testing.assert_frame_equal(serial, procs, check_exact=True)
    # the heights differ with k0: the sweep really solved each setting
    assert serial["z_mid"].nunique() == 10


def test_a_dask_sweep_of_100_settings_equals_the_serial_sweep(tmp_path):
    if os.environ.get("PDESHAPE_REQUIRE_DASK") != "1":
        pytest.importorskip("distributed")
    from distributed import Client, LocalCluster

    pd = pytest.importorskip("pandas")
    scene = pdeshape.Scene.load(BLEND)
    values = {"k0": np.linspace(0.4, 2.4, 10), "k1": np.linspace(0.5, 3.0, 10)}
    serial = pdeshape.sweep(scene, values, progress=False)
    assert len(serial) == 100
    done = []
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            on_dask = pdeshape.sweep(
                scene, values, executor=client, meshes=tmp_path, progress=lambda k, n: done.append((k, n))
            )
    assert done[-1] == (100, 100)
    pd.testing.assert_frame_equal(serial, on_dask.drop(columns=["mesh_file"]), check_exact=True)
    assert len(list(tmp_path.glob("*.npz"))) == 100


def test_bad_sweeps_raise_naming_the_setting():
    scene = pdeshape.Scene.load(BLEND)
    with pytest.raises(KeyError, match=r"settings\[0\]: no parameter `b`"):
        pdeshape.sweep(scene, {"b": [1.0]}, table="dict")
    with pytest.raises(ValueError, match=r"settings\[1\]: a = nan is not finite"):
        pdeshape.sweep(scene, [{"a": 1.0}, {"a": float("nan")}], table="dict")
    with pytest.raises(ValueError, match="table = 'csv'"):
        pdeshape.sweep(scene, {"a": [1.0]}, table="csv")
    # a setting the scene refuses (a = 0: the operator degenerates) names the setting
    with pytest.raises(pdeshape.SceneError, match=r"sweep setting 1 \{'a': 0.0\}: "):
        pdeshape.sweep(scene, {"a": [1.0, 0.0]}, table="dict")


def test_the_dataset_example_writes_its_variants(tmp_path):
    """examples/python/dataset.py at 24 variants on two processes: a table row and an npz
    per variant, each mesh the one its setting's scene makes at the asked resolution."""
    pd = pytest.importorskip("pandas")
    import importlib.util

    spec = importlib.util.spec_from_file_location("dataset", ROOT / "examples/python/dataset.py")
    dataset = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(dataset)
    table = dataset.main([str(tmp_path), "--count", "24", "--workers", "2", "--resolution", "7", "11"])
    assert len(table) == 24 and len(list((tmp_path / "meshes").glob("*.npz"))) == 24
    saved = pd.read_parquet(tmp_path / "variants.parquet") if (tmp_path / "variants.parquet").exists() else pd.read_csv(tmp_path / "variants.csv")
    assert list(saved["mesh_file"]) == [f"meshes/{k:06d}.npz" for k in range(24)]
    base = pdeshape.Scene.load(BLEND)
    names = [n for n, p in base.parameters.items() if p["min"] is not None]
    assert len(names) == 6 and all(n in saved for n in names)
    for k in (0, 23):
        setting = {n: float(table[n][k]) for n in names}
        for n in names:
            p = base.parameters[n]
            assert p["min"] <= setting[n] <= p["max"], (n, setting[n])
        mesh = base.set(**setting).patches[0].mesh(resolution=(7, 11))
        with np.load(tmp_path / saved["mesh_file"][k]) as f:
            assert np.array_equal(f["blend/vertices"], mesh.vertices)
            assert np.array_equal(f["blend/faces"], mesh.faces)
