"""`pdeshape fill-holes --order 6` on the bench's meshes (those of `cgal_mesh_holes.py`,
the same holes) at 1, 2 and 4 times its resolution: the fill's largest and root-mean-square
distance to the true surface, by refinement.

Where the distance falls as the mesh is refined, the collar (the surface estimated from the
vertices around the hole) limits the fill; where it stops falling, the fill itself does (a
PDE surface through the collar's data is not the sphere, the torus or the height field).

    python crates/pdeshape-io/bench/mesh_refinement.py    # the same venv as cgal_mesh_holes.py
"""

import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cgal_mesh_holes as bench  # noqa: E402  (its meshes, readers and measures)


def main():
    print("| mesh | resolution | new vertices | largest distance | rms distance | seam dihedral (rad) |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        obj, out = Path(tmp) / "in.obj", Path(tmp) / "out.obj"
        rows = []
        for k in (1, 2, 4):
            for name, v, f, dist, max_edges in bench.bench_models(k):
                bench.write_obj(obj, v, f)
                args = [str(bench.EXE), "-q", "fill-holes", str(obj), "-o", str(out), "--order", "6"]
                if max_edges:
                    # the height field's outer rim stays open
                    args += ["--max-edges", max_edges]
                subprocess.run(args, check=True)
                pv, pf = bench.read_obj(out)
                m = bench.measure(v, f, pv, pf, dist)
                rows.append((name, k, m))
        for name, k, m in sorted(rows, key=lambda r: (r[0], r[1])):
            print(f"| {name} | {k}× | {m[0]} | {m[1]:.2e} | {m[2]:.2e} | {m[3]:.3f} |")


if __name__ == "__main__":
    main()
