"""Python against Rust, in one run: 10⁵ scattered points on the Klein bottle and the
Bloor–Wilson blend, values, one thread, through `Patch.evaluate` and through the Rust
loop it wraps (`Surface::points_at`, the example `scattered_timing`), alternated.

    cargo build --release -p pdeshape-bench --example scattered_timing
    python crates/pdeshape-py/bench/overhead.py [--rounds 5]

Both take the same low-discrepancy points (u = frac(kφ₁), v = V frac(kφ₂)); each Rust
round is the median of its 5 calls, each Python round the median of 5 calls; the table
gives the medians over the rounds and their ratio.
"""

import argparse
import os
import re
import statistics
import subprocess
import time
from pathlib import Path

os.environ["RAYON_NUM_THREADS"] = "1"  # the module's pool, before it starts

import numpy as np  # noqa: E402

import pdeshape  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ["klein-bottle.toml", "bloor-wilson-blend.toml"]
N = 100_000


def python_round(patch) -> float:
    start, end, _ = patch.v_domain
    k = np.arange(N, dtype=np.float64)
    uv = np.column_stack([np.modf(k * 0.7548776662466927)[0], start + (end - start) * np.modf(k * 0.5698402909980532)[0]])
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        patch.evaluate(uv)
        times.append(time.perf_counter() - t0)
    return statistics.median(times) / N * 1e6


def rust_round(binary: Path) -> dict:
    env = dict(os.environ, PDESHAPE_BATCH_ONLY="1", PDESHAPE_VALUES_ONLY="1")
    out = subprocess.run([str(binary), *EXAMPLES], env=env, capture_output=True, text=True, check=True).stdout
    found = dict(re.findall(r"^(\S+): values NaN → ([0-9.]+) µs", out, flags=re.M))
    return {name: float(found[name]) for name in EXAMPLES}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--binary", type=Path, default=ROOT / "target/release/examples/scattered_timing")
    args = ap.parse_args()
    patches = {name: pdeshape.Scene.load(ROOT / "examples" / name).patches[0] for name in EXAMPLES}
    for p in patches.values():
        p.evaluate(np.array([[0.5, 0.5]]))  # warm-up: the folded modes are made once
    py = {name: [] for name in EXAMPLES}
    rs = {name: [] for name in EXAMPLES}
    for _ in range(args.rounds):
        for name, x in rust_round(args.binary).items():
            rs[name].append(x)
        for name, p in patches.items():
            py[name].append(python_round(p))
    print("| 10⁵ points, values, one thread | Rust `points_at` | Python `Patch.evaluate` | ratio |")
    print("|---|---|---|---|")
    for name in EXAMPLES:
        r, p = statistics.median(rs[name]), statistics.median(py[name])
        print(f"| {name} | {r:.3f} µs a point | {p:.3f} µs | {p / r:.2f}× |")


if __name__ == "__main__":
    main()
