"""OpenCASCADE's plate filling (BRepOffsetAPI_MakeFilling, G1 to a support face on every
edge) on the sphere holes of examples/fill-sphere-{triangle,pentagon,hexagon}.toml: the
figures the examples and tests quote beside pdeshape's fills.

Each hole's edge i is the great-circle arc from vertex A to vertex A' on the unit sphere. Its
support is the unit sphere placed so that the arc is its equator: Geom_SphericalSurface with
axis M = A x A' / |A x A'| (towards the hole) and x direction A, whose (u, v) = (longitude,
latitude) puts the arc at v = 0, u in [0, angle(A, A')]: the edge is built from that line of
the parameter plane (its pcurve, exact), and the support face is the band -0.45 <= v <= 0
outside the hole, as in the examples (s < 0).

Measured on the filled face, at 400 points per edge: the gap (distance from the arc's point
to the face, by projection), the G1 error (angle between the normal lines of the face and of
the sphere, whose normal is the position), and over the face's triangulation the largest
|r - 1| (the ideal fill is the spherical cap). Time: the median of 5 builds, one thread.

    python crates/pdeshape-io/bench/occt_filling.py        # needs cadquery-ocp
"""

import math
import statistics
import time

from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace
from OCP.BRepLib import BRepLib
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeFilling
from OCP.Geom import Geom_SphericalSurface
from OCP.Geom2d import Geom2d_Line
from OCP.GeomAbs import GeomAbs_G1
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.GeomLProp import GeomLProp_SLProps
from OCP.gp import gp_Ax3, gp_Dir, gp_Dir2d, gp_Pnt, gp_Pnt2d
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS

# name, sides, polar angle of the vertices (degrees): the examples' holes
HOLES = [("triangle", 3, 50.0), ("pentagon", 5, 40.0), ("hexagon", 6, 60.0)]
PER_EDGE = 400


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def unit(a):
    n = math.sqrt(sum(x * x for x in a))
    return tuple(x / n for x in a)


def hole(n, deg):
    """The edges and support faces of the hole: [(edge, face, sphere, angle)]."""
    th = math.radians(deg)
    vert = [
        (math.sin(th) * math.cos(2 * math.pi * i / n), math.sin(th) * math.sin(2 * math.pi * i / n), math.cos(th))
        for i in range(n)
    ]
    out = []
    for i in range(n):
        a, a1 = vert[i], vert[(i + 1) % n]
        m = unit(cross(a, a1))
        ang = math.acos(max(-1.0, min(1.0, sum(x * y for x, y in zip(a, a1)))))
        sphere = Geom_SphericalSurface(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(*m), gp_Dir(*a)), 1.0)
        line = Geom2d_Line(gp_Pnt2d(0, 0), gp_Dir2d(1, 0))
        edge = BRepBuilderAPI_MakeEdge(line, sphere, 0.0, ang).Edge()
        BRepLib.BuildCurves3d_s(edge)
        face = BRepBuilderAPI_MakeFace(sphere, 0.0, ang, -0.45, 0.0, 1e-9).Face()
        out.append((edge, face, sphere, ang))
    return out


def fill(edges):
    f = BRepOffsetAPI_MakeFilling()
    for edge, face, _, _ in edges:
        f.Add(edge, face, GeomAbs_G1, True)
    f.Build()
    assert f.IsDone()
    exp = TopExp_Explorer(f.Shape(), TopAbs_FACE)
    return TopoDS.Face(exp.Current())


def measure(edges, face):
    surf = BRep_Tool.Surface_s(face)
    g1 = gap = 0.0
    for _, _, sphere, ang in edges:
        for k in range(PER_EDGE):
            p = sphere.Value(ang * (k + 0.5) / PER_EDGE, 0.0)
            proj = GeomAPI_ProjectPointOnSurf(p, surf)
            gap = max(gap, proj.LowerDistance())
            u, v = proj.LowerDistanceParameters()
            props = GeomLProp_SLProps(surf, u, v, 1, 1e-9)
            nrm = props.Normal()
            r = (p.X(), p.Y(), p.Z())
            c = cross((nrm.X(), nrm.Y(), nrm.Z()), unit(r))
            g1 = max(g1, math.asin(min(1.0, math.sqrt(sum(x * x for x in c)))))
    BRepMesh_IncrementalMesh(face, 1e-3, False, 0.1)
    tri = BRep_Tool.Triangulation_s(face, TopLoc_Location())
    dev = max(abs(tri.Node(i).Distance(gp_Pnt(0, 0, 0)) - 1.0) for i in range(1, tri.NbNodes() + 1))
    return g1, gap, dev


def main():
    print("| hole | time (ms, median of 5) | G1 error (rad) | edge gap | max abs(r - 1) |")
    print("|---|---|---|---|---|")
    for name, n, deg in HOLES:
        edges = hole(n, deg)
        times = []
        for _ in range(5):
            t = time.perf_counter()
            face = fill(edges)
            times.append((time.perf_counter() - t) * 1e3)
        g1, gap, dev = measure(edges, face)
        print(f"| fill-sphere-{name} | {statistics.median(times):.1f} | {g1:.1e} | {gap:.1e} | {dev:.1e} |")


if __name__ == "__main__":
    main()
