"""Designs evaluated per second by ``simulation.method: spectral`` and by the time domain, in
the same run, on two linear random-road problems:

- the Ch. 3 class-B quarter car (configs/ch3/part1a_qc_class_b.yaml: 60 s at dt = 1 ms),
  objectives the body acceleration's variance and Wk r.m.s. and the travel's variance, its
  spring and damper drawn within -50 % .. +100 % of the config's;
- the Ch. 8 PS seat problem (configs/ch8/pareto_ps_class_a.yaml: the seat's Wk r.m.s. over
  1000 m of class A, 30 s at dt = 1 ms), its K_v and C_v drawn inside their bounds.

Each is ``Problem.evaluate`` of P designs (best of two calls; the time domain on the engine
``--engine`` names, default compiled when numba is installed), with the largest relative
difference of the objectives between the two methods (the time domain's finite road and its
start from rest against the stationary value). The time domain at P = 10000 is timed once.

A second table times the spectral method on batches of 2000 designs of which one, or every
one, never converges (its damping 1e-9 of the bound's: a resonance narrower than the finest
grid), with the peak of the arrays numpy allocated meanwhile (tracemalloc, a second call):
the refinement computes the designs not yet converged alone, in parts that fit
``spectral.REFINE_BYTES``.

Run: ``python benchmarks/bench_spectral.py [--sizes 1,100,10000] [--no-unconverged]``.
Prints tables; asserts nothing.
"""

from __future__ import annotations

import argparse
import platform
import time
import tracemalloc
from pathlib import Path

import numpy as np

import suspopt
from suspopt.integrator import compiled_available

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
QC = """
design_variables:
  - {name: k, path: vehicle.corners.F1.spring.linear, lower: LOWK, upper: HIGHK}
  - {name: c, path: vehicle.corners.F1.damper.c, lower: LOWC, upper: HIGHC}
objectives:
  main:
    - {name: acc_var, metric: var, signal: body.heave_acc}
    - {name: acc_Wk, metric: rms_weighted, signal: body.heave_acc, weighting: Wk}
    - {name: travel_var, metric: var, signal: travel.F1}
optimiser: {algorithm: nsga2, seed: 1, population: 10, generations: 1}
"""


def _qc_config():
    cfg = suspopt.load_config(CONFIGS / "ch3" / "part1a_qc_class_b.yaml")
    corner = cfg.vehicle.corners["F1"]
    k, c = corner.spring.linear, corner.damper.c
    text = (CONFIGS / "ch3" / "part1a_qc_class_b.yaml").read_text() + QC.replace(
        "LOWK", f"{0.5 * k:g}"
    ).replace("HIGHK", f"{2 * k:g}").replace("LOWC", f"{0.5 * c:g}").replace("HIGHC", f"{2 * c:g}")
    from suspopt.config.loader import load_config_text

    return load_config_text(text, CONFIGS / "ch3" / "qc_study.yaml")


def _problems(method: str, engine: str):
    out = {}
    for label, cfg in (
        ("Ch. 3 QC class B", _qc_config()),
        ("Ch. 8 PS class A", suspopt.load_config(CONFIGS / "ch8" / "pareto_ps_class_a.yaml")),
    ):
        cfg = cfg.model_copy(deep=True)
        cfg.simulation.method = method
        cfg.simulation.engine = engine
        out[label] = suspopt.Problem.from_config(cfg)
    return out


def _timed(problem, X, repeats: int):
    wall, F = np.inf, None
    for _ in range(repeats):
        start = time.perf_counter()
        F = problem.evaluate(X, return_values_of=["F"])
        wall = min(wall, time.perf_counter() - start)
    return wall, F


def _unconverged(problems, P: int = 2000) -> None:
    """The second table (module docstring); ``failed`` counts the designs whose
    ``simulation_failed`` constraint is violated."""
    print(
        f"\n{'problem':<18} {'P':>6} {'never converge':>15} {'failed':>7} "
        f"{'spectral [s]':>13} {'peak [MB]':>10}"
    )
    rng = np.random.default_rng(2027)
    for label, problem in problems.items():
        damping = [i for i, name in enumerate(problem.var_names) if name in ("c", "C_v")][0]
        for bad in (1, P):
            X = rng.uniform(problem.xl, problem.xu, (P, problem.n_var))
            X[:bad, damping] = 1e-9 * problem.xl[damping]
            start = time.perf_counter()
            G = problem.evaluate(X, return_values_of=["G"])
            wall = time.perf_counter() - start
            tracemalloc.start()
            problem.evaluate(X, return_values_of=["G"])
            peak = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
            failed = int(np.sum(G[:, -1] > 0))
            print(f"{label:<18} {P:>6} {bad:>15} {failed:>7} {wall:>13.2f} {peak / 2**20:>10.0f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="1,100,10000")
    parser.add_argument("--engine", default="compiled" if compiled_available() else "numpy")
    parser.add_argument("--no-unconverged", action="store_true", help="leave the second table out")
    args = parser.parse_args()
    suspopt.reuse_memory()
    sizes = [int(s) for s in args.sizes.split(",")]
    spectral, timed = _problems("spectral", args.engine), _problems("time", args.engine)
    print(
        f"suspopt {suspopt.__version__} | Python {platform.python_version()} | "
        f"numpy {np.__version__} | time domain on the {args.engine} engine"
    )
    print(
        f"{'problem':<18} {'P':>6} {'spectral [designs/s]':>21} {'time [designs/s]':>17} "
        f"{'ratio':>8} {'max rel diff F':>15}"
    )
    rng = np.random.default_rng(2026)
    for label in spectral:
        problem = spectral[label]
        for P in sizes:
            X = rng.uniform(problem.xl, problem.xu, (P, problem.n_var))
            timed[label].evaluate(X[:2])  # warm-up (imports, compilation)
            problem.evaluate(X[:2])
            s_wall, Fs = _timed(problem, X, 2)
            t_wall, Ft = _timed(timed[label], X, 1 if P >= 10000 else 2)
            diff = np.max(np.abs(Fs / Ft - 1.0))
            print(
                f"{label:<18} {P:>6} {P / s_wall:>21.0f} {P / t_wall:>17.1f} "
                f"{t_wall / s_wall:>7.2g}x {diff:>15.2e}"  # (below 1: the time domain is faster)
            )
    if not args.no_unconverged:
        _unconverged(spectral)


if __name__ == "__main__":
    main()
