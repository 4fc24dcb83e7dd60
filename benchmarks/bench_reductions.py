"""The streamed metrics' one arithmetic (:mod:`suspopt.loops._compiled`) against numpy's and
scipy's own routines for the same quantities, in the same run.

For windows of P designs x T samples (white noise, seed 2026): the ISO 2631 Wk filter at
1 kHz (:meth:`suspopt.weighting.WeightingFilter.apply`, against its FIR in numpy and
``scipy.signal.sosfilt``), the moments (:func:`suspopt.metrics.stats.moments`, against
``np.mean`` and ``np.var``) and the weighted power sums
(:func:`suspopt.metrics.iso2631.power_state`, against ``np.sum`` of the squares and fourth
powers and ``np.max``), each timed best of 5, and the largest relative difference of the
results. Run: ``python benchmarks/bench_reductions.py``. Prints the table; asserts nothing.
"""

from __future__ import annotations

import platform
import time

import numpy as np

import suspopt
from suspopt.metrics.iso2631 import power_state, weighting_filter
from suspopt.metrics.stats import moment_value, moments

SIZES = ((100, 1024), (1000, 1024), (1000, 1500), (10000, 256))


def _best(fn, x, rounds: int = 5) -> float:
    fn(x)
    times = []
    for _ in range(rounds):
        t = time.perf_counter()
        fn(x)
        times.append(time.perf_counter() - t)
    return min(times)


def _numpy_filter(f, x):
    from scipy.signal import sosfilt

    m, n = len(f.numerator) - 1, x.shape[-1]
    padded = np.concatenate([np.zeros((x.shape[0], m)), x], axis=-1)
    out = f.numerator[0] * padded[:, m:]
    for k, c in enumerate(f.numerator[1:], start=1):
        out = out + c * padded[:, m - k : m - k + n]
    return sosfilt(f.sections, out, axis=-1)


def main() -> None:
    print(f"suspopt {suspopt.__version__}, {platform.processor() or platform.machine()}")
    wk = weighting_filter("Wk", 1000.0)
    jobs = {
        "Wk filter": (lambda x: wk.apply(x)[0], lambda x: _numpy_filter(wk, x)),
        "moments": (
            lambda x: moment_value("var", moments(x)),
            lambda x: np.var(x, axis=-1),
        ),
        "power sums": (
            lambda x: np.sum(power_state(x)[1][:2], axis=0),
            lambda x: np.sum(np.square(x), axis=-1),
        ),
    }
    print(f"{'P':>6} {'T':>5} {'reduction':<11} {'numpy [ms]':>11} {'suspopt [ms]':>13} "
          f"{'ratio':>6}  largest relative difference")  # fmt: skip
    for P, T in SIZES:
        x = np.random.default_rng(2026).standard_normal((P, T))
        for name, (ours, theirs) in jobs.items():
            slow, fast = _best(theirs, x), _best(ours, x)
            difference = np.max(np.abs(ours(x) / theirs(x) - 1.0))
            print(f"{P:>6} {T:>5} {name:<11} {slow * 1e3:>11.2f} {fast * 1e3:>13.2f} "
                  f"{slow / fast:>6.1f}  {difference:.1e}")  # fmt: skip


if __name__ == "__main__":
    main()
