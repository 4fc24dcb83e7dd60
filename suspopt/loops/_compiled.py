"""The arithmetic of the streamed metrics, written once, compiled (through
:func:`suspopt.loops.compiled_reductions`).

Every streamed metric is reduced sample by sample by the steps below, wherever it runs: the
compiled kernel calls them for the signals it forms itself (:mod:`suspopt.integrator._accumulate`,
and the lane loop generated for a network, :func:`suspopt.integrator._accumulate.source`,
which calls them by name), and the row loops here call them for a signal held in memory: a
whole record (:mod:`suspopt.metrics.stats`, :mod:`suspopt.metrics.iso2631`) or a window of one
on the numpy engine (:mod:`suspopt.streaming`). So a metric gives the same bits from the
same samples on either engine and in any windows:

- :func:`welford`: one sample into the running mean and sum of squared deviations (Welford's
  update, ``d = x - m; m += d w; M2 += d (x - m)`` with ``w = 1 / count``), from which the
  variance, standard deviation, r.m.s. and mean follow
  (:func:`suspopt.metrics.stats.moment_value`);
- :func:`extremes`: the largest and smallest sample so far (a NaN stays, as ``np.max`` keeps
  it);
- :func:`tap` and :func:`section`: the ISO 2631-1 weighting filter
  (:class:`suspopt.weighting.WeightingFilter`): the FIR correction as its taps in their fixed
  order, then each second-order section in transposed direct form II (scipy's ``sosfilt``
  difference equations);
- :func:`powers` and :func:`carry`: the sums of ``a_w²`` and ``a_w⁴`` and the largest
  ``|a_w|`` (Eq 2.78, 2.82, 2.83), each sum kept per block of ``SUM_BLOCK`` samples and
  carried into its total at the block's end (:func:`suspopt.metrics.iso2631.weighted_value`).

The row loops :func:`moment_rows`, :func:`weight_rows` and :func:`power_rows` continue a
state given to them, so a record cut into windows gives the whole record's bits. They are
single-threaded (no ``prange``): they run in the caller's thread while the kernel may
integrate the next window on every core (:func:`suspopt.integrator._ahead`).
"""

from __future__ import annotations

import numba
import numpy as np

from .. import _numba_cache

_numba_cache.prepare()  # (cached for the machine, damaged files compiled again: suspopt._numba_cache)
_jit = numba.njit(cache=True, nogil=True)
#: A step: compiled into its caller (the kernel's lane loops vectorise through it).
_step = numba.njit(cache=True, nogil=True, inline="always")


@_step
def welford(x, w, mean, m2):
    """The running ``(mean, M2)`` after the sample ``x``, ``w = 1 / count`` (``count`` the
    samples so far, ``x`` included)."""
    d = x - mean
    mean = mean + d * w
    return mean, m2 + d * (x - mean)


@_step
def extremes(x, high, low):
    """The largest and smallest sample after ``x`` (a NaN, once met, stays)."""
    return (high if high != high or x <= high else x), (low if low != low or x >= low else x)


@_step
def tap(y, c, x):
    """One tap ``c x`` of the weighting's FIR correction added to ``y``, the taps in their
    fixed order from the newest input (``y`` starts at 0)."""
    return y + c * x


@_step
def section(u, z0, z1, b0, b1, b2, a1, a2):
    """One second-order section ``[b0, b1, b2, 1, a1, a2]`` in transposed direct form II:
    ``(output, state 0, state 1)`` after the input ``u``."""
    x = b0 * u + z0
    return x, b1 * u - a1 * x + z1, b2 * u - a2 * x


@_step
def powers(a, squares, fourth, peak):
    """The running sums of ``a²`` and ``a⁴`` and the largest ``|a|`` after the weighted
    sample ``a`` (a NaN stays the largest)."""
    sq = a * a
    size = abs(a)
    return squares + sq, fourth + sq * sq, (peak if peak != peak or size <= peak else size)


@_step
def carry(part, total):
    """A block's sum carried into the total: ``(0, total + part)``."""
    return 0.0, total + part


#: Rows the filter takes at once: their samples side by side, time-major, so that each
#: operation runs over the lanes (the compiler vectorises it) while each lane's recursion
#: keeps its own order (a row filtered alone waits on its sections' chain at every sample).
LANES = 32


@_jit
def weight_rows(numerator, sections, a, history, poles, out):
    """The weighting filter over the rows of ``a (R, T)`` into ``out (R, T)``: the FIR
    ``numerator (M + 1,)`` with the last ``M`` inputs before ``a`` in ``history (R, M)``, then
    the ``sections (S, 6)`` with their states ``poles (S, R, 2)``; ``history`` and ``poles``
    are left as the filter's state after ``a``. Rows go :data:`LANES` at a time, or all
    together when there are fewer (the scratch is then no larger than ``a``: a single long
    record does not take 32 times its size); the last lanes of the last group carry an
    earlier group's finite values, never written out."""
    R, T = a.shape
    M, S, C = numerator.shape[0] - 1, sections.shape[0], min(LANES, R)
    x = np.zeros((M + T, C))  # the group's inputs, its history first
    y = np.zeros((T, C))
    z = np.zeros((S, 2, C))
    for r0 in range(0, R, C):
        c = min(C, R - r0)
        for i in range(c):
            for k in range(M):
                x[k, i] = history[r0 + i, k]
            for t in range(T):
                x[M + t, i] = a[r0 + i, t]
            for s in range(S):
                z[s, 0, i] = poles[s, r0 + i, 0]
                z[s, 1, i] = poles[s, r0 + i, 1]
        for t in range(T):
            for i in range(C):
                y[t, i] = tap(0.0, numerator[0], x[M + t, i])
            for k in range(1, M + 1):
                for i in range(C):
                    y[t, i] = tap(y[t, i], numerator[k], x[M + t - k, i])
            for s in range(S):
                b0, b1, b2 = sections[s, 0], sections[s, 1], sections[s, 2]
                a1, a2 = sections[s, 4], sections[s, 5]
                for i in range(C):
                    y[t, i], z[s, 0, i], z[s, 1, i] = section(
                        y[t, i], z[s, 0, i], z[s, 1, i], b0, b1, b2, a1, a2
                    )
        for i in range(c):
            for t in range(T):
                out[r0 + i, t] = y[t, i]
            for k in range(M):
                history[r0 + i, k] = x[T + k, i]
            for s in range(S):
                poles[s, r0 + i, 0] = z[s, 0, i]
                poles[s, r0 + i, 1] = z[s, 1, i]


@_jit
def _lanes(a, r0, c, scratch):
    """Rows ``r0 .. r0 + c`` of ``a (R, T)`` into the time-major ``scratch (T, C)``."""
    for i in range(c):
        for t in range(a.shape[1]):
            scratch[t, i] = a[r0 + i, t]


@_jit
def _load(rows, r0, c, state):
    """Columns ``r0 .. r0 + c`` of ``rows (Q, R)`` into ``state (Q, C)``; the spare lanes
    of a last, part-filled group take the last row's (a finite state, never written back)."""
    for i in range(state.shape[1]):
        k = r0 + min(i, c - 1)
        for q in range(rows.shape[0]):
            state[q, i] = rows[q, k]


@_jit
def _store(state, r0, c, rows):
    """The first ``c`` lanes of ``state (Q, C)`` back into columns ``r0 ..`` of ``rows``."""
    for i in range(c):
        for q in range(rows.shape[0]):
            rows[q, r0 + i] = state[q, i]


@_jit
def moment_rows(x, count, rows):
    """Each row of ``x (R, T)`` after ``count`` samples into its running mean, M2, largest
    and smallest sample, ``rows (4, R)`` in place (:func:`welford`, :func:`extremes`), the
    rows of ``x`` :data:`LANES` at a time side by side."""
    R, T = x.shape
    C = min(LANES, R)
    lanes = np.empty((T, C))
    state = np.empty((4, C))
    for r0 in range(0, R, C):
        c = min(C, R - r0)
        _lanes(x, r0, c, lanes)
        _load(rows, r0, c, state)
        for t in range(T):
            w = 1.0 / (count + t + 1)
            for i in range(C):
                v = lanes[t, i]
                state[0, i], state[1, i] = welford(v, w, state[0, i], state[1, i])
                state[2, i], state[3, i] = extremes(v, state[2, i], state[3, i])
        _store(state, r0, c, rows)


@_jit
def power_rows(aw, start, block, rows):
    """Each row of the weighted ``aw (R, T)``, whose first sample is sample ``start`` of its
    record, into ``rows (5, R)`` in place: the block's and the total sum of ``a_w²``, the
    same of ``a_w⁴``, the largest ``|a_w|`` (:func:`powers`; a block's sums carried into the
    totals at its end, :func:`carry`), the rows of ``aw`` :data:`LANES` at a time."""
    R, T = aw.shape
    C = min(LANES, R)
    lanes = np.empty((T, C))
    state = np.empty((5, C))
    for r0 in range(0, R, C):
        c = min(C, R - r0)
        _lanes(aw, r0, c, lanes)
        _load(rows, r0, c, state)
        for t in range(T):
            for i in range(C):
                state[0, i], state[2, i], state[4, i] = powers(
                    lanes[t, i], state[0, i], state[2, i], state[4, i]
                )
            if (start + t + 1) % block == 0:
                for i in range(C):
                    state[0, i], state[1, i] = carry(state[0, i], state[1, i])
                    state[2, i], state[3, i] = carry(state[2, i], state[3, i])
        _store(state, r0, c, rows)
