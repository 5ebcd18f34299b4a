"""STEP export read back by OpenCASCADE, the independent consumer (run by .ci/run in a venv
with `cadquery-ocp`).

For each example: `pdeshape build SCENE -o X.step` (the fit's measured figures are read
from its report), then OCCT's STEPControl_Reader transfers the file, BRepCheck_Analyzer
judges the shape, and at 1000 random (u, v) per patch the exact point from
`pdeshape sample` is compared with OCCT's point of the read face at the same (u, v) (that
distance bounds the distance to the face; GeomAPI_ProjectPointOnSurf confirms it at every
tenth point): it must be within the tolerance the fit was held to.

The CLI binary is $PDESHAPE_BIN, else target/release/pdeshape or target/debug/pdeshape.
"""

import os
import re
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from OCP.BRep import BRep_Tool
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.GeomAbs import GeomAbs_BSplineSurface
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_Reader
from OCP.TopAbs import TopAbs_FACE, TopAbs_SHELL
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.gp import gp_Pnt

ROOT = Path(__file__).resolve().parents[4]

# example: faces (patches and the drawn parts of primary surfaces); representative kinds:
# a 4th-order PDE patch through creased polylines (kinks found by the fit), a blend, the
# 40th-order Klein bottle (closed in v), N-sided fills (C0 corners, a pole), the dolphin
# (a trimmed body with fins standing on its holes)
CASES = {
    "dolphin": 5,
    "four-curve-patch": 1,
    "bloor-wilson-blend": 3,
    "klein-bottle": 1,
    "fill-sphere-pentagon": 6,
    "fill-wing-root": 7,
}

REPORT = re.compile(r"face (\S+): B-spline (\d+) × (\d+) control points, measured deviation (\S+) ≤ (\S+)")


def cli():
    env = os.environ.get("PDESHAPE_BIN")
    candidates = [Path(env)] if env else [ROOT / "target/release/pdeshape", ROOT / "target/debug/pdeshape"]
    for c in candidates:
        if c.is_file():
            return str(c)
    pytest.fail(f"no pdeshape binary at {candidates}: run `cargo build` first or set PDESHAPE_BIN")


def build(name, tmp_path, *extra):
    out = tmp_path / f"{name}.step"
    r = subprocess.run(
        [cli(), "build", str(ROOT / "examples" / f"{name}.toml"), "-o", str(out), *extra],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    fits = {m[0]: (int(m[1]), int(m[2]), float(m[3]), float(m[4])) for m in REPORT.findall(r.stderr)}
    return out, fits


def read(path):
    reader = STEPControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_RetDone
    assert reader.TransferRoots() > 0
    return reader.OneShape()


def faces(shape):
    out = []
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        out.append(TopoDS.Face(ex.Current()))
        ex.Next()
    return out


def count(shape, kind):
    ex, n = TopExp_Explorer(shape, kind), 0
    while ex.More():
        n += 1
        ex.Next()
    return n


def sample(name, patch, uv):
    text = "u,v\n" + "\n".join(f"{float(u)!r},{float(v)!r}" for u, v in uv)
    r = subprocess.run(
        [cli(), "sample", str(ROOT / "examples" / f"{name}.toml"), "--patch", patch],
        input=text,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    rows = np.loadtxt(r.stdout.splitlines()[1:], delimiter=",")
    return rows[:, 2:5]


@pytest.mark.parametrize("name", sorted(CASES))
def test_step_reads_back_valid_and_within_the_tolerance(name, tmp_path):
    t0 = time.perf_counter()
    path, fits = build(name, tmp_path)
    t1 = time.perf_counter()
    shape = read(path)
    fs = faces(shape)
    assert len(fs) == CASES[name] == len(fits), (len(fs), fits)
    analyzer = BRepCheck_Analyzer(shape)
    assert analyzer.IsValid(), f"{name}: BRepCheck_Analyzer says invalid"
    assert count(shape, TopAbs_SHELL) >= 1
    rng = np.random.default_rng(7)
    for face, (patch, (nu, nv, deviation, tol)) in zip(fs, fits.items()):
        assert deviation <= tol
        adaptor = BRepAdaptor_Surface(face)
        assert adaptor.GetType() == GeomAbs_BSplineSurface
        bs = adaptor.BSpline()
        # a surface closed in v is read as periodic, its repeated seam row dropped
        assert (bs.NbUPoles(), bs.NbVPoles() + bs.IsVPeriodic()) == (nu, nv)
        surf = BRep_Tool.Surface_s(face)
        u0, u1, v0, v1 = surf.Bounds()
        assert (u0, u1) == (0.0, 1.0)
        uv = np.column_stack([rng.random(1000), v0 + (v1 - v0) * rng.random(1000)])
        exact = sample(name, patch, uv)
        worst = 0.0
        for k, ((u, v), x) in enumerate(zip(uv, exact)):
            # the deviation at the same (u, v) (OCCT's evaluation of the read surface)
            # bounds the distance to the face from above: it is the figure checked at every
            # point; the projection itself (slow on large nets) at every tenth
            p = surf.Value(float(u), float(v))
            d_param = float(np.linalg.norm(np.array([p.X(), p.Y(), p.Z()]) - x))
            assert not np.isnan(d_param)
            worst = max(worst, d_param)
            if k % 10 == 0:
                # OCCT's projection, searched within 5 % of the ranges around (u, v): over
                # the whole surface its extremum search can settle on the far side of a
                # thin face (the wing at its trailing edge: 1.2e-4 found, 6.4e-8 at (u, v))
                du, dv = 0.05 * (u1 - u0), 0.05 * (v1 - v0)
                box = (max(u0, u - du), min(u1, u + du), max(v0, v - dv), min(v1, v + dv))
                proj = GeomAPI_ProjectPointOnSurf(gp_Pnt(*map(float, x)), surf, *map(float, box), 1e-12)
                assert proj.NbPoints() > 0
                assert proj.LowerDistance() <= d_param + 1e-12
        # the measured maximum agrees with random points (the
        # report prints it to 3 digits: 0.5 % rounding)
        assert worst <= tol, (name, patch, worst, tol)
        assert worst <= deviation * 1.005, (name, patch, worst, deviation)
    print(f"{name}: build {t1 - t0:.2f} s, check {time.perf_counter() - t1:.2f} s")


def test_a_tighter_tolerance_gives_a_finer_net_still_within_it(tmp_path):
    _, loose = build("bloor-wilson-blend", tmp_path)
    path, tight = build("bloor-wilson-blend", tmp_path, "--tolerance", "1e-8")
    (nu0, nv0, _, _), (nu1, nv1, dev, tol) = loose["blend"], tight["blend"]
    assert tol == 1e-8 and dev <= 1e-8
    assert nu1 * nv1 > nu0 * nv0
    assert BRepCheck_Analyzer(read(path)).IsValid()


def normals(face, u, vs):
    from OCP.GeomLProp import GeomLProp_SLProps

    surf = BRep_Tool.Surface_s(face)
    out = []
    for v in vs:
        props = GeomLProp_SLProps(surf, float(u), float(v), 1, 1e-12)
        assert props.IsNormalDefined()
        n = props.Normal()
        out.append([n.X(), n.Y(), n.Z()])
    return np.array(out)


@pytest.mark.parametrize(
    "name, patch, u, surface, su",
    [
        ("bloor-wilson-blend", "blend", 0.0, "surface-cylinder", 0.0),
        ("dynamic-elliptic-cylinders", "blend", 0.0, "surface-top", 1.0),
        ("dynamic-elliptic-cylinders", "blend", 1.0, "surface-bottom", 0.0),
    ],
)
def test_a_c1_blend_stays_g1_with_its_surfaces_after_export(name, patch, u, surface, su, tmp_path):
    """The blend's edge and its primary surface's edge share v knots and interpolate the
    same position and (parallel) cross derivatives, so the faces OCCT reads meet G1: the
    normal lines' angle at 200 points along the seam, computed by OCCT, is ≤ 1e-12 rad."""
    path, fits = build(name, tmp_path)
    shape = read(path)
    # the blend and its two surfaces share their seam edges: one connected shell
    assert count(shape, TopAbs_SHELL) == 1 and BRepCheck_Analyzer(shape).IsValid()
    fs = dict(zip(fits, faces(shape)))
    v0, v1 = BRep_Tool.Surface_s(fs[patch]).Bounds()[2:]
    vs = np.linspace(v0, v1, 200)
    na, nb = normals(fs[patch], u, vs), normals(fs[surface], su, vs)
    angle = np.arcsin(np.clip(np.linalg.norm(np.cross(na, nb), axis=1), 0, 1))
    assert np.isfinite(angle).all()
    print(f"{name} {patch}-{surface}: largest normal-line angle {angle.max():.2e} rad")
    # OCCT's own normals of the read faces: round-off (measured 4.2e-15 … 1.4e-14)
    assert angle.max() <= 1e-12, angle.max()
    pa = np.array([[p.X(), p.Y(), p.Z()] for p in (BRep_Tool.Surface_s(fs[patch]).Value(u, float(v)) for v in vs)])
    pb = np.array([[p.X(), p.Y(), p.Z()] for p in (BRep_Tool.Surface_s(fs[surface]).Value(su, float(v)) for v in vs)])
    assert np.linalg.norm(pa - pb, axis=1).max() <= 1e-12 * (1 + np.abs(pa).max())


def test_a_trimmed_patch_is_a_face_with_its_hole(tmp_path):
    """trim-circle: the patch minus the disc |(u, v) − (0.5, 0.5)| < 0.22 (the scene's
    defaults). OCCT reads one valid face with an outer and an inner wire; its classifier
    puts (u, v) inside the disc OUT of the face and points away from it IN."""
    from OCP.BRepClass import BRepClass_FaceClassifier
    from OCP.TopAbs import TopAbs_IN, TopAbs_OUT, TopAbs_WIRE
    from OCP.gp import gp_Pnt2d

    path, fits = build("trim-circle", tmp_path)
    shape = read(path)
    assert BRepCheck_Analyzer(shape).IsValid()
    (face,) = faces(shape)
    assert count(face, TopAbs_WIRE) == 2
    rng = np.random.default_rng(3)
    checked = 0
    for u, v in rng.random((400, 2)):
        r = np.hypot(u - 0.5, v - 0.5)
        if abs(r - 0.22) < 0.01:
            continue  # near the trim curve
        state = BRepClass_FaceClassifier(face, gp_Pnt2d(float(u), float(v)), 1e-9).State()
        assert state == (TopAbs_OUT if r < 0.22 else TopAbs_IN), (u, v, r)
        checked += 1
    assert checked > 300
    # the hole's edge carries its pcurve: the trim circle in (u, v), to the face's
    # tolerance over its largest |S_u| + |S_v| (about 1e-6 here)
    from OCP.TopAbs import TopAbs_EDGE

    ex = TopExp_Explorer(face, TopAbs_EDGE)
    radii = []
    while ex.More():
        edge = TopoDS.Edge(ex.Current())
        from OCP.BRepAdaptor import BRepAdaptor_Curve2d

        c2d = BRepAdaptor_Curve2d(edge, face)
        pts = [c2d.Value(float(t)) for t in np.linspace(c2d.FirstParameter(), c2d.LastParameter(), 400)]
        r = np.array([np.hypot(p.X() - 0.5, p.Y() - 0.5) for p in pts])
        if abs(r.mean() - 0.22) < 0.01:
            radii.append(r)
        ex.Next()
    assert len(radii) == 1
    print(f"trim-circle pcurve: max |r − 0.22| = {np.abs(radii[0] - 0.22).max():.2e}")
    assert np.abs(radii[0] - 0.22).max() <= 1e-5, np.abs(radii[0] - 0.22).max()


# solid blends: the faces that bound them, each with the solid's parameters that are the
# face's (u, v) (a periodic v of the solid is every face's v)
SOLIDS = {
    "solid-cylinders": {"solid-u1": ("w", "v"), "solid-w0": ("u", "v"), "solid-w1": ("u", "v")},
    "solid-cubes": {
        "solid-u0": ("v", "w"),
        "solid-u1": ("v", "w"),
        "solid-v0": ("w", "u"),
        "solid-v1": ("w", "u"),
        "solid-w0": ("u", "v"),
        "solid-w1": ("u", "v"),
    },
}


def sample_solid(name, uvw):
    text = "u,v,w\n" + "\n".join(",".join(repr(float(x)) for x in row) for row in uvw)
    r = subprocess.run(
        [cli(), "sample", str(ROOT / "examples" / f"{name}.toml")],
        input=text,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    return np.loadtxt(r.stdout.splitlines()[1:], delimiter=",")[:, 3:6]


@pytest.mark.parametrize("name", sorted(SOLIDS))
def test_a_solid_blend_is_a_closed_valid_solid_with_its_volume(name, tmp_path):
    """The faces that bound the solid share their edges (common knots per direction of the
    solid): OCCT reads one valid solid in one closed shell, its faces within the
    tolerance of the exact boundary (1000 random points each), and GProp's volume within
    the fit's reach of pdeshape's (∫ det J by Gauss–Legendre): |ΔV| ≤ tolerance × area."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_SOLID
    import json

    path, fits = build(name, tmp_path)
    shape = read(path)
    assert BRepCheck_Analyzer(shape).IsValid()
    assert count(shape, TopAbs_SOLID) == 1 and count(shape, TopAbs_SHELL) == 1
    shell = TopExp_Explorer(shape, TopAbs_SHELL).Current()
    assert BRep_Tool.IsClosed_s(shell)
    fs = faces(shape)
    assert list(fits) == list(SOLIDS[name]) and len(fs) == len(fits)
    rng = np.random.default_rng(11)
    for face, (label, (nu, nv, deviation, tol)) in zip(fs, fits.items()):
        assert deviation <= tol
        surf = BRep_Tool.Surface_s(face)
        u0, u1, v0, v1 = surf.Bounds()
        st = np.column_stack([rng.random(1000), v0 + (v1 - v0) * rng.random(1000)])
        axis, value = label.split("-")[1][0], float(label.split("-")[1][1])
        uvw = np.zeros((1000, 3))
        names = "uvw"
        uvw[:, names.index(axis)] = value
        for k, d in enumerate(SOLIDS[name][label]):
            uvw[:, names.index(d)] = st[:, k]
        exact = sample_solid(name, uvw)
        worst = 0.0
        for (s, t), x in zip(st, exact):
            p = surf.Value(float(s), float(t))
            d = float(np.linalg.norm(np.array([p.X(), p.Y(), p.Z()]) - x))
            assert not np.isnan(d)
            worst = max(worst, d)
        assert worst <= tol, (name, label, worst, tol)
    props, area = GProp_GProps(), GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    BRepGProp.SurfaceProperties_s(shape, area)
    r = subprocess.run([cli(), "check", "--json", str(ROOT / "examples" / f"{name}.toml")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    volume = json.loads(r.stdout)["patches"][0]["mass_properties"]["volume"]
    # outward faces: a positive volume; the fitted faces lie within `tol` of the exact
    # boundary, so the volumes differ by at most tol × area (plus GProp's own integration
    # error, 1e-9 relative)
    tol = max(f[3] for f in fits.values())
    assert props.Mass() > 0
    assert abs(props.Mass() - volume) <= tol * area.Mass() + 1e-9 * volume, (props.Mass(), volume)


def test_the_dolphin_is_one_shell_with_the_fins_on_the_body(tmp_path):
    """Each fin's root is its boundary isocurve u = 0, and the body's hole there is that
    same edge: OCCT reads one valid shell in which each of the three root edges bounds two
    faces (the body and a fin), and the body's face has its outer wire and three holes."""
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_WIRE

    def edges(face):
        out, ex = [], TopExp_Explorer(face, TopAbs_EDGE)
        while ex.More():
            out.append(ex.Current())
            ex.Next()
        return out

    path, fits = build("dolphin", tmp_path)
    shape = read(path)
    assert BRepCheck_Analyzer(shape).IsValid()
    assert count(shape, TopAbs_SHELL) == 1
    fs = dict(zip(fits, faces(shape)))
    assert count(fs["body"], TopAbs_WIRE) == 4
    body = edges(fs["body"])
    for fin in ["dorsal", "right_fin", "left_fin"]:
        shared = {i for i, e in enumerate(body) for g in edges(fs[fin]) if e.IsSame(g)}
        assert len(shared) == 1, (fin, shared)


def curvatures(face, u, vs):
    """(Gaussian, |mean|) curvature of a read face at (u, v) for each v, computed by OCCT."""
    from OCP.GeomLProp import GeomLProp_SLProps

    surf = BRep_Tool.Surface_s(face)
    out = []
    for v in vs:
        props = GeomLProp_SLProps(surf, float(u), float(v), 2, 1e-12)
        assert props.IsCurvatureDefined()
        out.append([props.GaussianCurvature(), abs(props.MeanCurvature())])
    return np.array(out)


def test_degree_five_keeps_a_c2_blend_curvature_continuous(tmp_path):
    """blend-cone-cylinder's 6th-order blend o6 meets its cone and cylinder C2. Quintic
    faces interpolate the second cross derivative at their edges too, so OCCT's Gaussian
    and mean curvature of the blend and of each surface agree along both seams (two
    surfaces that meet G2 have one second fundamental form there); bicubic faces do not."""
    gaps = {}
    for degree in ["3", "5"]:
        path, fits = build("blend-cone-cylinder", tmp_path, "--degree", degree)
        shape = read(path)
        assert BRepCheck_Analyzer(shape).IsValid()
        fs = dict(zip(fits, faces(shape)))
        if degree == "5":
            assert BRep_Tool.Surface_s(fs["o6"]).UDegree() == 5
        worst = 0.0
        for u, surface, su in [(0.0, "surface-cone", 0.0), (1.0, "surface-cylinder", 0.0)]:
            v0, v1 = BRep_Tool.Surface_s(fs["o6"]).Bounds()[2:]
            vs = np.linspace(v0, v1, 100)
            a, b = curvatures(fs["o6"], u, vs), curvatures(fs[surface], su, vs)
            scale = 1.0 + np.abs(a).max()
            worst = max(worst, float(np.abs(a - b).max() / scale))
        gaps[degree] = worst
    print(f"blend-cone-cylinder o6 seams, relative curvature gap by degree: {gaps}")
    # measured: 1e-3 … 1e-2 with degree 3, round-off (1e-13) with degree 5
    assert gaps["5"] <= 1e-9, gaps
    assert gaps["3"] >= 1e-5, gaps
