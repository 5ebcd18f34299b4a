"""pdeshape's measured B-spline fit beside OpenCASCADE's GeomAPI_PointsToBSplineSurface on
the same number of samples (BENCHMARKS.md, issue 18).

For each face: pdeshape's fit at the default tolerance (1e-6 × the face's bounding-box
diagonal) gives a net of nu × nv control points; OCCT approximates a uniform nu × nv grid
of exact points (`pdeshape sample`) with Tol3D = the same tolerance (degree 3 … 8, C2).
Both surfaces are then measured against 4000 random exact points by projection
(GeomAPI_ProjectPointOnSurf): the largest distance found. OCCT guarantees its tolerance at
its samples only; pdeshape's figure is the measured maximum over every knot cell.

    python crates/pdeshape-io/bench/occt_fit.py   # needs cadquery-ocp and target/release/pdeshape
"""

import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.GeomAbs import GeomAbs_C2
from OCP.GeomAPI import GeomAPI_PointsToBSplineSurface, GeomAPI_ProjectPointOnSurf
from OCP.STEPControl import STEPControl_Reader
from OCP.OCP.collections import Array2_gp_Pnt as TColgp_Array2OfPnt
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.gp import gp_Pnt

ROOT = Path(__file__).resolve().parents[3]
BIN = str(ROOT / "target/release/pdeshape")
CASES = [("bloor-wilson-blend", "blend"), ("four-curve-patch", "sheet"), ("dolphin", "body"), ("fill-sphere-pentagon", "cap")]
REPORT = re.compile(r"face (\S+): B-spline (\d+) × (\d+) control points, measured deviation (\S+) ≤ (\S+)")


def sample(scene, patch, uv):
    text = "u,v\n" + "\n".join(f"{float(u)!r},{float(v)!r}" for u, v in uv)
    r = subprocess.run([BIN, "sample", scene, "--patch", patch], input=text, capture_output=True, text=True, check=True)
    return np.loadtxt(r.stdout.splitlines()[1:], delimiter=",")[:, 2:5]


def worst_distance(surf, pts):
    worst = 0.0
    for x in pts:
        proj = GeomAPI_ProjectPointOnSurf(gp_Pnt(*map(float, x)), surf)
        d = proj.LowerDistance() if proj.NbPoints() > 0 else float("nan")
        worst = max(worst, d) if not np.isnan(d) else float("nan")
    return worst


def main():
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, patch in CASES:
            scene = str(ROOT / "examples" / f"{name}.toml")
            out = Path(tmp) / f"{name}.step"
            r = subprocess.run([BIN, "build", scene, "-o", str(out)], capture_output=True, text=True, check=True)
            fits = {m[0]: m[1:] for m in REPORT.findall(r.stderr)}
            nu, nv, dev, tol = int(fits[patch][0]), int(fits[patch][1]), float(fits[patch][2]), float(fits[patch][3])
            reader = STEPControl_Reader()
            reader.ReadFile(str(out))
            reader.TransferRoots()
            ex = TopExp_Explorer(reader.OneShape(), TopAbs_FACE)
            names = list(fits)
            ours = None
            k = 0
            while ex.More():
                if names[k] == patch:
                    ours = BRep_Tool.Surface_s(TopoDS.Face(ex.Current()))
                ex.Next()
                k += 1
            v0, v1 = ours.Bounds()[2:]
            # the same number of exact samples as our control points, on a uniform grid
            us, vs = np.linspace(0, 1, nu), np.linspace(v0, v1, nv)
            grid = sample(scene, patch, [(u, v) for u in us for v in vs]).reshape(nu, nv, 3)
            arr = TColgp_Array2OfPnt(1, nu, 1, nv)
            for i in range(nu):
                for j in range(nv):
                    arr.SetValue(i + 1, j + 1, gp_Pnt(*map(float, grid[i, j])))
            t0 = time.perf_counter()
            occ = GeomAPI_PointsToBSplineSurface(arr, 3, 8, GeomAbs_C2, tol).Surface()
            t_occ = time.perf_counter() - t0
            rng = np.random.default_rng(11)
            uv = np.column_stack([rng.random(4000), v0 + (v1 - v0) * rng.random(4000)])
            pts = sample(scene, patch, uv)
            rows.append(
                (
                    f"{name} / {patch}",
                    tol,
                    f"{nu} × {nv}",
                    dev,
                    worst_distance(ours, pts),
                    f"{occ.NbUPoles()} × {occ.NbVPoles()} (degree {occ.UDegree()}, {occ.VDegree()})",
                    t_occ * 1e3,
                    worst_distance(occ, pts),
                    out.stat().st_size,
                )
            )
    print("| face | tolerance | pdeshape net | measured max | max at 4000 random points | OCCT net | OCCT time (ms) | OCCT max at 4000 random points | STEP bytes |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]:.2e} | {r[2]} | {r[3]:.2e} | {r[4]:.2e} | {r[5]} | {r[6]:.1f} | {r[7]:.2e} | {r[8]} |")


if __name__ == "__main__":
    sys.exit(main())
