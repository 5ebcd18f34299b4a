"""Writes the STEP models of the `holes`/`fill-holes` tests with OpenCASCADE (the CI venv's
`cadquery-ocp`): each a solid with faces removed, so that the removed faces leave holes.

    python make_models.py    # in this directory; rewrites the .step files

- cylinder-open.step: a cylinder (radius 1, height 2) without its top: one hole bounded by
  one closed circular edge on a cylindrical face.
- rounded-box-corners.step: a 2 × 2 × 2 box with every edge rounded (radius 0.4) without
  its eight spherical corner faces: eight three-sided holes between cylindrical faces.
- loft-open.step: a loft through a circle, an ellipse and a smaller circle (B-spline
  faces) without its top: one hole bounded by one closed edge on a B-spline face.
- loft-twelve.step: a loft through three circles (radius 1 at z = 0; 1.3, its centre moved
  by (0.2, 0.1), at z = 1; 0.7 at z = 2), each cut into twelve arcs, without its top: one
  hole of twelve edges, each on its own B-spline face, the faces meeting G1 at its corners.
- tube-windows.step: a B-spline tube (a loft's lateral face alone: a circle, an ellipse, a
  smaller circle) with two windows cut through its wall by boxes: four holes on its one
  face — the two open ends (one closed edge each) and the two windows (four edges each,
  where the boxes cut the wall).
- touching-parts.step: two parts of one open shell that touch at two points, with a gap
  between them: the lower part a cylinder (radius 1) with its bottom, cut by a roof
  z = 1 − |x|/2, the upper part the same cylinder with its top, cut by z = 1 + |x|/2;
  the roofs left out. They touch at (0, ±1, 1), each with its own vertices there; the gap
  is two lens-shaped holes, each running along the lower part's edges and back along the
  upper part's.

Made by this project with OpenCASCADE; no third-party content.
"""

import math

from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Cut
from OCP.BRep import BRep_Builder
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakePolygon,
    BRepBuilderAPI_MakeWire,
)
from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
from OCP.BRepOffsetAPI import BRepOffsetAPI_ThruSections
from OCP.GC import GC_MakeArcOfCircle
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakePrism
from OCP.GeomAbs import GeomAbs_Plane, GeomAbs_Sphere
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Shell
from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Elips, gp_Pnt, gp_Vec


def faces(shape):
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        yield TopoDS.Face(ex.Current())
        ex.Next()


def shell_without(shape, drop):
    """The faces of `shape` but those `drop(face)` picks, as one open shell."""
    b = BRep_Builder()
    sh = TopoDS_Shell()
    b.MakeShell(sh)
    for f in faces(shape):
        if not drop(f):
            b.Add(sh, f)
    return sh


def write(shape, path):
    w = STEPControl_Writer()
    w.Transfer(shape, STEPControl_AsIs)
    assert w.Write(path) == 1, path


def top_plane(z):
    def drop(f):
        s = BRepAdaptor_Surface(f)
        return s.GetType() == GeomAbs_Plane and abs(s.Plane().Location().Z() - z) < 1e-9
    return drop


def main():
    cyl = BRepPrimAPI_MakeCylinder(1.0, 2.0).Shape()
    write(shell_without(cyl, top_plane(2.0)), "cylinder-open.step")

    box = BRepPrimAPI_MakeBox(2.0, 2.0, 2.0).Shape()
    fillet = BRepFilletAPI_MakeFillet(box)
    ex = TopExp_Explorer(box, TopAbs_EDGE)
    while ex.More():
        fillet.Add(0.4, TopoDS.Edge(ex.Current()))
        ex.Next()
    rounded = fillet.Shape()
    write(shell_without(rounded, lambda f: BRepAdaptor_Surface(f).GetType() == GeomAbs_Sphere), "rounded-box-corners.step")

    def wire(curve):
        return BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(curve).Edge()).Wire()

    loft = BRepOffsetAPI_ThruSections(True, False)
    loft.AddWire(wire(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 1.0)))
    loft.AddWire(wire(gp_Elips(gp_Ax2(gp_Pnt(0, 0, 1), gp_Dir(0, 0, 1)), 1.3, 0.8)))
    loft.AddWire(wire(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 2), gp_Dir(0, 0, 1)), 0.7)))
    loft.Build()
    write(shell_without(loft.Shape(), top_plane(2.0)), "loft-open.step")

    def arcs(circle, n=12):
        w = BRepBuilderAPI_MakeWire()
        for k in range(n):
            a0, a1 = 2 * math.pi * k / n, 2 * math.pi * (k + 1) / n
            w.Add(BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(circle, a0, a1, True).Value()).Edge())
        return w.Wire()

    twelve = BRepOffsetAPI_ThruSections(True, False)
    twelve.AddWire(arcs(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 1.0)))
    twelve.AddWire(arcs(gp_Circ(gp_Ax2(gp_Pnt(0.2, 0.1, 1), gp_Dir(0, 0, 1)), 1.3)))
    twelve.AddWire(arcs(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 2), gp_Dir(0, 0, 1)), 0.7)))
    twelve.Build()
    write(shell_without(twelve.Shape(), top_plane(2.0)), "loft-twelve.step")

    tube = BRepOffsetAPI_ThruSections(False, False)
    tube.AddWire(wire(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 1.0)))
    tube.AddWire(wire(gp_Elips(gp_Ax2(gp_Pnt(0, 0, 1.5), gp_Dir(0, 0, 1)), 1.3, 0.9)))
    tube.AddWire(wire(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 3), gp_Dir(0, 0, 1)), 0.8)))
    tube.Build()
    cut = tube.Shape()
    # windows on the ±y sides, away from the face's seam (at +x)
    for lo, hi in [((-0.35, 0.2, 0.8), (0.35, 2.0, 1.6)), ((-0.3, -2.0, 1.7), (0.3, -0.2, 2.3))]:
        cut = BRepAlgoAPI_Cut(cut, BRepPrimAPI_MakeBox(gp_Pnt(*lo), gp_Pnt(*hi)).Shape()).Shape()
    write(cut, "tube-windows.step")

    def prism(xz):
        """The polygon `xz` in the plane y = -2, swept to y = 2."""
        poly = BRepBuilderAPI_MakePolygon()
        for x, z in xz:
            poly.Add(gp_Pnt(x, -2.0, z))
        poly.Close()
        return BRepPrimAPI_MakePrism(BRepBuilderAPI_MakeFace(poly.Wire()).Face(), gp_Vec(0, 4.0, 0)).Shape()

    cyl = BRepPrimAPI_MakeCylinder(1.0, 2.0).Shape()
    lower = BRepAlgoAPI_Common(cyl, prism([(-2, -1), (2, -1), (2, 0), (0, 1), (-2, 0)])).Shape()
    upper = BRepAlgoAPI_Common(cyl, prism([(-2, 2), (0, 1), (2, 2), (2, 3), (-2, 3)])).Shape()

    def roof(f):
        s = BRepAdaptor_Surface(f)
        return s.GetType() == GeomAbs_Plane and abs(abs(s.Plane().Axis().Direction().Z()) - 1) > 1e-9

    b = BRep_Builder()
    both = TopoDS_Shell()
    b.MakeShell(both)
    for part in (lower, upper):
        for f in faces(part):
            if not roof(f):
                b.Add(both, f)
    write(both, "touching-parts.step")


if __name__ == "__main__":
    main()
