"""Designs simulated per second for the Chapter 5 HC2 problem, at P = 1, 100 and 1000.

Table 5.1 half car with Duffing springs, half-sine bump 0.05 m (base 1 m) at 40 km/h, 3 s at
dt = 1 ms (configs/quickstart.yaml); designs drawn uniformly inside the Table 5.2 bounds (with
the k_nl range of docs/thesis-slips.md#table-52). Each size is timed as the best of three calls
(the first call of a size also pays the operating system for memory the process has not touched
before). Run:
``python benchmarks/bench_simulate.py``. Prints a table; asserts nothing.
Like the command line, it first makes the allocator reuse freed memory
(:func:`suspopt.reuse_memory`); ``--default-allocator`` leaves it as it is.
"""

from __future__ import annotations

import platform
import sys
import time
from pathlib import Path

import numpy as np

import suspopt

CONFIG = Path(__file__).resolve().parents[1] / "configs" / "quickstart.yaml"
BOUNDS = {  # Table 5.2 (k_nl range: slip: docs/thesis-slips.md#table-52)
    "vehicle.corners.F1.spring.linear": (3.2e4, 1.5e5),
    "vehicle.corners.R1.spring.linear": (3.2e4, 1.5e5),
    "vehicle.corners.F1.damper.c": (2.0e3, 1.0e4),
    "vehicle.corners.R1.damper.c": (2.0e3, 1.0e4),
    "vehicle.corners.F1.spring.cubic": (5.0e5, 3.0e7),
    "vehicle.corners.R1.spring.cubic": (5.0e5, 3.0e7),
}


def designs(P: int, rng: np.random.Generator) -> dict[str, np.ndarray]:
    return {k: rng.uniform(lo, hi, P) for k, (lo, hi) in BOUNDS.items()}


def main() -> None:
    memory = (
        "reused"
        if "--default-allocator" not in sys.argv[1:] and suspopt.reuse_memory()
        else "default"
    )
    cfg = suspopt.load_config(CONFIG)
    rng = np.random.default_rng(2026)
    suspopt.simulate(cfg, params=designs(2, rng))  # warm-up (imports, caches)
    print(
        f"suspopt {suspopt.__version__} | Python {platform.python_version()} | "
        f"numpy {np.__version__} | {platform.machine()} | freed memory {memory}"
    )
    print(
        f"HC2 Ch. 5 problem: {cfg.simulation.duration} s at dt = {cfg.simulation.dt} s "
        f"({cfg.simulation.n_steps} RK4 steps)"
    )
    print(f"{'P':>6} {'wall [s]':>10} {'designs/s':>12} {'body acc metric (mean RMS)':>28}")
    for P in (1, 100, 1000):
        params = designs(P, rng)
        wall = np.inf
        for _ in range(3):
            start = time.perf_counter()
            res = suspopt.simulate(cfg, params=params)
            rms = np.sqrt(np.mean(res.signals["body.heave_acc"] ** 2, axis=-1))
            wall = min(wall, time.perf_counter() - start)
        print(f"{P:>6} {wall:>10.3f} {P / wall:>12.1f} {rms.mean():>28.4f}")


if __name__ == "__main__":
    main()
