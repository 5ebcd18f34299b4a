"""What the test modules share."""

import numpy as np


def random_params(patch, n, seed):
    """n random parameter rows inside the patch's domain."""
    rng = np.random.default_rng(seed)
    if patch.kind == "solid":
        return rng.random((n, 3))
    start, end, _ = patch.v_domain
    return np.column_stack([rng.random(n), start + (end - start) * rng.random(n)])
