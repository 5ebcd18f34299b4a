"""Overhead of the Python layer: 10⁶ exact Bloor–Wilson blend points through `Patch.evaluate`.

Compare with the Rust side, the same call on the same points:
    cargo bench -p pdeshape-bench --bench surfaces -- "evaluate/bloor-wilson"
Run both on one thread (the bench pins one; here):
    RAYON_NUM_THREADS=1 python crates/pdeshape-py/bench/evaluate.py
Prints the median of 10 runs (the array conversion included).
"""

import statistics
import time
from pathlib import Path

import numpy as np

import pdeshape

ROOT = Path(__file__).resolve().parents[3]


def main():
    patch = pdeshape.Scene.load(ROOT / "examples/bloor-wilson-blend.toml").patches[0]
    n = 1_000_000
    k = np.arange(n, dtype=np.float64)
    # u = frac(k φ₁), v = 2π frac(k φ₂): the bench's points, computed the same way
    uv = np.column_stack([np.modf(k * 0.7548776662466927)[0], 2 * np.pi * np.modf(k * 0.5698402909980532)[0]])
    patch.evaluate(uv[:1000])  # warm-up
    times = []
    for _ in range(10):
        t0 = time.perf_counter()
        out = patch.evaluate(uv)
        times.append(time.perf_counter() - t0)
    assert out.shape == (n, 3) and np.isfinite(out).all()
    print(f"Patch.evaluate, 10^6 Bloor-Wilson points: median {statistics.median(times) * 1e3:.1f} ms "
          f"(min {min(times) * 1e3:.1f}, max {max(times) * 1e3:.1f})")


if __name__ == "__main__":
    main()
