"""The Ch. 8 PS seat fronts by the spectral method beside the time-domain fronts.

Optimises configs/ch8/pareto_ps_class_a.yaml and pareto_ps_class_b.yaml (NSGA-II,
population 100, 100 generations; objectives RC_se, the seat's Wk r.m.s. acceleration, and
X_ST) twice: with ``simulation.method: time`` (the bundled configs, on the compiled engine
when numba is installed) and with ``method: spectral``. Then it evaluates each front's
designs under the other method (same designs) and prints, per road class, a Markdown table:
the run times, the front sizes, and the RC_se of the same designs by both methods (the
largest, median and smallest relative difference), and each front's RC_se at three X_ST
levels.

Run: ``python examples/spectral_vs_time_ch8.py OUTDIR`` (a few minutes). Writes the four
Pareto files into OUTDIR and prints the tables for configs/README.md.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import suspopt
from suspopt.integrator import compiled_available
from suspopt.optimisation.run import optimise

CONFIGS = Path(__file__).resolve().parents[1] / "configs" / "ch8"


def _run(cfg, out: Path) -> tuple[float, np.ndarray, np.ndarray]:
    start = time.perf_counter()
    result = optimise(cfg, out)
    return time.perf_counter() - start, result.X, result.F


def _interpolated(X_ST: np.ndarray, RC: np.ndarray, at: float) -> float:
    order = np.argsort(X_ST)
    return float(np.interp(at, X_ST[order], RC[order]))


def main(outdir: Path) -> None:
    outdir.mkdir(parents=True, exist_ok=True)
    for road in ("a", "b"):
        base = suspopt.load_config(CONFIGS / f"pareto_ps_class_{road}.yaml")
        if compiled_available():
            base.simulation.engine = "compiled"
        runs, problems = {}, {}
        for method in ("time", "spectral"):
            cfg = base.model_copy(deep=True)
            cfg.simulation.method = method
            problems[method] = suspopt.Problem.from_config(cfg)
            runs[method] = _run(cfg, outdir / f"ps_class_{road}_{method}.h5")
        print(f"\n#### Class {road.upper()}\n")
        print("| front | run [s] | designs | RC_se by the other method: max / median / min "
              "relative difference |")  # fmt: skip
        print("|---|---|---|---|")
        other = {"time": "spectral", "spectral": "time"}
        for method, (wall, X, F) in runs.items():
            search = problems[other[method]].to_search(X)
            again = problems[other[method]].evaluate(search, return_values_of=["F"])
            diff = again[:, 0] / F[:, 0] - 1.0
            print(
                f"| {method} | {wall:.1f} | {len(X)} | {diff.max():+.2%} / "
                f"{np.median(diff):+.2%} / {diff.min():+.2%} |"
            )
        print("\n| X_ST [m] | RC_se time front [m/s^2] | RC_se spectral front [m/s^2] |")
        print("|---|---|---|")
        F_time, F_spectral = runs["time"][2], runs["spectral"][2]
        low = max(F_time[:, 1].min(), F_spectral[:, 1].min())
        high = min(F_time[:, 1].max(), F_spectral[:, 1].max())
        for at in np.linspace(low, high, 3):
            print(
                f"| {at:.4f} | {_interpolated(F_time[:, 1], F_time[:, 0], at):.4f} | "
                f"{_interpolated(F_spectral[:, 1], F_spectral[:, 0], at):.4f} |"
            )


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else "out/spectral_ch8"))
