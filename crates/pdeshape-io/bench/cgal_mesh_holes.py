"""CGAL's hole filling (`triangulate_refine_and_fair_hole`, a bi-Laplacian fairing) and
`pdeshape fill-holes --order 6` on the same holes of meshes cut from known surfaces, side
by side in one run.

Meshes (made here): the unit icosphere (5 subdivisions, 10 242 vertices) with three caps of
18°, 25° and 35° removed; a torus (R = 1, r = 0.4, 128 × 64 quads split) with two holes; a
height field z = 0.3 (x² − ½ y²) + 0.1 x y on a 81 × 81 grid with an elliptical hole.

Measured on each result: the new vertices' distance to the true surface (largest and root
mean square), the largest dihedral angle across the former border edges against the 99th
percentile of the input mesh's own dihedral angles, and the time on one core — CGAL's
calls in this process (no I/O), pdeshape's whole command (reading and writing the OBJ
included); medians of 3.

    python crates/pdeshape-io/bench/cgal_mesh_holes.py    # needs `pip install cgal numpy`
                                                            # and a release build

With `--noise SIGMA` every vertex of the holed meshes is first moved by normal deviates of
size SIGMA (seed 1), as a scan's noise; distances are still to the true surfaces.

With `--pictures DIR` the holed meshes and both fills are also written to DIR as OBJ and
drawn in zebra stripes by `pdeshape render`, and (with `pip install pillow`) put side by
side in DIR/mesh-holes.png: one row per mesh, the holed mesh, CGAL's fill and pdeshape's.
"""

import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from CGAL import CGAL_Polygon_mesh_processing as PMP
from CGAL.CGAL_Polyhedron_3 import Polyhedron_3

ROOT = Path(__file__).resolve().parents[3]
# another build to compare with: PDESHAPE_EXE=/path/to/pdeshape
EXE = Path(os.environ.get("PDESHAPE_EXE", ROOT / "target" / "release" / "pdeshape"))


def icosphere(level):
    t = (1 + 5**0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    v = [np.array(p) / np.linalg.norm(p) for p in v]
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
         [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11],
         [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    for _ in range(level):
        mid = {}

        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                p = v[a] + v[b]
                v.append(p / np.linalg.norm(p))
                mid[k] = len(v) - 1
            return mid[k]

        f = [t for a, b, c in f for t in ([a, m(a, b), m(c, a)], [b, m(b, c), m(a, b)], [c, m(c, a), m(b, c)],
                                          [m(a, b), m(b, c), m(c, a)])]
    return np.array(v), np.array(f)


def torus(nu=128, nv=64, R=1.0, r=0.4):
    u, w = np.meshgrid(np.arange(nu) * 2 * np.pi / nu, np.arange(nv) * 2 * np.pi / nv, indexing="ij")
    v = np.column_stack([((R + r * np.cos(w)) * np.cos(u)).ravel(), ((R + r * np.cos(w)) * np.sin(u)).ravel(),
                         (r * np.sin(w)).ravel()])
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a, b = (i * nv + j).ravel(), (i * nv + (j + 1) % nv).ravel()
    c, d = (((i + 1) % nu) * nv + j).ravel(), (((i + 1) % nu) * nv + (j + 1) % nv).ravel()
    return v, np.concatenate([np.column_stack([a, c, d]), np.column_stack([a, d, b])])


def height(x, y):
    return 0.3 * (x * x - 0.5 * y * y) + 0.1 * x * y


def field(k=80):
    t = np.linspace(-1, 1, k + 1)
    x, y = np.meshgrid(t, t)
    v = np.column_stack([x.ravel(), y.ravel(), height(x, y).ravel()])
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
    a = (i * (k + 1) + j).ravel()
    return v, np.concatenate([np.column_stack([a, a + 1, a + k + 2]), np.column_stack([a, a + k + 2, a + k + 1])])


def cut(v, f, keep):
    """The mesh without the triangles whose centroid `keep` rejects, unused vertices dropped."""
    f = f[keep(v[f].mean(axis=1))]
    used, f = np.unique(f, return_inverse=True)
    return v[used], f.reshape(-1, 3)


def dihedrals(v, f):
    """Angle between the two triangles' normals of every interior edge, by edge."""
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n /= np.linalg.norm(n, axis=1)[:, None]
    by = {}
    for t, (a, b, c) in enumerate(f):
        for e in ((a, b), (b, c), (c, a)):
            by.setdefault((min(e), max(e)), []).append(t)
    return {e: math.atan2(np.linalg.norm(np.cross(n[ts[0]], n[ts[1]])), n[ts[0]] @ n[ts[1]])
            for e, ts in by.items() if len(ts) == 2}


def border(f):
    count = {}
    for a, b, c in f:
        for e in ((a, b), (b, c), (c, a)):
            k = (min(e), max(e))
            count[k] = count.get(k, 0) + 1
    return [e for e, n in count.items() if n == 1]


def write_obj(path, v, f):
    with open(path, "w") as o:
        o.writelines(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in v)
        o.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in f)


def write_off(path, v, f):
    with open(path, "w") as o:
        o.write(f"OFF\n{len(v)} {len(f)} 0\n")
        o.writelines(f"{float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in v)
        o.writelines(f"3 {a} {b} {c}\n" for a, b, c in f)


def arrays(P):
    """A polyhedron's vertices and triangles at full precision."""
    v, index = [], {}
    for vh in P.vertices():
        p = vh.point()
        index[(p.x(), p.y(), p.z())] = len(v)
        v.append((p.x(), p.y(), p.z()))
    f = []
    for fh in P.facets():
        h = fh.halfedge()
        tri = []
        for _ in range(3):
            p = h.vertex().point()
            tri.append(index[(p.x(), p.y(), p.z())])
            h = h.next()
        f.append(tri)
    return np.array(v), np.array(f)


def read_obj(path):
    v, f = [], []
    for l in Path(path).read_text().split("\n"):
        w = l.split()
        if w and w[0] == "v":
            v.append(list(map(float, w[1:4])))
        elif w and w[0] == "f":
            f.append([int(x.split("/")[0]) - 1 for x in w[1:4]])
    return np.array(v), np.array(f)


def cgal_fill(off, max_edges):
    P = Polyhedron_3(str(off))
    t0 = time.perf_counter()
    borders = []
    for h in P.halfedges():
        if h.is_border():
            borders.append(h)
    # one border halfedge per hole: walk each loop once
    seen = set()
    starts = []
    for h in borders:
        k = (h.vertex().point().x(), h.vertex().point().y(), h.vertex().point().z())
        if k in seen:
            continue
        loop, g = [], h
        while True:
            p = g.vertex().point()
            loop.append((p.x(), p.y(), p.z()))
            g = g.next()
            if g == h:
                break
        seen.update(loop)
        if max_edges is None or len(loop) <= int(max_edges):
            starts.append(h)
    for h in starts:
        PMP.triangulate_refine_and_fair_hole(P, h, [], [])
    dt = time.perf_counter() - t0
    return dt, arrays(P)


def measure(v0, f0, v, f, dist):
    """Distance of the new vertices to the surface; seam dihedral against the input's p99."""
    n0 = len(v0)
    # the new vertices: those whose coordinates are not input coordinates; the seam: the
    # input's border edges that the output closed
    old = {tuple(p) for p in v0}
    new = np.array([p for p in v if tuple(p) not in old])
    d = dist(new)
    own = np.quantile(list(dihedrals(v0, f0).values()), 0.99)
    # border edges of the input, found by their coordinates in the output
    index = {tuple(p): i for i, p in enumerate(v)}
    dh = dihedrals(v, f)
    keys = (tuple(sorted((index[tuple(v0[a])], index[tuple(v0[b])]))) for a, b in border(f0))
    seam = max(dh[k] for k in keys if k in dh)
    return len(new), d.max(), math.sqrt((d * d).mean()), seam, own, n0


def bench_models(scale=1):
    """The bench's meshes: (name, vertices, faces, distance to the true surface, --max-edges).
    `scale` 2 or 4: the same holes in meshes of half or a quarter the edge length."""
    sph_v, sph_f = icosphere(5 + {1: 0, 2: 1, 4: 2}[scale])
    caps = [((0.3, 0.2, 0.9), 35), ((-0.7, 0.6, -0.2), 25), ((0.1, -0.8, -0.5), 18)]

    def sphere_keep(c):
        k = np.ones(len(c), bool)
        for d, a in caps:
            d = np.array(d) / np.linalg.norm(d)
            k &= (c / np.linalg.norm(c, axis=1)[:, None]) @ d < math.cos(math.radians(a))
        return k

    tor_v, tor_f = torus(128 * scale, 64 * scale)

    def torus_keep(c):
        k = np.ones(len(c), bool)
        for p in ([1.0, 0.0, 0.4], [-0.6, 0.8 * 1.4 / 1.0, 0.0]):
            k &= np.linalg.norm(c - np.array(p), axis=1) > 0.3
        return k

    fld_v, fld_f = field(80 * scale)
    return [
        ("sphere, 3 caps (35°, 25°, 18°)", *cut(sph_v, sph_f, sphere_keep),
         lambda p: np.abs(np.linalg.norm(p, axis=1) - 1.0), None),
        ("torus, 2 holes", *cut(tor_v, tor_f, torus_keep),
         lambda p: np.abs(np.hypot(np.hypot(p[:, 0], p[:, 1]) - 1.0, p[:, 2]) - 0.4), None),
        ("height field, elliptical hole", *cut(fld_v, fld_f, lambda c: (c[:, 0] / 0.45) ** 2 + (c[:, 1] / 0.3) ** 2 >= 1),
         lambda p: np.abs(p[:, 2] - height(p[:, 0], p[:, 1])), str(200 * scale)),
    ]


# camera (azimuth, elevation) looking into each model's first hole
VIEWS = [(33.7, 68.5), (0.0, 50.0), (35.0, 55.0)]


def pictures(out, shots):
    """Zebra pictures of every (model, method) OBJ in `shots`, and the sheet of them."""
    rows = []
    for (az, el), row in zip(VIEWS, shots):
        pngs = []
        for label, obj in row:
            png = obj.with_suffix(".png")
            subprocess.run([str(EXE), "-q", "render", str(obj), "-o", str(png), "--view", "zebra",
                            "--stripes", "10", "--width", "420", "--height", "360",
                            "--azimuth", str(az), "--elevation", str(el)], check=True)
            pngs.append((label, png))
        rows.append(pngs)
    try:
        from PIL import Image, ImageDraw
    except ImportError:
        print("pillow is not installed: the sheet is not made", file=sys.stderr)
        return
    w, h, top = 420, 360, 26
    sheet = Image.new("RGB", (3 * w, len(rows) * (h + top)), "white")
    draw = ImageDraw.Draw(sheet)
    for i, row in enumerate(rows):
        for j, (label, png) in enumerate(row):
            sheet.paste(Image.open(png).convert("RGB"), (j * w, i * (h + top) + top))
            draw.text((j * w + 10, i * (h + top) + 6), label, fill="black")
    sheet.save(out / "mesh-holes.png")
    print(f"wrote {out / 'mesh-holes.png'}", file=sys.stderr)


def main():
    shots_dir = None
    if "--pictures" in sys.argv:
        shots_dir = Path(sys.argv[sys.argv.index("--pictures") + 1])
        shots_dir.mkdir(parents=True, exist_ok=True)
    shots = []
    if not EXE.exists():
        sys.exit(f"build {EXE} first: cargo build --release")
    models = bench_models()
    if "--noise" in sys.argv:
        # every vertex moved by a normal deviate of the given size in each coordinate (a
        # scan's noise); distances are still measured to the true surface
        sigma = float(sys.argv[sys.argv.index("--noise") + 1])
        rng = np.random.default_rng(1)
        models = [(f"{name} + noise {sigma:g}", v + rng.normal(0.0, sigma, v.shape), f, dist, me)
                  for name, v, f, dist, me in models]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, v, f, dist, max_edges in models:
            obj = Path(tmp) / "in.obj"
            write_obj(obj, v, f)
            # the height field's outer rim stays open for both (`--max-edges`)
            off = Path(tmp) / "in.off"
            write_off(off, v, f)
            times = []
            for _ in range(3):
                dt, (cv, cf) = cgal_fill(off, max_edges)
                times.append(dt)
            cg = measure(v, f, cv, cf, dist) + (statistics.median(times),)
            ptimes, pout = [], Path(tmp) / "pde.obj"
            args = ["taskset", "-c", "0", str(EXE), "-q", "fill-holes", str(obj), "-o", str(pout), "--order", "6"]
            if max_edges:
                args += ["--max-edges", max_edges]
            for _ in range(3):
                t0 = time.perf_counter()
                subprocess.run(args, check=True, env={**os.environ, "RAYON_NUM_THREADS": "1"})
                ptimes.append(time.perf_counter() - t0)
            pv, pf = read_obj(pout)
            pd = measure(v, f, pv, pf, dist) + (statistics.median(ptimes),)
            rows.append((name, cg, pd))
            if shots_dir:
                k = len(rows)
                row = []
                for label, (mv, mf) in ((f"{name}: holed", (v, f)), ("CGAL (fairing)", (cv, cf)),
                                        ("pdeshape (order 6)", (pv, pf))):
                    path = shots_dir / f"{k}-{len(row)}.obj"
                    write_obj(path, mv, mf)
                    row.append((label, path))
                shots.append(row)
    print("| mesh | method | new vertices | largest distance | rms distance | seam dihedral (rad) | mesh p99 (rad) | time (s) |")
    print("|---|---|---|---|---|---|---|---|")
    for name, cg, pd in rows:
        for who, r in (("CGAL", cg), ("pdeshape order 6", pd)):
            print(f"| {name} | {who} | {r[0]} | {r[1]:.2e} | {r[2]:.2e} | {r[3]:.3f} | {r[4]:.3f} | {r[6]:.3f} |")
    if shots_dir:
        pictures(shots_dir, shots)


if __name__ == "__main__":
    main()
