"""k-ε sort of N solutions × m objectives: wall time and peak memory of ``suspopt.kesort``.

Random objectives (uniform, seed 2026) at N = 1,000, 3,000 and 10,000 with m = 10; the sort
with a fixed P (k-ε and k-optimality levels, Eq 6.10-6.12) and the levels alone. Peak memory
is what numpy allocates during the call (tracemalloc), beside the (N, m) input. Run:
``python benchmarks/bench_kesort.py``. Prints a table; asserts nothing.
"""

from __future__ import annotations

import platform
import time
import tracemalloc

import numpy as np

import suspopt
from suspopt.kesort import k_eps_levels


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


if __name__ == "__main__":
    main()
