"""Statistics of signals along time, and the handling / road-holding metrics (thesis Sec 2.4.4).

Every function reduces the last (time) axis of ``(T,)`` or ``(P, T)`` samples to a scalar or
``(P,)``, in the unit of the signal (squared for variances). Sample statistics weight the samples
equally, as the thesis's sums over ``j = 1..n`` do; the simulator's fixed step makes that a time
average.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = [
    "STATISTICS",
    "moments",
    "moment_value",
    "var",
    "std",
    "rms",
    "maximum",
    "minimum",
    "max_abs",
    "mean",
    "peak_to_peak",
    "suspension_travel_variance",
    "suspension_travel_max",
    "suspension_travel_max_abs",
    "tyre_deflection_variance",
    "tyre_deflection_max",
    "tyre_deflection_max_abs",
    "pitch_variance",
    "dynamic_tyre_load_ratio",
    "peak_dynamic_tyre_load_ratio",
    "peak_tyre_force",
]


def moments(x: np.ndarray, state: tuple | None = None) -> tuple:
    """The streamed state of the samples ``x (..., T)``: ``(count, mean, M2, high, low)``, the
    arrays of shape ``x.shape[:-1]``, after ``state`` (the samples before ``x``; default
    none). One pass per row, sample by sample, by the steps every engine uses
    (:func:`suspopt.loops._compiled.welford`, :func:`~suspopt.loops._compiled.extremes`), so a
    signal cut into pieces gives the whole signal's bits and the compiled kernel, reducing the
    signals it forms itself, the same arithmetic. :func:`moment_value` makes a statistic of
    it."""
    from ..loops import compiled_reductions

    a = np.asarray(x, dtype=np.float64)
    if a.ndim == 0 or (a.shape[-1] == 0 and state is None):
        raise ValueError("the signal must have a non-empty time axis (last axis)")
    lead = a.shape[:-1]
    if state is None:
        count, kept = 0, np.zeros((4, *lead))
        kept[2], kept[3] = -np.inf, np.inf  # (the largest and smallest sample: none yet)
    else:
        count, kept = state[0], np.array(np.stack(state[1:]), dtype=np.float64)
    rows = kept.reshape(4, -1)
    flat = np.ascontiguousarray(a.reshape(-1, a.shape[-1]))
    compiled_reductions().moment_rows(flat, count, rows)  # (in place)
    kept = rows.reshape(4, *lead)
    return count + a.shape[-1], kept[0], kept[1], kept[2], kept[3]


def moment_value(statistic: str, state: tuple) -> np.ndarray:
    """The statistic ``statistic`` (a key of :data:`STATISTICS`) of the samples whose
    streamed state is ``state`` (:func:`moments`): ``var = M2 / n`` (Eq 2.87), ``std`` its
    root, ``mean``, ``rms = (var + mean²)^½``, ``max``, ``min``, ``max_abs`` the larger
    magnitude of the two, ``peak_to_peak`` their difference."""
    return np.asarray(_value(statistic, *state))[()]  # (a scalar for one signal)


def _value(statistic: str, count: int, mean, m2, high, low):
    if statistic in ("var", "std", "rms"):
        variance = m2 / count
        if statistic == "var":
            return variance
        return np.sqrt(variance if statistic == "std" else variance + np.square(mean))
    if statistic == "mean":
        return mean
    if statistic == "max":
        return high
    if statistic == "min":
        return low
    if statistic == "max_abs":
        return np.maximum(np.abs(high), np.abs(low))
    if statistic == "peak_to_peak":
        return high - low
    raise ValueError(f"no statistic {statistic!r}; available: {', '.join(STATISTICS)}")


def var(x: np.ndarray) -> np.ndarray:
    """Population variance ``(1/n) Σ (x_j - x̄)²`` along time (thesis Eq 2.87, 2.89, 2.91)."""
    return moment_value("var", moments(x))


def std(x: np.ndarray) -> np.ndarray:
    """Population standard deviation along time, the square root of :func:`var`."""
    return moment_value("std", moments(x))


def rms(x: np.ndarray) -> np.ndarray:
    """Root mean square ``[(1/n) Σ x_j²]^½`` along time (mean not removed), as
    ``(var + mean²)^½``."""
    return moment_value("rms", moments(x))


def maximum(x: np.ndarray) -> np.ndarray:
    """Largest (signed) sample along time (thesis Eq 2.88, 2.90: ``MAX``)."""
    return moment_value("max", moments(x))


def minimum(x: np.ndarray) -> np.ndarray:
    """Smallest (signed) sample along time."""
    return moment_value("min", moments(x))


def max_abs(x: np.ndarray) -> np.ndarray:
    """Largest magnitude ``max_j |x_j|`` along time."""
    return moment_value("max_abs", moments(x))


def mean(x: np.ndarray) -> np.ndarray:
    """Arithmetic mean along time."""
    return moment_value("mean", moments(x))


def peak_to_peak(x: np.ndarray) -> np.ndarray:
    """Range ``max - min`` along time."""
    return moment_value("peak_to_peak", moments(x))


STATISTICS: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "var": var,
    "std": std,
    "rms": rms,
    "max": maximum,
    "min": minimum,
    "max_abs": max_abs,
    "mean": mean,
    "peak_to_peak": peak_to_peak,
}
"""Statistic name -> function of a signal ``(..., T)`` returning ``(...)``; objectives use these
names (objectives must be configurable as var / std / rms / max of a signal, slip:
docs/thesis-slips.md#variance-units). The
functions are named ``maximum`` / ``minimum`` so that they do not shadow the builtins."""


def suspension_travel_variance(travel: np.ndarray) -> np.ndarray:
    """VST: variance of the suspension travel in m² (thesis Eq 2.87)."""
    return var(travel)


def suspension_travel_max(travel: np.ndarray) -> np.ndarray:
    """MST: maximum (signed, as printed) of the suspension travel in m (thesis Eq 2.88).

    Eq 2.88 reads ``MAX(ST_i)``; the largest excursion either way is
    :func:`suspension_travel_max_abs`.
    """
    return maximum(travel)


def suspension_travel_max_abs(travel: np.ndarray) -> np.ndarray:
    """Largest suspension travel magnitude in m, the two-sided reading of Eq 2.88."""
    return max_abs(travel)


def tyre_deflection_variance(deflection: np.ndarray) -> np.ndarray:
    """VTD: variance of the tyre deflection in m² (thesis Eq 2.89)."""
    return var(deflection)


def tyre_deflection_max(deflection: np.ndarray) -> np.ndarray:
    """MTD: maximum (signed, as printed) of the tyre deflection in m (thesis Eq 2.90)."""
    return maximum(deflection)


def tyre_deflection_max_abs(deflection: np.ndarray) -> np.ndarray:
    """Largest tyre deflection magnitude in m, the two-sided reading of Eq 2.90."""
    return max_abs(deflection)


def pitch_variance(pitch: np.ndarray) -> np.ndarray:
    """PTC: variance of the body pitch angle in rad² (thesis Eq 2.91)."""
    return var(pitch)


def dynamic_tyre_load_ratio(tyre_force: np.ndarray, static_load: np.ndarray | float) -> np.ndarray:
    """Standard deviation of the tyre force over the static wheel load, dimensionless.

    ``tyre_force`` in N, ``(..., T)``; ``static_load`` in N, scalar or ``(...)`` (one per design).
    The standard deviation ignores the mean, so the force may be the dynamic part (the thesis's
    ``k_T·TD`` about equilibrium, Eq 2.28) or the total load. The thesis scores road holding by
    tyre deflection (Eq 2.89); this is the same quantity normalised by the load it rides on.
    """
    return std(tyre_force) / np.asarray(static_load, dtype=float)


def peak_dynamic_tyre_load_ratio(
    tyre_force: np.ndarray, static_load: np.ndarray | float, includes_static: bool = False
) -> np.ndarray:
    """Largest dynamic tyre force magnitude over the static wheel load, dimensionless.

    ``tyre_force`` in N is the dynamic force about static equilibrium (Eq 2.28) unless
    ``includes_static`` is true, in which case ``static_load`` (N) is subtracted first. A ratio
    of 1 means the wheel momentarily carries no load (or twice its static load).
    """
    load = np.asarray(static_load, dtype=float)
    dynamic = np.asarray(tyre_force, dtype=float)
    if includes_static:
        dynamic = dynamic - load[..., None]
    return max_abs(dynamic) / load


def peak_tyre_force(tyre_force: np.ndarray) -> np.ndarray:
    """Largest tyre force magnitude in N along time."""
    return max_abs(tyre_force)
