"""OpenCASCADE helpers shared by the fill-holes test and its benchmark beside MakeFilling:
a shape's faces, each edge with the faces that use it, and the local geometry of a face
at the foot of a point (normal, second derivatives, normal curvature in a direction)."""

from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.gp import gp_Pnt, gp_Vec


def faces(shape):
    out = []
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        out.append(TopoDS.Face(ex.Current()))
        ex.Next()
    return out


def edge_uses(shape):
    """Each edge with the faces that use it (a seam twice by its face)."""
    groups = {}
    for f in faces(shape):
        ex = TopExp_Explorer(f, TopAbs_EDGE)
        while ex.More():
            e = TopoDS.Edge(ex.Current())
            bucket = groups.setdefault(hash(e), [])
            for g in bucket:
                if g[0].IsSame(e):
                    g[1].append(f)
                    break
            else:
                bucket.append((e, [f]))
            ex.Next()
    return [g for b in groups.values() for g in b]


def jet(face, p):
    """Point, unit normal and second derivatives of the face's surface at the foot of p."""
    surf = BRep_Tool.Surface_s(face)
    proj = GeomAPI_ProjectPointOnSurf(p, surf)
    u, v = proj.LowerDistanceParameters()
    s = BRepAdaptor_Surface(face)
    pt, su, sv, suu, svv, suv = gp_Pnt(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
    s.D2(u, v, pt, su, sv, suu, svv, suv)
    n = su.Crossed(sv)
    n.Normalize()
    return proj.LowerDistance(), n, (su, sv, suu, svv, suv)


def normal_curvature(d, n, t):
    """II(t, t) / I(t, t) for t in the tangent plane, t = a S_u + b S_v."""
    su, sv, suu, svv, suv = d
    e, f, g = su.Dot(su), su.Dot(sv), sv.Dot(sv)
    tu, tv = t.Dot(su), t.Dot(sv)
    det = e * g - f * f
    a, b = (g * tu - f * tv) / det, (e * tv - f * tu) / det
    second = suu.Multiplied(a * a).Added(suv.Multiplied(2 * a * b)).Added(svv.Multiplied(b * b))
    first = su.Multiplied(a).Added(sv.Multiplied(b))
    return second.Dot(n) / first.Dot(first)
