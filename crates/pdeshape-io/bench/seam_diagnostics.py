"""Where the seam of `fill-holes` creases: per border edge, on the bench's meshes
(`cgal_mesh_holes.py`), for one or more pdeshape binaries side by side.

For each mesh and binary: the largest distance of the new vertices to the true surface,
the largest dihedral angle across the former border edges and how many of them exceed the
input mesh's 99th percentile, the largest dihedral angle at the new interior edges (both
triangles new), and the shortest and longest new edge against the local median: the
median length of the 24 input edges whose midpoints lie nearest the new edge's midpoint
(the issue asks for new edges within 2× of the local median), with how many fall outside
[½, 2] of it.

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


def local_ratios(v0, f0, v, new_edges, k=24):
    """Each new edge's length over the median length of the `k` input edges nearest it
    (by midpoint)."""
    ie = np.array(sorted({tuple(sorted(e)) for a, b, c in f0 for e in ((a, b), (b, c), (c, a))}))
    il = np.linalg.norm(v0[ie[:, 0]] - v0[ie[:, 1]], axis=1)
    im = 0.5 * (v0[ie[:, 0]] + v0[ie[:, 1]])
    old = {tuple(x) for x in ie}
    ne = np.array(sorted(e for e in new_edges if e not in old))
    nl = np.linalg.norm(v[ne[:, 0]] - v[ne[:, 1]], axis=1)
    nm = 0.5 * (v[ne[:, 0]] + v[ne[:, 1]])
    out = np.empty(len(ne))
    for i in range(len(ne)):
        d = np.linalg.norm(im - nm[i], axis=1)
        out[i] = nl[i] / np.median(il[np.argpartition(d, k)[:k]])
    return out


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
    nl = local_ratios(v0, f0, v, new_edges)
    d = dist(v[n0:])
    outside = int(((nl < 0.5) | (nl > 2)).sum())
    return d.max(), seam.max(), int((seam > own).sum()), len(seam), own, max(inner), nl.min(), nl.max(), outside, len(nl)


def main():
    exes = sys.argv[1:] or [str(bench.EXE)]
    print("| mesh | binary | largest distance | seam | edges over p99 | p99 | inner max | new edges / local median: min, max, outside [½, 2] |")
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
                d, s, over, nb, own, inner, lo, hi, out, ne = diagnose(v, f, pv, pf, dist)
                print(f"| {name} | {exe} | {d:.2e} | {s:.4f} | {over} of {nb} | {own:.4f} | {inner:.3f} "
                      f"| {lo:.2f}, {hi:.2f}, {out} of {ne} |")


if __name__ == "__main__":
    main()
