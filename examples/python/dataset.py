"""A dataset of shape variants: the Bloor–Wilson blend (cylinder to plane) at 10 000 random
settings of its six parameters, each with its mesh and its figures.

Each setting is drawn uniformly inside the parameters' slider ranges (seeded, so the dataset
is reproducible), solved once by `pdeshape.sweep` on a process pool, measured by
`scene.check()` (every number of its report: the conditions' errors, the modes' condition
numbers and solve paths, the remainder's residuals)
and meshed at `--resolution` into `OUT/meshes/NNNNNN.npz` (arrays `blend/vertices`,
`blend/faces`, `blend/normals`, `blend/uvs`). The table of parameters and figures goes to
`OUT/variants.parquet` when pyarrow is installed, else `OUT/variants.csv`.

    python examples/python/dataset.py OUT [--count 10000] [--workers N] [--resolution 13 49]
"""

import argparse
import os
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

import pdeshape

ROOT = Path(__file__).resolve().parents[2]


def settings(scene: pdeshape.Scene, count: int, seed: int = 20261204) -> List[Dict[str, float]]:
    """`count` settings drawn uniformly inside every slider range of the scene."""
    rng = np.random.default_rng(seed)
    ranges = {n: (p["min"], p["max"]) for n, p in scene.parameters.items() if p["min"] is not None and p["max"] is not None}
    draws = {n: lo + (hi - lo) * rng.random(count) for n, (lo, hi) in ranges.items()}
    return [{n: float(draws[n][i]) for n in ranges} for i in range(count)]


def main(argv: Optional[Sequence[str]] = None) -> Any:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path)
    ap.add_argument("--count", type=int, default=10_000)
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--resolution", type=int, nargs=2, default=(13, 49), metavar=("NU", "NV"))
    args = ap.parse_args(argv)
    scene = pdeshape.Scene.load(ROOT / "examples/bloor-wilson-blend.toml")
    variants = settings(scene, args.count)
    args.out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        table = pdeshape.sweep(
            scene,
            variants,
            executor=pool,
            meshes=args.out / "meshes",
            mesh_resolution=tuple(args.resolution),
            progress=True,
        )
    seconds = time.perf_counter() - start
    # file names relative to OUT, so the dataset can move
    table["mesh_file"] = [os.path.relpath(f, args.out) for f in table["mesh_file"]]
    try:
        path = args.out / "variants.parquet"
        table.to_parquet(path)
    except ImportError:
        path = args.out / "variants.csv"
        table.to_csv(path, index=False)
    size = sum(f.stat().st_size for f in (args.out / "meshes").glob("*.npz"))
    print(f"{len(table)} variants in {seconds:.1f} s on {args.workers} processes: {path}, meshes {size / 2**20:.1f} MiB")
    print(f"largest condition error over the variants: {table['blend.condition_error.max_rel'].max():.1e} (relative)")
    return table


if __name__ == "__main__":
    main()
