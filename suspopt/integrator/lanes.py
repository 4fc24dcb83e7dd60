"""Arrays as the compiled kernel takes them: one column per design, writable and
contiguous, so that one compiled signature serves every batch."""

from __future__ import annotations

import numpy as np

__all__ = ["padded"]


def padded(a: np.ndarray, P: int) -> np.ndarray:
    """``a (..., 1 | P0)`` over ``P >= P0`` designs, the last one repeated: a new, writable,
    contiguous array (a read-only view, as ``broadcast_to`` gives for one design, is another
    numba type: the kernel compiled again for it, a minute on a fresh machine)."""
    extra = np.repeat(a[..., -1:], P - a.shape[-1], axis=-1)
    return np.concatenate([a, extra], axis=-1)
