"""k-ε sort of N solutions × m objectives: wall time and peak memory of ``suspopt.kesort``.

Random objectives (uniform, seed 2026) at N = 1,000, 3,000 and 10,000 with m = 10; the sort
with a fixed P (k-ε and k-optimality levels, Eq 6.10-6.12) and the levels alone. Peak memory
is what numpy allocates during the call (tracemalloc), beside the (N, m) input.

A second table times ``P = "auto"`` on sets where no P of the grid leaves one solution on
top (so the whole grid of 100 values is tried): a straight two-objective front (its two
middle designs tie for ever) and a three-objective front pooled twice (every design is
there twice), against the long way, every P of the grid a whole sort (``k_eps_levels``),
in the same run; the P and the levels are compared bit for bit.

Run: ``python benchmarks/bench_kesort.py``. Prints tables; asserts nothing.
"""

from __future__ import annotations

import platform
import time
import tracemalloc

import numpy as np

import suspopt
from suspopt.choosing.kepsilon import k_eps_levels


def measure(call):
    tracemalloc.start()
    start = time.perf_counter()
    call()
    wall = time.perf_counter() - start
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return wall, peak / 2**20


def main() -> None:
    rng = np.random.default_rng(2026)
    m = 10
    print(
        f"suspopt {suspopt.__version__} | Python {platform.python_version()} | "
        f"numpy {np.__version__} | {platform.machine()}"
    )
    print("| N × m | kesort(F, P=0.1) [s] | peak [MB] | k_eps_levels alone [s] |")
    print("|---|---|---|---|")
    for N in (1_000, 3_000, 10_000):
        F = rng.random((N, m))
        wall, peak = measure(lambda F=F: suspopt.kesort(F, P=0.1))
        levels, _ = measure(lambda F=F: k_eps_levels(F, 0.1))
        print(f"| {N:,} × {m} | {wall:.2f} | {peak:.0f} | {levels:.2f} |")
    _auto(rng)


def _every_P(F):
    """P = "auto" the long way: the whole set sorted at every P of the default grid."""
    NF = F / F.max(axis=0)
    for k in range(100):
        P = float(f"{0.01 + k * 0.01:.12g}")
        levels = k_eps_levels(NF, P * NF.max(axis=0))
        if (levels >= levels.max() - 1e-9).sum() == 1:
            break
    return P, levels


def _auto(rng) -> None:
    print("\n| set | N × m | kesort(F, P='auto') [s] | every P sorted [s] | ratio | same |")
    print("|---|---|---|---|---|---|")
    for N in (2_000, 10_000):
        x = np.linspace(0.0, 1.0, N)
        pooled = rng.dirichlet(np.ones(3), N // 2)
        for label, F in (
            ("straight front", np.column_stack([1.0 + x, 2.0 - x])),
            ("front pooled twice", np.vstack([pooled, pooled])),
        ):
            start = time.perf_counter()
            result = suspopt.kesort(F, P="auto")
            fast = time.perf_counter() - start
            start = time.perf_counter()
            P, levels = _every_P(F)
            slow = time.perf_counter() - start
            same = result.P == P and np.array_equal(result.k_eps, levels)
            print(
                f"| {label} | {N:,} × {F.shape[1]} | {fast:.2f} | {slow:.2f} | "
                f"{slow / fast:.3g}x | {same} |"
            )


if __name__ == "__main__":
    main()
