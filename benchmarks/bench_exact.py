"""The exact stepper (``simulation.method: exact``) against RK4 at the same ``dt``, in one run.

For each linear optimisation config of Ch. 5-8 (the others have a Duffing spring, a
semi-active controller or a non-linear seat, which the exact stepper refuses) and the Ch. 3
quarter and half car on class B: ``Problem.evaluate`` of F and G for P random designs (seed
2026), on RK4's compiled engine and with ``simulation.method: exact``, each timed best of 3
after a warm-up, the duration cut to ``--duration`` seconds for both; the designs/s of each,
their ratio, and the largest relative difference of the objectives (RK4's error at that
``dt`` plus the road's first-order hold). Run: ``python benchmarks/bench_exact.py [--designs
P] [--duration S]``. Prints the table; asserts nothing.
"""

from __future__ import annotations

import argparse
import platform
import time
from datetime import date
from functools import partial
from pathlib import Path

import numpy as np

import suspopt

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = ("ch8/pareto_ps_class_a.yaml", "ch8/pareto_ps_class_b.yaml")
CH3 = ("ch3/part1a_qc_class_b.yaml", "ch3/part1a_hc2_class_b.yaml")


def _problem(name: str, method: str, duration: float):
    cfg = suspopt.load_config(ROOT / "configs" / name)
    cfg.simulation.duration, cfg.simulation.method = duration, method
    cfg.simulation.engine = "compiled"
    return suspopt.Problem.from_config(cfg)


def _best(fn, rounds: int = 3) -> float:
    fn()
    times = []
    for _ in range(rounds):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def _simulated(name: str, method: str, duration: float, P: int):
    """A Ch. 3 config (no optimiser): P copies of its design, simulated with its metrics."""
    cfg = suspopt.load_config(ROOT / "configs" / name)
    cfg.simulation.duration, cfg.simulation.method = duration, method
    cfg.simulation.engine = "compiled"
    path = "vehicle.corners.F1.damper.c"
    c = np.linspace(800.0, 2400.0, P)

    def run():
        return suspopt.simulate(cfg, params={path: c}).signals["body.heave_acc"]

    return run


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--designs", type=int, default=200)
    parser.add_argument("--duration", type=float, default=10.0)
    args = parser.parse_args()
    P, duration = args.designs, args.duration
    print(f"{date.today()}, suspopt {suspopt.__version__}, "
          f"{platform.processor() or platform.machine()}; P = {P}, {duration:g} s")  # fmt: skip
    print(f"{'config':<30} {'dt [s]':>7} {'RK4 [designs/s]':>16} {'exact [designs/s]':>18} "
          f"{'ratio':>6} {'largest rel. diff.':>19}")  # fmt: skip
    for name in CONFIGS:
        rk4, ex = (_problem(name, m, duration) for m in ("time", "exact"))
        X = rk4.xl + np.random.default_rng(2026).random((P, rk4.n_var)) * (rk4.xu - rk4.xl)
        t_rk4 = _best(partial(rk4.evaluate, X, return_values_of=["F"]))
        t_ex = _best(partial(ex.evaluate, X, return_values_of=["F"]))
        F_rk4, F_ex = (p.evaluate(X, return_values_of=["F"]) for p in (rk4, ex))
        diff = np.max(np.abs(F_ex / F_rk4 - 1.0))
        print(f"{name:<30} {rk4.cfg.simulation.dt:>7.0e} {P / t_rk4:>16.0f} {P / t_ex:>18.0f} "
              f"{t_rk4 / t_ex:>6.2f} {diff:>19.1e}")  # fmt: skip
    for name in CH3:
        runs = {m: _simulated(name, m, duration, P) for m in ("time", "exact")}
        t_rk4, t_ex = _best(runs["time"]), _best(runs["exact"])
        a, b = runs["exact"](), runs["time"]()
        diff = np.max(np.abs(a - b)) / np.max(np.abs(b))
        dt = suspopt.load_config(ROOT / "configs" / name).simulation.dt
        print(f"{name + ' (simulate)':<30} {dt:>7.0e} {P / t_rk4:>16.0f} {P / t_ex:>18.0f} "
              f"{t_rk4 / t_ex:>6.2f} {diff:>19.1e}")  # fmt: skip


if __name__ == "__main__":
    main()
