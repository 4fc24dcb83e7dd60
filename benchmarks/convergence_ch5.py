"""How the Chapter 5 objectives depend on the integration step: the basis of the ch5 configs'
``dt = 2 ms``.

40 designs drawn uniformly inside the Table 5.2 bounds (configs/ch5/case4_s1.yaml: HC2 of
Table 5.1, Duffing springs, the 40 km/h half-sine bump) are evaluated through
``Problem.evaluate`` at several steps ``dt`` (the signals sampled at ``dt``). The table gives
the largest relative difference of f1-f3 (Eq 5.4-5.6) and of RC (Eq 5.2) over the designs:

- ``vs 0.25 ms``: against the run at dt = 0.25 ms - the whole effect of the step, i.e. of RK4's
  error and of computing the statistics on a coarser sample grid;
- ``RK4 only``: against a run at dt = 0.25 ms whose signals are kept on the same grid as
  ``dt`` (``output_dt = dt``) - the integrator's own error.

Run: ``python benchmarks/convergence_ch5.py``. Prints a table; asserts nothing.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import suspopt

CONFIG = Path(__file__).resolve().parents[1] / "configs" / "ch5" / "case4_s1.yaml"
FINE = 0.25e-3
STEPS = (0.5e-3, 1.0e-3, 2.0e-3, 2.5e-3, 3.0e-3, 4.0e-3, 5.0e-3)


def objectives(cfg, X: np.ndarray, dt: float, output_dt: float) -> np.ndarray:
    """f1, f2, f3 and RC of the designs X (N, n) at the step dt, sampled every output_dt."""
    c = cfg.model_copy(deep=True)
    c.simulation = c.simulation.model_copy(update={"dt": dt, "output_dt": output_dt})
    problem = suspopt.Problem.from_config(c)
    F, G = problem.evaluate(X, return_values_of=["F", "G"])
    return np.column_stack([F, G[:, 0] + cfg.constraints[0].max])


def main() -> None:
    cfg = suspopt.load_config(CONFIG)
    problem = suspopt.Problem.from_config(cfg)
    X = problem.xl + np.random.default_rng(3).random((40, problem.n_var)) * (
        problem.xu - problem.xl
    )
    reference = objectives(cfg, X, FINE, FINE)
    print(f"Ch. 5 HC2 ({CONFIG.name}), 40 designs; max relative difference over the designs")
    print(
        f"{'dt [ms]':>8}  {'vs 0.25 ms: f1':>14} {'f2':>9} {'f3':>9} {'RC':>9}   "
        f"{'RK4 only: f1':>12} {'f2':>9} {'f3':>9} {'RC':>9}"
    )
    for dt in STEPS:
        coarse = objectives(cfg, X, dt, dt)
        whole = np.max(np.abs(coarse / reference - 1.0), axis=0)
        ratio = dt / FINE
        if abs(ratio - round(ratio)) < 1e-9:
            same_grid = objectives(cfg, X, FINE, dt)
            own = np.max(np.abs(coarse / same_grid - 1.0), axis=0)
            tail = " ".join(f"{v:>9.1e}" for v in own)
        else:
            tail = "(not a multiple of 0.25 ms)"
        print(
            f"{1e3 * dt:>8.2f}  {whole[0]:>14.1e} "
            + " ".join(f"{v:>9.1e}" for v in whole[1:])
            + f"   {tail}"
        )


if __name__ == "__main__":
    main()
