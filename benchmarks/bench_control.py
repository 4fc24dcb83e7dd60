"""Cost of the semi-active controller relative to the same model with passive dampers.

Two problems: the Table 4.1 quarter car on class C at 50 km/h (configs/ch4/sh_2_class_c.yaml,
5 s) and the Table 3.1 full car on class B (configs/ch3/part1b_fc_class_b.yaml, 2 s), both at
dt = 1 ms with ΔT = 4 ms and every step kept. For P = 1, 100 and 1000 designs (front spring
stiffness drawn within +-20 %) it times one batched simulate call of: the passive damper
(c = C_min), SH-2, SH-ADD-2 (which evaluates the equations of motion at each sample), SH-2 with
a 10 ms actuator lag, and SH-2 with an adaptive CDF threshold refitted every 1 s (empirical
quantile; Student-t, fitted from the controller's bounded summary of the history,
``suspopt.control.StudentTSummary``).

Two figures per variant: ``total``, the process CPU time of the whole call over the passive
call's (best of several interleaved rounds; CPU time because the development machine is shared
and wall time swings by tens of per cent), and ``own``, the time spent inside the controller
(start, sample, record: the laws, the sampling, the refits) over the passive call's. ``total``
also contains the simulator keeping the controller's records (three per-corner signals and the
coefficient) once per change (every ΔT) and publishing them, which a run does only when one is
first read and the benchmark makes it do (expanding them to every output sample, when a signal
is read, is not timed); the last row keeps every 4th step instead of every step. Run:
``python benchmarks/bench_control.py [--engine compiled]`` (``simulation.engine`` of every
variant; default numpy).
Like the command line, it first makes the allocator reuse freed memory
(:func:`suspopt.reuse_memory`); ``--default-allocator`` leaves it as it is.
Prints a table; asserts nothing.
"""

from __future__ import annotations

import importlib
import platform
import sys
import time
from pathlib import Path

import numpy as np

import suspopt
from suspopt.config.control import Control, Threshold
from suspopt.config.vehicle import PassiveDamper, SemiActiveDamper

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
PROBLEMS = {
    "QC Table 4.1, class C, 5 s": (CONFIGS / "ch4" / "sh_2_class_c.yaml", 5.0),
    "FC Table 3.1, class B, 2 s": (CONFIGS / "ch3" / "part1b_fc_class_b.yaml", 2.0),
}
#: (designs, rounds, output_dt [s]; None keeps every step as the configs do)
SIZES = ((1, 15, None), (100, 10, None), (1000, 6, None), (1000, 6, 0.004))
_simulate_module = importlib.import_module("suspopt.simulation")
_build_controller = _simulate_module.build_controller


def variants(cfg) -> dict:
    """The passive model and the controlled ones, as configs."""
    out = {}
    for name, law, control in (
        ("passive", None, None),
        ("SH-2", "sh_2", Control()),
        ("SH-ADD-2", "sh_add_2", Control()),
        ("SH-2 lag", "sh_2", Control(actuator_lag=0.01)),
        (
            "SH-2 CDF empir.",
            "sh_2",
            Control(
                threshold=Threshold(
                    mode="adaptive", c_max_share=0.27, learn_time=1.0, distribution="empirical"
                )
            ),
        ),
        (
            "SH-2 CDF t",
            "sh_2",
            Control(threshold=Threshold(mode="adaptive", c_max_share=0.27, learn_time=1.0)),
        ),
    ):
        v = cfg.model_copy(deep=True)
        v.metrics = []
        v.control = control
        for corner in v.vehicle.corners.values():
            d = corner.damper
            corner.damper = (
                PassiveDamper(c=d.c_min)
                if law is None
                else SemiActiveDamper(
                    kind="semi_active",
                    c_min=d.c_min,
                    c_max=d.c_max,
                    law=law,
                    crossover_frequency=39.0 if law == "sh_add_2" else None,
                )
            )
        out[name] = v
    return out


class _Timed:
    """A controller whose start, sample and record add their wall time to ``spent``; every
    other attribute is the controller's own."""

    def __init__(self, inner):
        self.inner, self.spent = inner, 0.0
        for name in ("start", "sample", "record"):
            setattr(self, name, self._timed(getattr(inner, name)))

    def __getattr__(self, name):
        return getattr(self.inner, name)

    def _timed(self, method):
        def call(*args):
            start = time.perf_counter()
            out = method(*args)
            self.spent += time.perf_counter() - start
            return out

        return call


def run(cfg, params) -> tuple[float, float, float]:
    """CPU time and wall time of one simulate call, and the wall time inside the controller."""
    timed = []

    def build(*args):
        controller = _build_controller(*args)
        if controller is not None:
            timed.append(_Timed(controller))
            return timed[-1]
        return None

    _simulate_module.build_controller = build
    try:
        cpu, wall = time.process_time(), time.perf_counter()
        result = suspopt.simulate(cfg, params=params)
        for name in result.controller_records:  # published when first read: counted
            result.controller_records[name]
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    finally:
        _simulate_module.build_controller = _build_controller
    return cpu, wall, (timed[0].spent if timed else 0.0)


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
    print(
        "cells: CPU time over the passive run's (total) / time inside the controller over "
        "the passive run's (own)"
    )
    engine = sys.argv[sys.argv.index("--engine") + 1] if "--engine" in sys.argv else "numpy"
    print(f"engine: {engine}")
    rng = np.random.default_rng(2026)
    for title, (path, duration) in PROBLEMS.items():
        cfg = suspopt.load_config(path)
        cfg.simulation.duration = duration
        cfg.simulation.engine = engine
        configs = variants(cfg)
        k = cfg.vehicle.corners["F1"].spring.linear
        print(f"\n{title}: {cfg.simulation.n_steps} RK4 steps")
        print(
            f"{'P':>5} {'passive CPU':>12} "
            + " ".join(f"{n:>16}" for n in configs if n != "passive")
        )
        for P, rounds, output_dt in SIZES:
            params = {"vehicle.corners.F1.spring.linear": rng.uniform(0.8 * k, 1.2 * k, P)}
            best = {name: (np.inf, np.inf) for name in configs}
            for _ in range(rounds):  # interleaved, best of the rounds
                for name, c in configs.items():
                    c.simulation.output_dt = output_dt
                    cpu, _wall, own = run(c, params)
                    best[name] = (min(best[name][0], cpu), min(best[name][1], own))
            base = best["passive"][0]
            cells = [
                f"{100 * (cpu / base - 1):+4.0f} % / {100 * own / base:3.0f} %".rjust(16)
                for name, (cpu, own) in best.items()
                if name != "passive"
            ]
            label = f"{P}" if output_dt is None else f"{P}*"
            print(f"{label:>5} {base:>10.2f} s " + " ".join(cells))
    print(
        "\n* output every 4 ms (= ΔT) instead of every step: the simulator stores a quarter of "
        "the samples and records"
    )


if __name__ == "__main__":
    main()
