"""The streamed reductions' compiled loops against their numpy arithmetic, in the same run.

For windows of P designs x T samples (white noise, seed 2026): the ISO 2631 Wk filter at
1 kHz (:meth:`suspopt.weighting.WeightingFilter.apply`), the moments' block statistics and
the weighted power sums of :mod:`suspopt.streaming`, each timed with the compiled loops
(:func:`suspopt.integrator.compiled_reductions`) and with the numpy code beside them, best of
5, and whether the two gave the same bits. Needs numba. Run:
``python benchmarks/bench_reductions.py``. Prints the table; asserts nothing.
"""

from __future__ import annotations

import platform
import time

import numpy as np

import suspopt
import suspopt.integrator as integrator
from suspopt import streaming
from suspopt.metrics.iso2631 import weighting_filter

SIZES = ((100, 1024), (1000, 1024), (1000, 1500), (10000, 256))


def _best(fn, x, rounds: int = 5) -> float:
    fn(x)
    times = []
    for _ in range(rounds):
        t = time.perf_counter()
        fn(x)
        times.append(time.perf_counter() - t)
    return min(times)


def _same(a, b) -> bool:
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, int):
        return a == b
    return np.array_equal(a, b, equal_nan=True)


def main() -> None:
    loops = integrator.compiled_reductions()
    if loops is None:
        raise SystemExit("needs numba: pip install numba")
    print(f"suspopt {suspopt.__version__}, {platform.processor() or platform.machine()}")
    wk = weighting_filter("Wk", 1000.0)
    jobs = {
        "Wk filter": lambda x: wk.apply(x),
        "block moments": streaming._block_moments,
        "power sums": streaming._power_sums,
    }
    print(f"{'P':>6} {'T':>5} {'reduction':<14} {'numpy [ms]':>11} {'compiled [ms]':>14} "
          f"{'ratio':>6}  same bits")  # fmt: skip
    for P, T in SIZES:
        x = np.random.default_rng(2026).standard_normal((P, T))
        for name, job in jobs.items():
            integrator.compiled_reductions = lambda: None  # type: ignore[assignment]
            slow, reference = _best(job, x), job(x)
            integrator.compiled_reductions = lambda: loops  # type: ignore[assignment]
            fast, got = _best(job, x), job(x)
            print(f"{P:>6} {T:>5} {name:<14} {slow * 1e3:>11.2f} {fast * 1e3:>14.2f} "
                  f"{slow / fast:>6.1f}  {_same(got, reference)}")  # fmt: skip


if __name__ == "__main__":
    main()
