"""One large hole, CGAL's `triangulate_refine_and_fair_hole` and `pdeshape fill-holes --order 6`
side by side in one run: the mission's "holes of up to 2 000 border edges".

The mesh is `cgal_mesh_holes.py`'s height field z = 0.3 (x² − ½ y²) + 0.1 x y on a K × K grid
of [−1, 1]², without an elliptical hole of semi-axes A and B; the outer rim (4 K edges) is
left open by both (`--max-edges 4K−1`). Printed: the border edges, then for each tool its time
(CGAL: its calls in this process; pdeshape: the whole command on one core, reading and writing
the OBJ) and the measures of `cgal_mesh_holes.measure` (new vertices, largest and rms distance
of the new vertices to the true surface, seam dihedral, the mesh's p99, input vertices).

    python crates/pdeshape-io/bench/cgal_big_hole.py 160 0.45 0.3   # a hole of 226 edges
    python crates/pdeshape-io/bench/cgal_big_hole.py 320 0.6 0.5    # 686 edges
    python crates/pdeshape-io/bench/cgal_big_hole.py 640 0.6 0.5    # 1 354 edges (minutes)
"""

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cgal_mesh_holes import EXE, border, cgal_fill, cut, field, height, measure, read_obj, write_obj, write_off  # noqa: E402


def main():
    k, a, b = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
    v, f = cut(*field(k), lambda c: (c[:, 0] / a) ** 2 + (c[:, 1] / b) ** 2 >= 1)
    print("vertices", len(v), "border edges (rim and hole)", len(border(f)), "rim", 4 * k)
    dist = lambda p: np.abs(p[:, 2] - height(p[:, 0], p[:, 1]))  # noqa: E731
    max_edges = str(4 * k - 1)
    with tempfile.TemporaryDirectory() as tmp:
        obj, off, out = Path(tmp) / "in.obj", Path(tmp) / "in.off", Path(tmp) / "out.obj"
        write_obj(obj, v, f)
        write_off(off, v, f)
        dt, (cv, cf) = cgal_fill(off, max_edges)
        print(f"CGAL {dt:.3f} s", measure(v, f, cv, cf, dist))
        args = ["taskset", "-c", "0", str(EXE), "-q", "fill-holes", str(obj), "-o", str(out), "--order", "6",
                "--max-edges", max_edges]
        t0 = time.perf_counter()
        subprocess.run(args, check=True, env={**os.environ, "RAYON_NUM_THREADS": "1"})
        dt = time.perf_counter() - t0
        pv, pf = read_obj(out)
        print(f"pdeshape {dt:.3f} s", measure(v, f, pv, pf, dist))


if __name__ == "__main__":
    main()
