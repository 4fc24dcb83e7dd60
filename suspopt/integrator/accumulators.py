"""Signals the compiled kernel computes and reduces itself (:mod:`._accumulate`), for a
streamed evaluation (:func:`suspopt.streaming.reduce`).

A signal whose every sample is an affine function of that instant's states, accelerations
and road inputs, ``e + Σ c_i x_i`` with coefficients per design (travel, tyre deflection, a
body's acceleration, a damper's force with a fixed coefficient...), needs no record: the
kernel forms it at each sample from its own buffer and accumulates its moments, its extremes
and its weighted sums as the integration runs, so its rows are neither written to the
``(rows, P, T)`` records nor read back, and no numpy pass runs over it. Which signals are
affine, and their coefficients, comes from the signal table itself
(:func:`suspopt.affine.affine_signals` probes it), not from a second description.

The kernel reduces by the steps every reduction uses (:mod:`suspopt.loops._compiled`), and
its accumulators are the state of :func:`suspopt.metrics.stats.moments` and
:func:`suspopt.metrics.iso2631.power_state`: each value agrees with the whole run's metric to
rounding (about 1e-15 relative, ``tests/test_accumulators.py``: the signal is formed as its
terms in turn, not by the signal table), and a design's value does not depend on its batch,
its block, the windows or the threads (each lane's arithmetic is its own). The numpy engine
and signals that are not affine are reduced from the windows.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["Accumulators", "Affine", "no_accumulators"]


@dataclass
class Affine:
    """One signal as ``constant + Σ coefficient · source``: ``sources`` rows of the whole
    network's ``[q; q'; q'']`` (``0 .. 3n``) or road inputs ``-(r + 1)`` (``r`` among the
    heights then the rates, ``2 n_u``), ``coefficients`` and ``constant`` (P,) each."""

    name: str
    sources: list[int]
    coefficients: list[np.ndarray]
    constant: np.ndarray


@dataclass
class Accumulators:
    """The signals ``signals`` the kernel forms and reduces, the weighted pairs ``pairs``
    (index into ``signals``, filter or None for the signal itself), the road inputs ``zs (J,
    2 n_u, G)`` at the J samples, their rate ``fs`` [Hz], each pair's (signal name,
    weighting) ``pair_keys``, whether they are ``alone`` (no signal read from records: the
    engine then writes none), and after the run the accumulators (:meth:`moments`,
    :meth:`weighted`)."""

    signals: list[Affine]
    pairs: list[tuple[int, Any]]
    zs: np.ndarray
    fs: float
    pair_keys: list[tuple[str, str | None]]
    alone: bool = False
    acc: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 1)))
    _pair_rows: list[int] = field(default_factory=list)

    def rows(self, n: int) -> np.ndarray:
        """The rows of ``[q; q'; q'']`` (3n,) the signals read."""
        read = np.zeros(3 * n, np.bool_)
        for signal in self.signals:
            read[[s for s in signal.sources if s >= 0]] = True
        return read

    def arrays(self, blocks: int, B: int, wanted: np.ndarray) -> tuple:
        """The kernel's ``red`` (:mod:`._accumulate`) over ``blocks`` of ``B`` lanes, the
        buffer's rows being the whole network's rows ``wanted`` (sorted), in order."""
        from ..metrics.iso2631 import SUM_BLOCK
        from ._accumulate import PER_PAIR, PER_SIGNAL
        from .lanes import padded

        P = blocks * B
        S = len(self.signals)
        terms, coefficients = [], []
        for s, signal in enumerate(self.signals):
            for source, c in zip(signal.sources, signal.coefficients):
                m = int(np.searchsorted(wanted, source)) if source >= 0 else source
                terms += [s, m]
                coefficients.append(c)
        coefficients += [signal.constant for signal in self.signals]
        filt: list[float] = []
        pairs: list[int] = []
        row = PER_SIGNAL * S
        self._pair_rows = []
        for s, fir in self.pairs:
            numerator = np.ones(1) if fir is None else fir.numerator
            sections = np.zeros((0, 6)) if fir is None else fir.sections
            pairs += [s, len(filt), numerator.size - 1, sections.shape[0], row]
            filt += list(numerator) + list(sections.ravel())
            row += numerator.size - 1 + 2 * sections.shape[0]
            self._pair_rows.append(row)
            row += PER_PAIR
        ri = np.array([S, len(terms) // 2, len(self.pairs), SUM_BLOCK] + terms + pairs, np.int64)
        # the coefficients (P0,) each over the lanes, the last design repeated
        coef = padded(np.stack(coefficients), P) if coefficients else np.zeros((0, P))
        acc = np.zeros((row, P))
        for s in range(S):
            acc[PER_SIGNAL * s + 3], acc[PER_SIGNAL * s + 4] = -np.inf, np.inf
        for top in self._pair_rows:
            acc[top + 5] = -np.inf
        self.acc = np.ascontiguousarray(acc.reshape(row, blocks, B).transpose(1, 0, 2))
        coef = np.ascontiguousarray(coef.reshape(-1, blocks, B).transpose(1, 0, 2))
        return ri, coef, self.acc, np.array(filt, float), self.zs

    def _rows(self, first: int, count: int, P: int) -> np.ndarray:
        """Rows ``first .. first + count`` of the accumulators over the first P designs."""
        a = self.acc[:, first : first + count]
        return a.transpose(1, 0, 2).reshape(count, -1)[:, :P]

    def moments(self, s: int, P: int) -> tuple[np.ndarray, ...]:
        """Signal ``s``'s mean, sum of squared deviations, largest and smallest value, (P,)
        each."""
        from ._accumulate import PER_SIGNAL

        mean, m2, high, low = self._rows(PER_SIGNAL * s + 1, 4, P)
        return mean, m2, high, low

    def weighted(self, p: int, P: int) -> tuple[np.ndarray, np.ndarray]:
        """Pair ``p``'s sums ``(4, P)``, the block's and the total of ``a_w²`` then of
        ``a_w⁴``, and its largest ``|a_w|`` (P,): the state of
        :func:`suspopt.metrics.iso2631.power_state`."""
        part, total, part4, total4, peak = self._rows(self._pair_rows[p] + 1, 5, P)
        return np.stack([part, total, part4, total4]), peak


def no_accumulators(blocks: int, B: int) -> tuple:
    """The kernel's ``red`` when it forms no signal."""
    return (
        np.array([0, 0, 0, 1], np.int64),
        np.zeros((blocks, 0, B)),
        np.zeros((blocks, 0, B)),
        np.zeros(0),
        np.zeros((1, 0, 1)),
    )
