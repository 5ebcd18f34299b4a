"""Where the seam of `fill-holes` creases: per border edge, on the bench's meshes
(`cgal_mesh_holes.py`), for one or more pdeshape binaries side by side.

For each mesh and binary: the largest distance of the new vertices to the true surface,
the largest dihedral angle across the former border edges and how many of them exceed the
input mesh's 99th percentile, the largest dihedral angle at the new interior edges (both
triangles new), and the shortest and longest new edge against the median edge at the
border's vertices.

    python crates/pdeshape-io/bench/seam_diagnostics.py [BINARY ...]   # default: the release build

Needs numpy and CGAL's Python bindings only because it reuses the bench's mesh makers.
"""

import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cgal_mesh_holes as bench  # noqa: E402


def diagnose(v0, f0, v, f, dist):
    n0 = len(v0)
    # fill-holes appends: input vertices keep their indices
    assert np.array_equal(v[:n0], v0)
    own = np.quantile(list(bench.dihedrals(v0, f0).values()), 0.99)
    dh = bench.dihedrals(v, f)
    border = [tuple(sorted(e)) for e in bench.border(f0)]
    filled = [e for e in border if e in dh]
    seam = np.array([dh[e] for e in filled])
    new_tri = f[len(f0):]
    new_edges = {tuple(sorted(e)) for a, b, c in new_tri for e in ((a, b), (b, c), (c, a))}
    inner = [dh[e] for e in new_edges if e in dh and e not in set(filled)]
    bverts = {x for e in filled for x in e}
    lens = [np.linalg.norm(v0[a] - v0[b]) for a, b, c in f0 for a, b in ((a, b), (b, c), (c, a)) if a in bverts]
    h = np.median(lens)
    nl = np.array([np.linalg.norm(v[a] - v[b]) for a, b in new_edges]) / h
    d = dist(v[n0:])
    return d.max(), seam.max(), int((seam > own).sum()), len(seam), own, max(inner), nl.min(), nl.max()


def main():
    exes = sys.argv[1:] or [str(bench.EXE)]
    print("| mesh | binary | largest distance | seam | edges over p99 | p99 | inner max | new edge min/max (h) |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name, v, f, dist, max_edges in bench.bench_models():
            obj = Path(tmp) / "in.obj"
            bench.write_obj(obj, v, f)
            for exe in exes:
                out = Path(tmp) / "out.obj"
                args = [exe, "-q", "fill-holes", str(obj), "-o", str(out), "--order", "6"]
                if max_edges:
                    args += ["--max-edges", max_edges]
                subprocess.run(args, check=True)
                pv, pf = bench.read_obj(out)
                d, s, over, nb, own, inner, lo, hi = diagnose(v, f, pv, pf, dist)
                print(f"| {name} | {exe} | {d:.2e} | {s:.4f} | {over} of {nb} | {own:.4f} | {inner:.3f} | {lo:.2f} / {hi:.2f} |")


if __name__ == "__main__":
    main()
