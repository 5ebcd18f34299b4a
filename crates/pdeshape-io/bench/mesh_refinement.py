"""`pdeshape fill-holes --order 6` on the bench's torus and height field (the meshes of
`cgal_mesh_holes.py`, same holes) at 1, 2 and 4 times the bench's resolution: the fill's
largest and root-mean-square distance to the true surface, by refinement.

Where the distance falls as the mesh is refined, the collar (the surface estimated from the
vertices around the hole) limits the fill; where it stops falling, the fill itself does (a
PDE surface through the collar's data is not the torus).

    python crates/pdeshape-io/bench/mesh_refinement.py    # the same venv as cgal_mesh_holes.py
"""

import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cgal_mesh_holes as bench  # noqa: E402  (its meshes, readers and measures)


def torus_keep(c):
    return np.all([np.linalg.norm(c - np.array(p), axis=1) > 0.3 for p in ([1.0, 0.0, 0.4], [-0.6, 0.8 * 1.4, 0.0])],
                  axis=0)


def torus_distance(p):
    return np.abs(np.hypot(np.hypot(p[:, 0], p[:, 1]) - 1.0, p[:, 2]) - 0.4)


def field_keep(c):
    return (c[:, 0] / 0.45) ** 2 + (c[:, 1] / 0.3) ** 2 >= 1


def field_distance(p):
    return np.abs(p[:, 2] - bench.height(p[:, 0], p[:, 1]))


def main():
    print("| mesh | resolution | new vertices | largest distance | rms distance | seam dihedral (rad) |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        obj, out = Path(tmp) / "in.obj", Path(tmp) / "out.obj"
        for name, make, keep, dist, max_edges in (
            ("torus", lambda k: bench.torus(128 * k, 64 * k), torus_keep, torus_distance, None),
            ("height field", lambda k: bench.field(80 * k), field_keep, field_distance, 200),
        ):
            for k in (1, 2, 4):
                v, f = bench.cut(*make(k), keep)
                bench.write_obj(obj, v, f)
                args = [str(bench.EXE), "-q", "fill-holes", str(obj), "-o", str(out), "--order", "6"]
                if max_edges:
                    # the height field's outer rim stays open
                    args += ["--max-edges", str(max_edges * k)]
                subprocess.run(args, check=True)
                pv, pf = bench.read_obj(out)
                m = bench.measure(v, f, pv, pf, dist)
                print(f"| {name} | {k}× | {m[0]} | {m[1]:.2e} | {m[2]:.2e} | {m[3]:.3f} |")


if __name__ == "__main__":
    main()
