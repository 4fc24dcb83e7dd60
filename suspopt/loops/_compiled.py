"""Compiled loops of the streamed reductions and of the weighting filter (imported only when
numba is installed, through :func:`suspopt.loops.compiled_reductions`).

Each function is the numpy arithmetic it replaces, operation for operation, so that both give
the same bits (``tests/test_reductions.py`` checks it against numpy on hostile signals):

- :func:`weight_rows`: :meth:`suspopt.weighting.WeightingFilter.apply` — the FIR correction
  as the sum of shifted copies in its fixed order, then each second-order section in scipy's
  transposed direct form II (``sosfilt``'s difference equations, sample by sample);
- :func:`block_moments`: the block statistics of :class:`suspopt.streaming._Moments` — each
  block's mean (``np.mean``: numpy's pairwise sum, divided by the count) and the sum of its
  squared deviations;
- :func:`power_sums`: :func:`suspopt.metrics.iso2631.block_sums` of ``a_w²`` and of
  ``a_w⁴`` and the largest ``|a_w|`` of each row, in one pass (``np.max``'s NaN included).

:data:`_pairwise` is numpy's pairwise summation (its ``pairwise_sum`` of a contiguous run:
eight partial sums up to 128 values, halves above that, a start at zero), so a block summed
here has the bits of ``np.sum`` of that block (numpy 2.x; the test compares them). One pass
over each row instead of numpy's several whole-array passes and temporaries
(``benchmarks/bench_reductions.py`` times both in one run). Single-threaded (no
``prange``): they run in the caller's thread while the kernel may integrate the next window
on every core (:func:`suspopt.integrator._ahead`).
"""

from __future__ import annotations

import numba
import numpy as np

from .. import _numba_cache

_numba_cache.prepare()  # (cached for the machine, damaged files compiled again: suspopt._numba_cache)
_jit = numba.njit(cache=True, nogil=True)


@_jit
def _leaf(x, start, n):
    """numpy's pairwise sum of ``x[start : start + n]`` for ``n <= 128``: one block of eight
    partial sums (fewer than eight values: in turn, from zero)."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += x[start + i]
        return res
    r0, r1, r2, r3 = x[start], x[start + 1], x[start + 2], x[start + 3]
    r4, r5, r6, r7 = x[start + 4], x[start + 5], x[start + 6], x[start + 7]
    i = start + 8
    stop = start + n - n % 8
    while i < stop:
        r0 += x[i]
        r1 += x[i + 1]
        r2 += x[i + 2]
        r3 += x[i + 3]
        r4 += x[i + 4]
        r5 += x[i + 5]
        r6 += x[i + 6]
        r7 += x[i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < start + n:
        res += x[i]
        i += 1
    return res


def _halves(part):
    """The pairwise sum one level up from ``part`` (numpy splits a run of more than 128
    values in two, the first a multiple of 8). Each level is its own function: numba's cache
    of a recursive function crashes the process that loads it (numba 0.68)."""

    def level(x, start, n):
        if n <= 128:
            return _leaf(x, start, n)
        half = n // 2
        half -= half % 8
        return part(x, start, half) + part(x, start + half, n - half)

    return _jit(level)


#: ``np.sum`` of ``x[start : start + n]`` (1-D, contiguous) in numpy's order, for ``n`` up to
#: :data:`LONGEST` (four levels of halves above the 128-value blocks).
_pairwise = _halves(_halves(_halves(_halves(_leaf))))
LONGEST = 1920


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
                y[t, i] = numerator[0] * x[M + t, i]
            for k in range(1, M + 1):
                for i in range(C):
                    y[t, i] = y[t, i] + numerator[k] * x[M + t - k, i]
            for s in range(S):
                b0, b1, b2 = sections[s, 0], sections[s, 1], sections[s, 2]
                a1, a2 = sections[s, 4], sections[s, 5]
                for i in range(C):
                    u = y[t, i]
                    v = b0 * u + z[s, 0, i]
                    z[s, 0, i] = b1 * u - a1 * v + z[s, 1, i]
                    z[s, 1, i] = b2 * u - a2 * v
                    y[t, i] = v
        for i in range(c):
            for t in range(T):
                out[r0 + i, t] = y[t, i]
            for k in range(M):
                history[r0 + i, k] = x[T + k, i]
            for s in range(S):
                poles[s, r0 + i, 0] = z[s, 0, i]
                poles[s, r0 + i, 1] = z[s, 1, i]


@_jit
def block_moments(x, block, means, squares):
    """Each row of ``x (R, T)`` in blocks of ``block`` samples (the last one shorter): the
    block's mean into ``means (R, nb)`` and its sum of squared deviations into ``squares``
    (``block`` at most :data:`LONGEST`)."""
    if block > LONGEST:
        raise ValueError("a block longer than the pairwise sum's levels")
    R, T = x.shape
    scratch = np.empty(block)
    for r in range(R):
        row = x[r]
        for b in range(means.shape[1]):
            start = b * block
            m = min(block, T - start)
            mean = _pairwise(row, start, m) / m
            for i in range(m):
                d = row[start + i] - mean
                scratch[i] = d * d
            means[r, b] = mean
            squares[r, b] = _pairwise(scratch, 0, m)


@_jit
def power_sums(aw, block, squares, fourth, peak):
    """Each row of ``aw (R, T)``: the sums of ``aw²`` and of ``aw⁴`` over each ``block``
    samples into ``squares, fourth (R, nb)`` and the largest ``|aw|`` into ``peak (R,)`` (NaN
    when a sample is NaN; ``block`` at most :data:`LONGEST`)."""
    if block > LONGEST:
        raise ValueError("a block longer than the pairwise sum's levels")
    R, T = aw.shape
    sq = np.empty(block)
    quad = np.empty(block)
    for r in range(R):
        top = -np.inf
        for b in range(squares.shape[1]):
            start = b * block
            m = min(block, T - start)
            for i in range(m):
                v = aw[r, start + i]
                s = v * v
                sq[i] = s
                quad[i] = s * s
                size = abs(v)
                if not size <= top:  # noqa: SIM102  (a NaN stays: np.max's order of tests)
                    if not np.isnan(top):
                        top = size
            squares[r, b] = _pairwise(sq, 0, m)
            fourth[r, b] = _pairwise(quad, 0, m)
        peak[r] = top
