"""Which signals are affine in a sample, and how: what the compiled kernel can form and reduce
itself (:mod:`suspopt.integrator.accumulators`) in a streamed evaluation.

:func:`affine_signals` probes the one signal table (:func:`suspopt.result.signal_table`) as
:func:`suspopt.streaming.recorded_rows` does, rather than describing the signals a second
time: it reads each signal on probe samples that move one source at a time (each row of the
states ``[q; q']`` and accelerations, each road height and rate) by 1 from zero, which gives
its constant and its coefficients per design; it then checks them on samples that move every
source at once, with mixed signs at the scales 1e-3, 1 and 1e3 (a clipped tyre force, a
product or a cubic spring is then caught: the prediction misses by far more than rounding),
each after a different sample (a signal that reads another instant's sample is caught too).
A signal is affine when every check agrees within 1e-12 of the terms' size, and every probe
value is finite.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from .integrator.accumulators import Accumulators, Affine

__all__ = ["affine_signals", "kernel_accumulators"]

#: Scales of the check samples (module docstring).
CHECK_SCALES = (1e-3, 1.0, 1e3, 1.0)
#: Agreement the checks ask for, relative to the size of the terms.
TOLERANCE = 1e-12


def affine_signals(
    result_of: Callable[..., object], n: int, n_u: int, P: int, names: Sequence[str]
) -> dict[str, Affine]:
    """The signals among ``names`` that are affine in a sample (module docstring), as
    :class:`~suspopt.integrator.accumulators.Affine`. ``result_of(states, accelerations, z,
    zd)`` is the Result of P designs' probe samples ``(2n, P, T)``, ``(n, P, T)`` under
    road heights and rates ``(n_u, T)`` at those samples."""
    N, C = 3 * n + 2 * n_u, len(CHECK_SCALES)
    checks = np.sin(1.0 + np.arange(N * C, dtype=float)).reshape(N, C) * np.array(CHECK_SCALES)
    # the samples: zero, then each source's unit sample, the first C each followed by a check
    unit_at = 1 + np.arange(N) + np.minimum(np.arange(N), C)
    check_at = unit_at[:C] + 1
    x = np.zeros((N, 1 + N + C))
    x[np.arange(N), unit_at] = 1.0
    x[:, check_at] = checks
    T = x.shape[1]
    rows = np.broadcast_to(x[: 3 * n, None, :], (3 * n, P, T))
    signals: Any = result_of(rows[: 2 * n], rows[2 * n :], x[3 * n : 3 * n + n_u], x[3 * n + n_u :])
    found = {}
    for name in names:
        values = np.broadcast_to(np.asarray(signals[name], dtype=np.float64), (P, T))
        if not np.isfinite(values).all():
            continue
        base = values[:, 0]
        coefficients = values[:, unit_at] - base[:, None]  # (P, N)
        predicted = base[:, None] + coefficients @ checks
        size = np.abs(base)[:, None] + np.abs(coefficients) @ np.abs(checks)
        if not (np.abs(values[:, check_at] - predicted) <= TOLERANCE * size).all():
            continue
        used = np.flatnonzero((coefficients != 0).any(axis=0))
        found[name] = Affine(
            name,
            [int(i) if i < 3 * n else -(int(i) - 3 * n + 1) for i in used],
            [coefficients[:, i].copy() for i in used],
            base.copy(),
        )
    return found


def kernel_accumulators(
    result_of: Callable[..., object],
    shape: tuple[int, int, int],
    wanted: tuple[Sequence[str], Sequence[tuple[str, str | None]]],
    road: tuple[np.ndarray, np.ndarray, np.ndarray],
    step: int,
) -> Accumulators | None:
    """The :class:`~suspopt.integrator.accumulators.Accumulators` of the signals ``wanted =
    (names, (name, weighting) pairs)`` that are affine (:func:`affine_signals`), or None when
    none is. ``shape = (n, n_u, P)``; ``road = (z, zd, t_grid)``: the roads' inputs ``(n_u,
    G, 2 n_steps + 1)`` on the half-step grid and that grid [s], sampled every ``step`` half
    steps."""
    from .metrics.iso2631 import weighting_filter

    n, n_u, P = shape
    names, pairs = wanted
    affine = affine_signals(result_of, n, n_u, P, sorted(set(names) | {p for p, _ in pairs}))
    if not affine:
        return None
    signals = [affine[name] for name in sorted(affine)]
    index = {s.name: i for i, s in enumerate(signals)}
    z, zd, t_grid = road
    samples = np.arange(0, t_grid.size, step)
    fs = 1.0 / (t_grid[step] - t_grid[0])  # (the output rate, as the numpy reductions')
    keys = [(name, w) for name, w in pairs if name in index]
    filters = [(index[name], weighting_filter(w, fs)) for name, w in keys]
    zs = np.concatenate([z[:, :, samples], zd[:, :, samples]]).transpose(2, 0, 1)
    return Accumulators(signals, filters, np.ascontiguousarray(zs), fs, keys)
