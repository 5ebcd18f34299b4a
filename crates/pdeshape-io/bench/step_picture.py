"""Renders a STEP file as OpenCASCADE reads it (docs/step-in-occt.png in the README):
STEPControl_Reader, BRepMesh_IncrementalMesh, then the triangles of every face drawn
with matplotlib, each face in its own colour, and its B-spline net size in the legend.

    python crates/pdeshape-io/bench/step_picture.py model.step out.png [azimuth elevation]
"""

import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS


def main(path, out, azim=-60.0, elev=25.0):
    reader = STEPControl_Reader()
    reader.ReadFile(path)
    reader.TransferRoots()
    shape = reader.OneShape()
    BRepMesh_IncrementalMesh(shape, 0.01, False, 0.2, True)
    fig = plt.figure(figsize=(8, 6), dpi=120)
    ax = fig.add_subplot(projection="3d")
    colours = plt.cm.tab10.colors
    ex, k, allpts = TopExp_Explorer(shape, TopAbs_FACE), 0, []
    all_polys, all_colours, labels = [], [], []
    light = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    while ex.More():
        face = TopoDS.Face(ex.Current())
        tri = BRep_Tool.Triangulation_s(face, TopLoc_Location())
        pts = np.array([[tri.Node(i).X(), tri.Node(i).Y(), tri.Node(i).Z()] for i in range(1, tri.NbNodes() + 1)])
        tris = np.array([tri.Triangle(i).Get() for i in range(1, tri.NbTriangles() + 1)]) - 1
        polys = pts[tris]
        n = np.cross(polys[:, 1] - polys[:, 0], polys[:, 2] - polys[:, 0])
        n /= np.linalg.norm(n, axis=1, keepdims=True) + 1e-300
        shade = 0.35 + 0.65 * np.abs(n @ light)
        base = np.array(colours[k % len(colours)])
        bs = BRepAdaptor_Surface(face).BSpline()
        all_polys.append(polys)
        all_colours.append(np.clip(base[None, :] * shade[:, None], 0, 1))
        labels.append(f"face {k + 1}: B-spline {bs.NbUPoles()} × {bs.NbVPoles()} poles")
        allpts.append(pts)
        ex.Next()
        k += 1
    # one collection: matplotlib orders its triangles by depth (not across collections)
    coll = Poly3DCollection(np.vstack(all_polys), facecolors=np.vstack(all_colours), edgecolors="none", linewidths=0)
    ax.add_collection3d(coll)
    allpts = np.vstack(allpts)
    lo, hi = allpts.min(0), allpts.max(0)
    c, r = (lo + hi) / 2, (hi - lo).max() / 2
    r *= 0.62
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()
    handles = [plt.Rectangle((0, 0), 1, 1, color=colours[i % len(colours)]) for i in range(k)]
    ax.legend(handles, labels, loc="lower left", fontsize=8, frameon=False)
    ax.set_title(f"{path.split('/')[-1]} read back by OpenCASCADE ({k} faces)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out)


if __name__ == "__main__":
    args = sys.argv[1:]
    main(args[0], args[1], *(float(a) for a in args[2:4]))
