"""Evaluations per second of the Chapter 5 HC2 problem: batched ``Problem.evaluate`` against a
straightforward per-design ``scipy.integrate.solve_ivp`` evaluation of the same designs.

The problem is configs/ch5/case4_s1.yaml: Table 5.1 half car with Duffing springs over the
half-sine bump (0.05 m, base 1 m, 40 km/h), 3 s at dt = 2 ms, objectives f1-f3 (Eq 5.4-5.6) and
constraints Eq 5.2-5.3. Designs are drawn uniformly inside the Table 5.2 bounds.

The per-design path writes the HC2 right-hand side here from the model's parameter arrays
(``suspopt.build_vehicle(cfg, ParamView(cfg, params))``: masses, travel map, spring, damper
and tyre coefficients) and the bump from the road section, integrates it with RK45
(``rtol = 1e-4``, ``max_step`` a quarter of the bump's duration), samples it on the same 2 ms
grid and computes the same objectives and constraints with the public metric functions. It runs
on the first ``--per-design`` designs (default 40) and its rate is per design. The batched
path is timed as the best of ``REPEATS`` calls on the whole population, each engine's after a
pause of ``QUIET`` (OpenBLAS's spinning threads), on the numpy engine
and (when numba is installed) the compiled engine (``simulation.engine: compiled``), whose
objectives are also compared with the numpy engine's.

Run: ``python benchmarks/bench_optimise.py``. Prints a table; asserts nothing.
Like the command line, it first makes the allocator reuse freed memory
(:func:`suspopt.reuse_memory`); ``--default-allocator`` leaves it as it is.
"""

from __future__ import annotations

import argparse
import platform
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import suspopt
from suspopt.metrics import iso2631, nonlinear_spring_usage
from suspopt.params import ParamView

CONFIG = Path(__file__).resolve().parents[1] / "configs" / "ch5" / "case4_s1.yaml"
#: RK45 tolerances of the per-design path. Against rtol = 1e-10 on 40 designs, f1-f3 differ by
#: at most 0.47 % at rtol = 1e-3, 0.12 % at 1e-4 and 0.016 % at 1e-5; max_step bounds the
#: step, so 1e-3 and 1e-4 run equally fast: 1e-4 keeps a margin to the 0.5 % target.
RTOL, ATOL = 1.0e-4, 1.0e-7
#: Batched calls timed per population size (the best counts): an optimiser evaluates one
#: population after another, and the first call of a size also pays the operating system for
#: memory the process has not touched before.
REPEATS = 3
#: Pause before an engine's timed calls [s]. OpenBLAS's threads keep spinning for about 0.1 s
#: after its last product (its thread time-out, 2**28 cycles), so calls right after the numpy
#: engine's share the cores with them: the compiled engine's evaluation of 200 designs took
#: 7.5-18.9 ms in the first five calls after the numpy engine's and 7.3-8.7 ms after a 0.3 s
#: pause (2026-12-05). An optimiser runs one engine and never pays this.
QUIET = 0.3


def bump(road, offsets: np.ndarray, t) -> tuple[np.ndarray, np.ndarray]:
    """Half-sine bump height and rate under each wheel, (..., N) at times t (...,) (slip:
    docs/thesis-slips.md#eq-2101)."""
    t = np.asarray(t)[..., None]
    t0 = road.start + offsets / road.speed
    duration = road.length / road.speed
    phase = np.pi * (t - t0) / duration
    on = (t >= t0) & (t < t0 + duration)
    return (
        np.where(on, road.height * np.sin(phase), 0.0),
        np.where(on, road.height * np.pi / duration * np.cos(phase), 0.0),
    )


def per_design(cfg, values: dict[str, float], time_grid: np.ndarray) -> np.ndarray:
    """f1, f2, f3 and the Eq 5.2-5.3 constraint values of one design, by solve_ivp."""
    model = suspopt.build_vehicle(cfg, ParamView(cfg, {k: [v] for k, v in values.items()}))
    mass = model.mass[0, 0]
    J = model.travel_map[0]
    k_l, k_nl = model.spring_linear[0, 0], model.spring_cubic[0, 0]
    c, k_t, c_t = model.damper[0, 0], model.tyre_stiffness[0, 0], model.tyre_damping[0, 0]
    wheels, offsets, n = model.wheels, model.offsets, model.n_dof

    def acceleration(t, q, v):
        """q'' at times t (...,) from q, v (..., n)."""
        travel, rate = q @ J.T, v @ J.T
        force = -(k_l * travel + k_nl * travel**3 + c * rate) @ J
        z, zdot = bump(cfg.road, offsets, t)
        force[..., wheels] += k_t * (z - q[..., wheels]) + c_t * (zdot - v[..., wheels])
        return force / mass

    def rhs(t, y):
        return np.concatenate([y[n:], acceleration(t, y[:n], y[n:])])

    duration = cfg.road.length / cfg.road.speed
    sol = solve_ivp(
        rhs,
        (0.0, time_grid[-1]),
        np.zeros(2 * n),
        method="RK45",
        t_eval=time_grid,
        rtol=RTOL,
        atol=ATOL,
        max_step=duration / 4,
    )
    q, v = sol.y[:n].T, sol.y[n:].T
    heave_acc = acceleration(time_grid, q, v)[:, 0]
    travel = q @ J.T
    tyre = q[:, wheels] - bump(cfg.road, offsets, time_grid)[0]
    fs = 1.0 / (time_grid[1] - time_grid[0])
    usage = nonlinear_spring_usage(travel.T, k_l, k_nl)
    return np.concatenate(
        [
            [
                np.var(heave_acc),
                np.var(travel, axis=0).mean(),
                np.var(tyre, axis=0).mean(),
                iso2631.weighted_rms(heave_acc, fs, "Wk"),
            ],
            usage,
        ]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--default-allocator",
        action="store_true",
        help="leave glibc's allocator as it is (the command line makes it "
        "reuse freed memory, suspopt.reuse_memory)",
    )
    parser.add_argument(
        "--per-design", type=int, default=40, help="designs evaluated one by one with solve_ivp"
    )
    args = parser.parse_args()
    memory = "reused" if not args.default_allocator and suspopt.reuse_memory() else "default"
    cfg = suspopt.load_config(CONFIG)
    from suspopt.integrator import compiled_available

    problems = {}
    for engine in ["numpy"] + (["compiled"] if compiled_available() else []):
        c = cfg.model_copy(deep=True)
        c.simulation.engine = engine
        problems[engine] = suspopt.Problem.from_config(c)
    problem = problems["numpy"]
    rng = np.random.default_rng(2026)
    for p in problems.values():  # warm-up (imports, the compiled engine's cache)
        p.evaluate(problem.xl[None] + 0.5 * (problem.xu - problem.xl)[None])
    print(
        f"suspopt {suspopt.__version__} | Python {platform.python_version()} | "
        f"numpy {np.__version__} | {platform.machine()} | freed memory {memory}"
    )
    print(
        f"Ch. 5 HC2 problem ({CONFIG.name}): {problem.n_var} variables, {problem.n_obj} "
        f"objectives, {problem.n_ieq_constr} constraints, {cfg.simulation.duration} s at "
        f"dt = {cfg.simulation.dt} s"
    )
    time_grid = np.arange(cfg.simulation.n_steps + 1) * cfg.simulation.dt
    print(
        f"{'P':>6} {'engine':>9} {'batched [s]':>12} {'batched /s':>11} {'solve_ivp /s':>13} "
        f"{'speed-up':>9} {'vs solve_ivp f1-f3':>19} {'vs numpy f1-f3':>15}"
    )
    for P in (200, 1000):
        X = problem.xl + rng.random((P, problem.n_var)) * (problem.xu - problem.xl)
        results = {}
        for engine, p in problems.items():
            time.sleep(QUIET)
            batched = np.inf
            for _ in range(REPEATS):  # the optimiser's steady state, one generation
                start = time.perf_counter()
                F, G = p.evaluate(X, return_values_of=["F", "G"])
                batched = min(batched, time.perf_counter() - start)
            results[engine] = (batched, F, G)
        designs = problem.to_physical(X[: args.per_design])
        start = time.perf_counter()
        reference = np.array(
            [
                per_design(cfg, dict(zip((v.path for v in problem.variables), row)), time_grid)
                for row in designs
            ]
        )
        single = (time.perf_counter() - start) / len(designs)
        F0 = results["numpy"][1]
        for engine, (batched, F, G) in results.items():
            diff = np.max(np.abs(F[: len(designs)] - reference[:, :3]) / np.abs(reference[:, :3]))
            rc = np.max(np.abs(G[: len(designs), 0] + 0.8 - reference[:, 3]) / reference[:, 3])
            same = np.max(np.abs(F - F0) / np.abs(F0))
            print(
                f"{P:>6} {engine:>9} {batched:>12.2f} {P / batched:>11.1f} {1 / single:>13.2f} "
                f"{single * P / batched:>8.1f}x {diff:>19.2e} {same:>15.1e}   (RC: {rc:.1e})"
            )


if __name__ == "__main__":
    main()
