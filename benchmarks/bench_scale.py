"""One evaluation of the Ch. 6 Part B population on each executor of :mod:`suspopt.execution`:
``local`` (this process), ``processes`` with 2 workers and ``dask`` with a LocalCluster of 2
single-threaded worker processes, wall time and speed-up over ``local`` in one run; then what
one chunk costs each executor on empty work (a task that returns at once).

The problem is configs/ch6/part_b.yaml (the Ch. 5 half car on the bump with the PS seat and
the seated passenger, passive) at population ``--population`` (default 1000), in chunks of ``--chunk`` designs
(default the config's: 250 for configs/ch6/part_b.yaml). Each executor first evaluates the population once (its start:
processes and imports, the problem sent to every worker), then the best of ``REPEATS`` calls
counts. The objectives of every executor are compared bit for bit with ``local``'s.

Run: ``python benchmarks/bench_scale.py [--engine numpy|compiled]``. Prints a table; asserts
nothing.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

# as the command line does (suspopt._entry): one BLAS thread, so that ``local`` is the
# single-process baseline and the workers do not fight over the cores
for _name in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import numpy as np  # noqa: E402

import suspopt  # noqa: E402
from suspopt import execution  # noqa: E402

CONFIG = Path(__file__).resolve().parents[1] / "configs" / "ch6" / "part_b.yaml"
REPEATS = 2
#: Empty tasks timed per executor for the per-chunk overhead.
EMPTY = 400


def _nothing(shared, item):
    return item


def _timed(function) -> float:
    best = np.inf
    for _ in range(REPEATS):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--population", type=int, default=1000)
    parser.add_argument("--chunk", type=int, default=None)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--engine", default="numpy", choices=["numpy", "compiled"])
    args = parser.parse_args()
    suspopt.reuse_memory()
    cfg = suspopt.load_config(CONFIG)
    cfg.simulation.engine = args.engine
    if args.chunk is not None:
        cfg.execution.chunk = args.chunk
    problem = suspopt.Problem.from_config(cfg)
    rng = np.random.default_rng(2026)
    X = problem.xl + rng.random((args.population, problem.n_var)) * (problem.xu - problem.xl)
    print(
        f"suspopt {suspopt.__version__} | Python {platform.python_version()} | "
        f"{os.cpu_count()} cores | engine {args.engine}"
    )
    print(
        f"Ch. 6 Part B ({CONFIG.name}): P = {args.population}, chunks of "
        f"{cfg.execution.chunk} designs, {cfg.simulation.duration} s at dt = {cfg.simulation.dt} s"
    )
    print(
        f"{'executor':>10} {'workers':>8} {'start [s]':>10} {'evaluate [s]':>13} "
        f"{'speed-up':>9} {'same bits':>10} {'empty chunk [ms]':>17}"
    )
    F0 = None
    local_time = None
    for name in ("local", "processes", "dask"):
        workers = 1 if name == "local" else args.workers
        with execution.use(name, workers=None if name == "local" else workers):
            start = time.perf_counter()
            F = problem.evaluate(X, return_values_of=["F"])
            first = time.perf_counter() - start
            best = _timed(lambda: problem.evaluate(X, return_values_of=["F"]))
            executor = execution.executor_for(cfg.execution)
            items = list(range(EMPTY))
            executor.map(_nothing, None, items)  # warm
            empty = _timed(lambda e=executor, i=items: e.map(_nothing, None, i)) / EMPTY
        if F0 is None:
            F0, local_time = F, best
        same = "yes" if np.array_equal(F, F0) else "NO"
        print(
            f"{name:>10} {workers:>8} {max(first - best, 0.0):>10.2f} {best:>13.3f} "
            f"{local_time / best:>8.2f}x {same:>10} {1e3 * empty:>17.3f}"
        )


if __name__ == "__main__":
    main()
