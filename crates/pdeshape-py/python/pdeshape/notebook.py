"""Interactive 3D views in Jupyter: ``scene.show()``, ``patch.show()``, ``mesh.show()``.

The view is a pythreejs widget (three.js in the notebook, through ipywidgets): the meshes
the objects make, drawn shaded with their normals, an orbiting camera aimed at their
bounding box. Static pictures need nothing of this: ``_repr_png_`` (the software renderer)
is what a notebook shows for a scene, a patch or a mesh by default, and what an exported
notebook keeps.
"""

from typing import TYPE_CHECKING, Any, List, Optional, Sequence, Tuple, Union

import numpy as np

if TYPE_CHECKING:
    from ._native import Mesh, Patch, Scene

# the editor's patch colours, in order
PALETTE: Sequence[str] = ("#5b9bd5", "#ed7d31", "#70ad47", "#ffc000", "#4472c4", "#a5a5a5", "#9e480e", "#264478")


def meshes(obj: "Union[Scene, Patch, Mesh]", resolution: Optional[Tuple[int, int]] = None) -> "List[Mesh]":
    """The meshes a view of ``obj`` draws: a scene's patches, a patch, or the mesh itself."""
    from ._native import Mesh, Patch, Scene

    if isinstance(obj, Mesh):
        if resolution is not None:
            raise TypeError("show(): `resolution` is for scenes and patches (a mesh is drawn as it is)")
        return [obj]
    if isinstance(obj, Patch):
        return [obj.mesh(resolution=resolution)]
    if isinstance(obj, Scene):
        return [p.mesh(resolution=resolution) for p in obj.patches]
    raise TypeError(f"show(): a Scene, Patch or Mesh, not {type(obj).__name__}")


def show(
    obj: "Union[Scene, Patch, Mesh]",
    *,
    resolution: Optional[Tuple[int, int]] = None,
    width: int = 800,
    height: int = 600,
) -> Any:
    """An interactive view of ``obj`` (a pythreejs ``Renderer`` widget: Jupyter displays
    it; drag to orbit, scroll to zoom). Needs ``pip install pythreejs``."""
    try:
        import pythreejs as three  # type: ignore[import-untyped, import-not-found, unused-ignore]
    except ImportError as e:
        raise ImportError("show() draws with pythreejs: pip install pythreejs (or use the PNG the object shows by default)") from e
    if width < 1 or height < 1:
        raise ValueError(f"show(): width and height are positive, got {width} × {height}")
    drawn = meshes(obj, resolution)
    children: List[Any] = []
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for i, m in enumerate(drawn):
        attributes = {
            "position": three.BufferAttribute(np.ascontiguousarray(m.vertices, dtype=np.float32), normalized=False),
            "index": three.BufferAttribute(np.ascontiguousarray(m.faces, dtype=np.uint32).ravel(), normalized=False),
        }
        if m.normals is not None:
            attributes["normal"] = three.BufferAttribute(np.ascontiguousarray(m.normals, dtype=np.float32), normalized=False)
        material = three.MeshStandardMaterial(color=PALETTE[i % len(PALETTE)], side="DoubleSide", roughness=0.55, metalness=0.05)
        children.append(three.Mesh(geometry=three.BufferGeometry(attributes=attributes), material=material, name=m.name))
        if len(m.vertices):
            lo = np.minimum(lo, m.vertices.min(axis=0))
            hi = np.maximum(hi, m.vertices.max(axis=0))
    if not np.all(np.isfinite(lo)):
        lo, hi = np.zeros(3), np.ones(3)
    centre = (lo + hi) / 2
    radius = max(float(np.linalg.norm(hi - lo)) / 2, 1e-9)
    # the render command's default view: from the front right, above
    eye = centre + radius * np.array([1.6, -2.0, 1.4])
    camera = three.PerspectiveCamera(
        position=eye.tolist(),
        up=[0, 0, 1],
        aspect=width / height,
        near=radius / 100,
        far=radius * 100,
        children=[three.DirectionalLight(color="white", position=[3, 5, 1], intensity=0.6)],
    )
    scene = three.Scene(children=[*children, camera, three.AmbientLight(color="#777777")], background="#f4f6f8")
    controls = three.OrbitControls(controlling=camera, target=centre.tolist())
    camera.lookAt(centre.tolist())
    return three.Renderer(camera=camera, scene=scene, controls=[controls], width=width, height=height)
