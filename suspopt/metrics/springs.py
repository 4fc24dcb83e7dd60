"""Usage of the non-linear part of a Duffing suspension spring (thesis Eq 5.3, spring Eq 2.31)."""

from __future__ import annotations

import numpy as np

__all__ = ["nonlinear_spring_usage"]


def nonlinear_spring_usage(
    travel: np.ndarray, k_linear: np.ndarray | float, k_nonlinear: np.ndarray | float
) -> np.ndarray:
    """``Ratio = max_t k_nl x³ / (k_l x + k_nl x³)``, dimensionless (thesis Eq 5.3).

    The share of the spring force ``k_l x + k_nl x³`` (Eq 2.31) carried by the cubic term, at its
    largest over the record. ``travel`` ``x`` in m, ``(T,)`` or ``(P, T)``; ``k_linear`` in N/m
    and ``k_nonlinear`` in N/m³, scalars or one per design ``(P,)``. The ratio is evaluated as
    ``k_nl x² / (k_l + k_nl x²)``, equal for ``x ≠ 0``; where the cubic force is zero (``x = 0``,
    the 0/0 of Eq 5.3, or ``k_nl = 0``) it is defined as 0. Chapter 5 constrains it to 10-30 %.

    With ``k_l > 0`` and ``k_nl >= 0`` the ratio grows with ``x²``, so it is evaluated once, at
    the largest ``x²`` of each record (the same value to the last bit or so: the rounded
    ratios of two nearly equal ``x²`` may be one unit in the last place out of order), a
    NaN or infinite travel giving NaN as the ratio of every sample would.
    """
    k_l = np.asarray(k_linear, dtype=float)[..., None]
    k_nl = np.asarray(k_nonlinear, dtype=float)[..., None]
    # (a diverging design's travel of 1e160 m squares to inf: its ratio is NaN, silently)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        x2 = np.square(np.asarray(travel, dtype=float))
        if np.all(k_l > 0.0) and np.all(k_nl >= 0.0):
            x2 = np.max(x2, axis=-1, keepdims=True)
        cubic = k_nl * x2
        ratio = np.where(cubic != 0.0, cubic / (k_l + cubic), 0.0)
    return np.max(ratio, axis=-1)
