"""The example notebook, run headless as a reader would run it, and the interactive view.

CI sets PDESHAPE_REQUIRE_NOTEBOOK=1: there nbclient, ipykernel and pythreejs must be
installed and these tests cannot skip.
"""

import base64
import io
import os
from pathlib import Path

import numpy as np
import pytest

import pdeshape

ROOT = Path(__file__).resolve().parents[3]
REQUIRED = os.environ.get("PDESHAPE_REQUIRE_NOTEBOOK") == "1"


def need(module):
    if REQUIRED:
        return __import__(module)
    return pytest.importorskip(module)


def drawn_fraction(png):
    """The share of the picture that differs from its corner's background colour, and the
    extent of the drawn part in pixels (rows, columns)."""
    image = pytest.importorskip("matplotlib.image").imread(io.BytesIO(png), format="png")
    drawn = np.any(np.abs(image[:, :, :3] - image[0, 0, :3]) > 0.05, axis=2)
    rows, cols = np.nonzero(drawn)
    extent = (rows.max() - rows.min(), cols.max() - cols.min()) if len(rows) else (0, 0)
    return drawn.mean(), extent


def test_the_example_notebook_runs_and_draws_its_shapes():
    nbformat = need("nbformat")
    nbclient = need("nbclient")
    need("ipykernel")
    need("pythreejs")
    nb = nbformat.read(ROOT / "examples/python/notebook.ipynb", as_version=4)
    nbclient.NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(ROOT)}}).execute()
    pictures, widgets, texts = [], 0, []
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            assert out.get("output_type") != "error", out
            data = out.get("data", {})
            if "image/png" in data:
                pictures.append(base64.b64decode(data["image/png"]))
            if "application/vnd.jupyter.widget-view+json" in data:
                widgets += 1
            texts.append(out.get("text", "") + data.get("text/plain", ""))
    # the Klein bottle, the bottle from data and the filled sheet
    assert len(pictures) == 3, len(pictures)
    for png in pictures:
        share, (h, w) = drawn_fraction(png)
        # a shape, not an empty or a filled frame, of a fair size in each direction
        assert 0.05 < share < 0.9 and h > 150 and w > 150, (share, h, w)
    assert widgets == 1
    printed = "".join(texts)
    assert "largest interpolation residual" in printed and "G1 " in printed, printed


def test_show_draws_the_meshes_the_object_makes():
    three = need("pythreejs")
    scene = pdeshape.Scene.load(ROOT / "examples/blend-cone-cylinder.toml")
    view = scene.show(resolution=(9, 17), width=640, height=480)
    assert isinstance(view, three.Renderer) and (view.width, view.height) == (640, 480)
    drawn = [c for c in view.scene.children if isinstance(c, three.Mesh)]
    assert [m.name for m in drawn] == [p.name for p in scene.patches]
    for m, p in zip(drawn, scene.patches):
        mesh = p.mesh(resolution=(9, 17))
        attrs = m.geometry.attributes
        assert np.array_equal(attrs["position"].array, mesh.vertices.astype(np.float32))
        assert np.array_equal(attrs["index"].array, mesh.faces.ravel())
        assert np.array_equal(attrs["normal"].array, mesh.normals.astype(np.float32))
    # the camera looks at the middle of the meshes' bounding box
    all_v = np.concatenate([p.mesh(resolution=(9, 17)).vertices for p in scene.patches])
    centre = (all_v.min(axis=0) + all_v.max(axis=0)) / 2
    assert np.allclose(view.controls[0].target, centre)
    patch_view = scene.patches[0].show()
    assert len([c for c in patch_view.scene.children if isinstance(c, three.Mesh)]) == 1
    mesh = scene.patches[0].mesh(resolution=(5, 7))
    assert mesh.show().scene.children[0].geometry.attributes["position"].array.shape == (35, 3)
    with pytest.raises(TypeError, match="a mesh is drawn as it is"):
        mesh.show(resolution=(3, 3))
    with pytest.raises(ValueError, match="positive"):
        scene.show(width=0)
