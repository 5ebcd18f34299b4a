"""The README's before/after picture of `fill-holes` (docs/fill-holes.png): the input model
and the filled one, both as OpenCASCADE reads them (STEPControl_Reader, BRepMesh), drawn
with matplotlib; the faces the input had in grey, the new faces in orange, shaded by one
light, the faces turned away from the eye left out.

    python crates/pdeshape-io/bench/fill_holes_picture.py before.step after.step out.png
"""

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from OCP.BRep import BRep_Tool
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED, TopAbs_SOLID
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS


ELEV, AZIM = 32.0, 40.0
VIEW = np.array(
    [np.cos(np.radians(ELEV)) * np.cos(np.radians(AZIM)), np.cos(np.radians(ELEV)) * np.sin(np.radians(AZIM)), np.sin(np.radians(ELEV))]
)


def read(path):
    r = STEPControl_Reader()
    r.ReadFile(path)
    r.TransferRoots()
    return r.OneShape()


def count(shape, kind):
    ex, n = TopExp_Explorer(shape, kind), 0
    while ex.More():
        n += 1
        ex.Next()
    return n


def draw(ax, shape, old_faces, title):
    BRepMesh_IncrementalMesh(shape, 0.002, False, 0.1, True)
    light = np.array([0.5, 0.2, 0.85]) / np.linalg.norm([0.5, 0.2, 0.85])
    polys, colours, pts_all = [], [], []
    ex, k = TopExp_Explorer(shape, TopAbs_FACE), 0
    while ex.More():
        face = TopoDS.Face(ex.Current())
        tri = BRep_Tool.Triangulation_s(face, TopLoc_Location())
        pts = np.array([[tri.Node(i).X(), tri.Node(i).Y(), tri.Node(i).Z()] for i in range(1, tri.NbNodes() + 1)])
        tris = np.array([tri.Triangle(i).Get() for i in range(1, tri.NbTriangles() + 1)]) - 1
        if face.Orientation() == TopAbs_REVERSED:
            tris = tris[:, ::-1]
        p = pts[tris]
        n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        n /= np.linalg.norm(n, axis=1, keepdims=True) + 1e-300
        # back faces culled: matplotlib sorts triangles by depth only roughly
        front = n @ VIEW > 0
        p, n = p[front], n[front]
        shade = 0.25 + 0.75 * np.clip(n @ light, 0, 1)
        base = np.array([0.62, 0.66, 0.72]) if k < old_faces else np.array([0.95, 0.55, 0.15])
        polys.append(p)
        colours.append(np.clip(base[None, :] * shade[:, None], 0, 1))
        pts_all.append(pts)
        ex.Next()
        k += 1
    ax.add_collection3d(Poly3DCollection(np.vstack(polys), facecolors=np.vstack(colours), edgecolors="none", linewidths=0))
    pts = np.vstack(pts_all)
    lo, hi = pts.min(0), pts.max(0)
    c, r = (lo + hi) / 2, (hi - lo).max() / 2 * 0.8
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=ELEV, azim=AZIM)
    ax.set_axis_off()
    ax.set_title(title, fontsize=10)


def main(before, after, out):
    a, b = read(before), read(after)
    na = count(a, TopAbs_FACE)
    fig = plt.figure(figsize=(10, 5), dpi=110)
    draw(fig.add_subplot(1, 2, 1, projection="3d"), a, na, f"{before.split('/')[-1]}: {na} faces, corners open")
    valid = "valid" if BRepCheck_Analyzer(b).IsValid() else "NOT valid"
    draw(
        fig.add_subplot(1, 2, 2, projection="3d"),
        b,
        na,
        f"filled, read back by OpenCASCADE: {count(b, TopAbs_FACE)} faces, {count(b, TopAbs_SOLID)} solid ({valid})",
    )
    fig.tight_layout()
    fig.savefig(out)


if __name__ == "__main__":
    main(*sys.argv[1:4])
