"""A fixed-size summary of growing sample histories and the Student-t fit from it
(:class:`StudentTSummary`): the adaptive CDF threshold's refit (Ch. 4, Eq 4.5-4.7) at a cost
that does not grow with the run; the fit itself is :mod:`suspopt.control.stats`'s."""

from __future__ import annotations

import numpy as np

from .stats import NU_RANGE, fit_t, robust_location_scale

__all__ = ["StudentTSummary"]

#: Summary of a growing history: ``_SUMMARY_BINS`` bins of equal width on ``[-U, U]``,
#: ``U = _SUMMARY_RANGE``, in ``u = asinh((x - m0)/s0)`` (values beyond fall in the end bins).
_SUMMARY_BINS = 64
_SUMMARY_RANGE = 8.0
#: The summary's fits stop at a Newton step below this (see _T_TOLERANCE): the error left,
#: about its square, is a few 1e-5 of s, below the grouping error.
_SUMMARY_TOLERANCE = 5e-3


class StudentTSummary:
    """A fixed-size summary of growing sample histories and the Student-t fit from it: the
    adaptive controller's refit (Eq 4.5-4.7 with the t of Sec 4.2.3) at a cost that does not
    grow with the history.

    It estimates what :func:`fit_student_t` does on the whole history - the same maximum-
    likelihood ``(μ, s, ν)`` - from grouped data: a deviation in method, not in what is
    estimated. Each column's samples are binned in the coordinate ``u = asinh((x - m0)/s0)``,
    linear within ``s0`` of ``m0`` and logarithmic beyond, so the bins are fine at the centre
    and span heavy tails: ``_SUMMARY_BINS`` bins of width ``Δu = 0.25`` on ``|u| <= 8``, i.e.
    ``|x - m0|`` up to ``1490 s0``; farther values fall in the end bins. Per bin it keeps the
    count and the first two moments of ``u`` about the bin's centre, and takes in each sample
    once, when a refit comes. A fit replaces each bin by two points of half its count at
    ``ū ± σ_u`` (the two-point rule that matches the bin's mean and variance) and maximises
    the weighted likelihood with :func:`fit_student_t`'s Newton method, warm-started from the
    column's last fit and stopped at a Newton step below ``_SUMMARY_TOLERANCE``: typically 2-4
    evaluations over at most ``2 x _SUMMARY_BINS`` points per column, however long the
    history.

    Error: the two-point rule errs at third order in ``Δu``; in the tails the terms of the
    likelihood are nearly linear in ``u`` (``log(1 + d²/ν) ≈ 2u + const``, ``w ≈ 0``), so the
    end bins' exact moments carry them. The fitted quantiles at 0.27 and 0.73 (the thresholds
    of a 27 % share) lie within ``5e-4 s`` of the exact full-history fit's, mostly within
    ``1e-4 s``, on SH-2 and SH-ADD-2 condition histories from class C roads and on t samples
    with ν from 1 to 30 (tests/test_control.py): far below the exact fit's own sampling error
    (``~ s/√n``) and, in the C_max share, below 0.02 points.

    The coordinate ``(m0, s0)`` is set at a column's first fit from its robust location and
    scale (:func:`robust_location_scale`), ``s0`` half the scale. The error above holds while
    the fitted ``s`` lies in ``[s0, 16 s0]`` and ``μ`` within ``s/2`` of ``m0``. When a fit
    leaves that (the road changed) and the history has at least doubled since the coordinate
    was set, the column is rebinned from the raw history on ``(μ, s/2)`` and refitted; the
    doubling bounds the rebinning to twice the samples in all. A fit that collapsed onto an
    atom (ν at its lower bound, see :func:`fit_student_t`) restarts at the next refit from the
    summary's median and interquartile range, as the exact fit starts afresh. Columns whose
    samples are all equal give ``s = 0`` and are binned once they differ; a non-finite sample
    makes the column's fit NaN from then on.

    Columns are independent (designs x corners, flattened); :meth:`fit` takes the history as
    an array ``(n, columns)`` whose rows only ever grow.
    """

    def __init__(self, columns: int):
        self._moments = np.zeros((3, _SUMMARY_BINS, columns))  # count, Σ o, Σ o² per bin
        self._centre = np.zeros(columns)  # m0
        self._spread = np.ones(columns)  # s0
        self._binned = np.zeros(columns, dtype=bool)
        self._built_rows = np.zeros(columns, dtype=np.intp)  # rows when (m0, s0) were set
        self._low = np.full(columns, np.inf)  # range of the samples
        self._high = np.full(columns, -np.inf)
        self._rows = 0  # history rows summarised
        self._fit = tuple(np.full(columns, np.nan) for _ in range(3))

    def fit(
        self, history: np.ndarray, columns: np.ndarray | slice = slice(None)
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(μ, s, ν)`` of ``columns`` (indices or a slice) from all rows of ``history``
        ``(n, columns)``; the summary first takes in the rows it has not seen (of every
        column)."""
        self._take_in(history)
        index = np.arange(self._centre.size)[columns]
        low, high = self._low[index], self._high[index]
        finite = np.isfinite(low) & np.isfinite(high)
        varied = finite & (high > low)
        new = index[varied & ~self._binned[index]]
        if new.size:
            centre, spread = robust_location_scale(history[:, self._select(new)])
            for stored, start in zip(self._fit, (centre, spread, 5.0)):
                stored[new] = start
            self._rebin(history, new, centre, 0.5 * spread)
        fitted = index[varied]
        collapsed = fitted[self._fit[2][fitted] <= NU_RANGE[0]]
        if collapsed.size:  # on an atom last time: start afresh
            middle, lower, upper = self._quantiles(collapsed, (0.5, 0.25, 0.75))
            for stored, start in zip(self._fit, (middle, (upper - lower) / 1.349, 5.0)):
                stored[collapsed] = start
        self._refit(fitted)
        loc, scale, df = (a[fitted] for a in self._fit)
        stale = (
            (
                (scale < self._spread[fitted])
                | (scale > 16.0 * self._spread[fitted])
                | (np.abs(loc - self._centre[fitted]) > 0.5 * scale)
            )
            & (history.shape[0] >= 2 * self._built_rows[fitted])
            & (df > NU_RANGE[0])
        )
        if stale.any():
            moved = fitted[stale]
            self._rebin(history, moved, loc[stale], 0.5 * scale[stale])
            self._refit(moved)
        loc = np.where(varied, np.nan, np.where(finite, low, np.nan))
        scale = np.where(finite, 0.0, np.nan)
        df = np.where(finite, 5.0, np.nan)
        for out, value in zip((loc, scale, df), self._fit):
            out[varied] = value[fitted]
        return loc, scale, df

    def _select(self, columns: np.ndarray) -> np.ndarray | slice:
        """``columns`` (sorted, distinct) as an index, a slice when they are all of them (no
        copies)."""
        return slice(None) if columns.size == self._centre.size else columns

    def _take_in(self, history: np.ndarray) -> None:
        """Extend the range of every column and the bins of the binned ones by the rows of
        ``history`` after ``self._rows``."""
        block = history[self._rows :]
        if block.shape[0] == 0:
            return
        self._low = np.minimum(self._low, np.min(block, axis=0))
        self._high = np.maximum(self._high, np.max(block, axis=0))
        binned = np.flatnonzero(self._binned)
        if binned.size:
            which = self._select(binned)
            finite = bool(
                np.isfinite(self._low[which]).all() and np.isfinite(self._high[which]).all()
            )
            if isinstance(which, slice):
                self._bin(block, self._centre, self._spread, finite, self._moments)
            else:
                moments = np.zeros((3, _SUMMARY_BINS, binned.size))
                self._bin(
                    block[:, which], self._centre[which], self._spread[which], finite, moments
                )
                self._moments[:, :, which] += moments
        self._rows = history.shape[0]

    def _rebin(self, history: np.ndarray, columns: np.ndarray, centre, spread) -> None:
        """Bin ``columns`` afresh from all rows of ``history`` on the coordinate
        ``(centre, spread)``."""
        which = self._select(columns)
        self._centre[which], self._spread[which] = centre, spread
        moments = np.zeros((3, _SUMMARY_BINS, columns.size))
        self._bin(history[: self._rows, which], centre, spread, True, moments)
        self._moments[:, :, which] = moments
        self._binned[which] = True
        self._built_rows[which] = self._rows

    @staticmethod
    def _bin(
        block: np.ndarray, centre: np.ndarray, spread: np.ndarray, finite: bool, moments: np.ndarray
    ) -> None:
        """Add the count and first two moments of the offset ``o`` from the bin's centre (in
        bin widths) per bin and column of the samples ``block`` ``(n, columns)`` to
        ``moments`` (3, bins, columns), C-contiguous; ``finite`` says every sample is finite
        (else non-finite ones go to the centre: their columns' fits are NaN anyway)."""
        bins, columns = _SUMMARY_BINS, block.shape[1]
        position = np.subtract(block, centre)
        position /= spread
        if not finite:
            position[~np.isfinite(position)] = 0.0
        np.arcsinh(position, out=position)
        position += _SUMMARY_RANGE
        position *= bins / (2.0 * _SUMMARY_RANGE)  # in bin widths from -U
        key = position.astype(np.intp)  # = floor where it matters:
        np.clip(key, 0, bins - 1, out=key)  # below 0 is the first bin
        position -= key
        position -= 0.5  # offset from the bin's centre
        key *= columns
        key += np.arange(columns)
        key, offset = key.ravel(), position.ravel()
        count, first, second = (m.reshape(-1) for m in moments)
        np.add.at(count, key, 1.0)
        np.add.at(first, key, offset)
        np.multiply(offset, offset, out=offset)
        np.add.at(second, key, offset)

    def _quantiles(self, columns: np.ndarray, levels) -> list[np.ndarray]:
        """Sample quantiles of ``columns`` at ``levels`` from their bins (linear in ``u``
        within a bin): a fresh start for a fit."""
        which = self._select(columns)
        count = self._moments[0][:, which]
        below = np.cumsum(count, axis=0)
        width = 2.0 * _SUMMARY_RANGE / _SUMMARY_BINS
        out = []
        for level in levels:
            target = level * below[-1]
            k = np.argmax(below >= target, axis=0)
            inside = np.take_along_axis(count, k[None], axis=0)[0]
            before = np.take_along_axis(below, k[None], axis=0)[0] - inside
            u = (k + (target - before) / inside) * width - _SUMMARY_RANGE
            out.append(self._centre[which] + self._spread[which] * np.sinh(u))
        return out

    def _points(self, columns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The two-point representation of the bins of ``columns``: values ``(2 bins',
        columns)`` and their weights, ``bins'`` the span of bins any of them occupies."""
        count, first, second = self._moments[:, :, self._select(columns)]
        occupied = np.flatnonzero(np.any(count > 0, axis=1))
        span = slice(occupied[0], occupied[-1] + 1)
        count, first, second = count[span], first[span], second[span]
        with np.errstate(divide="ignore", invalid="ignore"):
            mean = np.where(count > 0, first / count, 0.0)
            sd = np.sqrt(np.maximum(np.where(count > 0, second / count, 0.0) - mean * mean, 0.0))
        width = 2.0 * _SUMMARY_RANGE / _SUMMARY_BINS
        middle = (np.arange(_SUMMARY_BINS)[span] + 0.5) * width - _SUMMARY_RANGE
        u = np.concatenate(
            [middle[:, None] + width * (mean - sd), middle[:, None] + width * (mean + sd)]
        )
        which = self._select(columns)
        values = self._centre[which] + self._spread[which] * np.sinh(u)
        return values, np.concatenate([count, count]) * 0.5

    def _refit(self, columns: np.ndarray) -> None:
        """Fit ``columns`` from their bins, warm-started from their last fit."""
        if columns.size == 0:
            return
        values, weights = self._points(columns)
        which = self._select(columns)
        start = tuple(a[which] for a in self._fit)
        loc, scale, df = start
        fit = fit_t(
            values, weights, loc, scale, df, np.ones(columns.size, dtype=bool), _SUMMARY_TOLERANCE
        )
        for stored, new in zip(self._fit, fit):
            stored[which] = new
