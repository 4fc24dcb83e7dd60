"""Damper energy and switching metrics (thesis Sec 2.4.5-2.4.6).

Signals have time on the last axis, ``(T,)`` or ``(P, T)``; results are a scalar or ``(P,)``.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "mean_dissipated_power",
    "mean_dissipated_power_from_damping",
    "damper_switches",
    "share_at_max_damping",
]


def mean_dissipated_power(
    damper_force: np.ndarray, travel_velocity: np.ndarray, t: np.ndarray
) -> np.ndarray:
    """DE: mean power dissipated by a damper in W (thesis Eq 2.92, first form).

    ``(1/t_f) ∫ F_C · ṠT dt`` with the trapezoidal rule over the time samples ``t`` (s, ``(T,)``)
    and ``t_f = t[-1] - t[0]``. ``damper_force`` in N with the sign of ``c·ṠT`` (Eq 2.32), so that
    a passive damper gives a positive power; ``travel_velocity`` in m/s.
    """
    t = np.asarray(t, dtype=float)
    power = np.asarray(damper_force, dtype=float) * np.asarray(travel_velocity, dtype=float)
    from scipy.integrate import trapezoid

    return trapezoid(power, t, axis=-1) / (t[-1] - t[0])


def mean_dissipated_power_from_damping(
    damping: np.ndarray | float, travel_velocity: np.ndarray, t: np.ndarray
) -> np.ndarray:
    """DE from the damping coefficient, ``(1/t_f) ∫ C·ṠT² dt`` in W (thesis Eq 2.92, 2nd form).

    ``damping`` in N·s/m is either the instantaneous coefficient with the shape of
    ``travel_velocity`` (m/s, ``(..., T)``) or one constant per design, shape
    ``travel_velocity.shape[:-1]`` (or a scalar).
    """
    c = np.asarray(damping, dtype=float)
    v = np.asarray(travel_velocity, dtype=float)
    if c.ndim == v.ndim - 1:
        c = c[..., None]
    return mean_dissipated_power(c * v, v, t)


def damper_switches(state: np.ndarray, tol: float = 0.0) -> np.ndarray:
    """SW: number of changes of the damper state along time (thesis Sec 2.4.6), integer.

    ``state`` is the damper's state or damping coefficient (N·s/m) per sample, ``(..., T)``. A
    change is a step between consecutive samples larger than ``tol`` (same unit as ``state``),
    so solver noise on a nominally constant coefficient is not counted. A continuously varying
    coefficient (SH-L) counts every step above ``tol``. Sec 2.4.5 glosses switches as "times that
    the damper operates with C_max"; that reading is :func:`share_at_max_damping`, while SW
    (Sec 2.4.6, Tables 4.2-4.3) is the count of state changes computed here.
    """
    steps = np.abs(np.diff(np.asarray(state, dtype=float), axis=-1))
    return np.count_nonzero(steps > tol, axis=-1)


def share_at_max_damping(
    damping: np.ndarray, c_max: np.ndarray | float, tol: float = 0.0
) -> np.ndarray:
    """Fraction (0-1) of the samples at which the damper is at ``C_max`` (thesis Sec 4.2.3).

    The thesis's "percentage of the sample operating with C_max" (``1 - N%``) that the CDF
    thresholds are tuned to.

    ``damping`` in N·s/m, ``(..., T)``; ``c_max`` in N·s/m, scalar or one per design
    ``(...)``. A sample is at ``C_max`` when ``|C - C_max| <= tol`` (N·s/m). With the
    simulator's fixed step the sample share is the share of time.
    """
    c = np.asarray(damping, dtype=float)
    c_max = np.asarray(c_max, dtype=float)[..., None]
    return np.mean(np.abs(c - c_max) <= tol, axis=-1)
