"""A parameter study: how the cross-tangent length of a solid blend shapes its volume.

The solid blend of paper 000's example 2 (elliptic cylinder to circular cylinder) with the
axial cross-tangent `k` at both ends as a parameter: for each k the blend is solved again,
by `pdeshape.sweep`, its mass properties read from the diagnostics (`scene.check()`, the same report as
`pdeshape check --json`), and the volume and the smallest Jacobian (a fold where it reaches
zero) plotted against k, with the height of a point on the outer wall a quarter of the way
along (the tangent's reach).

    python examples/python/sweep.py [out.png]
"""

import sys
from typing import Dict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import pdeshape

SCENE = """
[scene]
title = "Solid blend with an adjustable cross-tangent"

[parameters]
k = { value = 2.0, min = 0.5, max = 6.0, description = "axial cross-tangent length at both ends" }

[patches.solid]
kind = "solid"
w0 = ["2*u*sin(2*pi*v)", "3*u*cos(2*pi*v)", "3"]
w0_tangent = ["-0.2*u*sin(2*pi*v)", "-0.3*u*cos(2*pi*v)", "-k"]
w1 = ["u*sin(2*pi*v)", "u*cos(2*pi*v)", "1"]
w1_tangent = ["-0.1*u*sin(2*pi*v)", "-0.1*u*cos(2*pi*v)", "-k"]
lmn = [6, 6, 6]
cells = [9, 49, 17]
"""


def measure(scene: pdeshape.Scene) -> Dict[str, float]:
    """The figures of one setting: volume and smallest Jacobian from the diagnostics, and
    the height of the outer wall's point (u, v, w) = (1, 0, 1/4)."""
    mass = scene.check()["patches"][0]["mass_properties"]
    z = scene.patches[0].evaluate(np.array([[1.0, 0.0, 0.25]]))[0, 2]
    return {"volume": mass["volume"], "min_jacobian": mass["min_jacobian"], "z_mid": float(z)}


def main(out: str = "sweep.png") -> None:
    base = pdeshape.Scene.from_toml(SCENE, "solid-sweep")
    # one solve per setting; pass executor=ProcessPoolExecutor() or a Dask Client to spread
    # the settings over processes or machines
    table = pdeshape.sweep(base, {"k": np.linspace(0.5, 6.0, 23)}, measure=measure, table="dict")
    ks, volume, min_jacobian = table["k"], table["volume"], table["min_jacobian"]

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ax1.plot(ks, volume, "o-")
    ax1.set_xlabel("cross-tangent length k")
    ax1.set_ylabel("volume")
    ax1.set_title("Volume of the solid blend")
    ax2.plot(ks, min_jacobian, "o-", label="min Jacobian")
    ax2.axhline(0, color="grey", lw=0.8)
    ax2.set_xlabel("cross-tangent length k")
    ax2.set_title("Smallest Jacobian (a fold at 0)")
    ax2b = ax2.twinx()
    ax2b.plot(ks, table["z_mid"], "s--", color="tab:red", label="z of X(1, 0, ¼)")
    ax2b.set_ylabel("z of X(1, 0, 1/4)", color="tab:red")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"wrote {out}: volume {min(volume):.3f} … {max(volume):.3f}, min Jacobian {min(min_jacobian):.3g} … {max(min_jacobian):.3g}")


if __name__ == "__main__":
    main(*sys.argv[1:])
