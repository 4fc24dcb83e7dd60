"""Wall time of one Ch. 8 seat run: QC + NSS4 seat + passenger, 1000 m of class A at 120 km/h.

configs/ch8/nss4_class_a_passenger.yaml: the Table 8.1 quarter car, the mid-range KDamper design
and the Table 2.3 passenger (9 seat DOFs on 2 vehicle DOFs), 30 s at dt = 1 ms, signals kept
every 2 ms. The target is under 0.1 s for one design. Also timed: the same run at
dt = 1.5 ms (near RK4's stability limit: the passenger's damped modes reach |λ| ≈ 1500 1/s),
the vehicle alone, to show where the time goes, and 100 designs (C_v from 200 to 2000 N s/m)
in one batch; each on the numpy engine and (when numba is installed) the compiled engine
(``simulation.engine``). Run: ``python benchmarks/bench_seat.py``. Prints a table; asserts
nothing.
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

CONFIG = Path(__file__).resolve().parents[1] / "configs" / "ch8" / "nss4_class_a_passenger.yaml"


def timed(cfg, params=None) -> tuple[float, float]:
    """Best of two wall times of simulate + the seat acceleration signal, and its mean r.m.s."""
    best, rms = np.inf, np.nan
    for _ in range(2):
        start = time.perf_counter()
        res = suspopt.simulate(cfg, params)
        acc = res.signals["seat.acc"] if cfg.seat is not None else res.signals["body.heave_acc"]
        best = min(best, time.perf_counter() - start)
        rms = float(np.mean(np.sqrt(np.mean(acc**2, axis=-1))))
    return best, rms


def main() -> None:
    memory = (
        "reused"
        if "--default-allocator" not in sys.argv[1:] and suspopt.reuse_memory()
        else "default"
    )
    print(
        f"suspopt {suspopt.__version__} | Python {platform.python_version()} | "
        f"numpy {np.__version__} | {platform.machine()} | freed memory {memory}"
    )
    cases = []
    cfg = suspopt.load_config(CONFIG)
    cfg.metrics = []  # time the simulation and one signal only
    cases.append(("QC + NSS4 + passenger, dt 1 ms (config)", cfg, None))
    fast = cfg.model_copy(deep=True)
    fast.simulation = fast.simulation.model_copy(update={"dt": 1.5e-3, "output_dt": 3.0e-3})
    cases.append(("QC + NSS4 + passenger, dt 1.5 ms", fast, None))
    bare = cfg.model_copy(deep=True)
    bare.seat = None
    cases.append(("QC alone, dt 1 ms", bare, None))
    batch = {"seat.damping": np.linspace(200.0, 2000.0, 100)}
    cases.append(("100 designs in one batch, dt 1 ms", cfg, batch))
    print(
        f"{cfg.road.speed * cfg.simulation.duration:.0f} m of class {cfg.road.road_class} "
        f"at {3.6 * cfg.road.speed:.0f} km/h ({cfg.simulation.duration} s)"
    )
    from suspopt.integrator import compiled_available

    engines = ["numpy"] + (["compiled"] if compiled_available() else [])
    print(
        f"{'case':<42} {'engine':>9} {'steps':>6} {'wall [s]':>9} {'us/step':>8} "
        f"{'s/design':>9} {'rms acc':>8}"
    )
    for label, c, params in cases:
        for engine in engines:
            run = c.model_copy(deep=True)
            run.simulation.engine = engine
            suspopt.simulate(run, params)  # warm-up (the compiled engine's cache)
            wall, rms = timed(run, params)
            steps, P = c.simulation.n_steps, 1 if params is None else len(params["seat.damping"])
            print(
                f"{label:<42} {engine:>9} {steps:>6} {wall:>9.3f} {1e6 * wall / steps:>8.1f} "
                f"{wall / P:>9.4f} {rms:>8.4f}"
            )


if __name__ == "__main__":
    main()
