"""Nominal-optimal against robust-optimal seats: configs/robust/ps.yaml and nss4.yaml.

For each seat (PS, NSS4) this optimises two problems with the same optimiser, budget, method
and engine:

- the **nominal** problem: the robust config without its ``scenarios:`` section, i.e. one
  class A road at 120 km/h with a 95 kg load (the thesis's Ch. 8 problem,
  configs/ch8/pareto_<seat>_class_a.yaml);
- the **robust** problem: the same designs evaluated under all nine scenarios (classes A-C at
  120/85/50 km/h x 75/95/115 kg on the isolator), worst-case RC_se and X_ST, every constraint
  in every scenario.

From each front it takes the knee (:func:`suspopt.choosing.kepsilon.pareto_picks`: the design nearest
the utopia point once the objectives are scaled to the front's range) and evaluates both
knees under every scenario with the robust problem's own evaluator
(:meth:`suspopt.Problem.scenario_values`), and simulates them in the time domain for the
seat's largest travel (PS) or its smallest mechanism travel margin (NSS4, the signal
``seat.travel_margin``: >= 0 while the mechanism's geometry holds). It prints a Markdown table
per seat with the run times and a sentence whose figures are computed from the table.

Run: ``python examples/robust_design.py OUTDIR [--population N --generations G]`` (the
configs' budget by default: population 100, 100 generations; about 20 minutes on two cores
with numba installed, most of it the NSS4 robust run). Writes the four Pareto files into
OUTDIR; the tables go into configs/robust/README.md.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import h5py
import numpy as np

import suspopt
from suspopt import streaming
from suspopt.choosing.kepsilon import pareto_picks
from suspopt.config.loader import edit_config, set_path
from suspopt.optimisation.run import optimise

CONFIGS = Path(__file__).resolve().parents[1] / "configs" / "robust"


def _configs(seat: str, population: int | None, generations: int | None):
    """The robust config and its nominal twin (the same text without ``scenarios:``)."""
    path = CONFIGS / f"{seat}.yaml"
    text = path.read_text()

    def budget(data: dict) -> None:
        if population:
            set_path(data, "optimiser.population", population)
        if generations:
            set_path(data, "optimiser.generations", generations)

    def nominal(data: dict) -> None:
        budget(data)
        del data["scenarios"]

    return edit_config(text, budget, path), edit_config(text, nominal, path)


def _optimised(cfg, out: Path, reuse: bool):
    """``(run time [s], X, F, G)`` of the front: optimised now, or read from ``out`` with
    ``reuse`` when it exists (its run time from its history)."""
    if reuse and out.exists():
        with h5py.File(out) as h5:
            wall = float(h5["history/time"][-1])
            return wall, h5["pareto/X"][...], h5["pareto/F"][...], h5["pareto/G"][...]
    start = time.perf_counter()
    result = optimise(cfg, out)
    return time.perf_counter() - start, result.X, result.F, result.G


def _dominated(points: np.ndarray, by: np.ndarray) -> np.ndarray:
    """Which rows of ``points (N, 2)`` some row of ``by (M, 2)`` dominates (both minimised)."""
    le = (by[None, :, :] <= points[:, None, :]).all(axis=2)
    lt = (by[None, :, :] < points[:, None, :]).any(axis=2)
    return (le & lt).any(axis=1)


def _travel(problem, X: np.ndarray, seat: str) -> np.ndarray:
    """(designs, scenarios): the largest |seat travel| [m] (PS) or the smallest mechanism
    travel margin [m] (NSS4) of each design under each scenario, simulated in the time
    domain (one simulation per scenario group)."""
    scenarios = problem.scenarios
    metric = (
        {"name": "travel", "metric": "max_abs", "signal": "seat.travel"}
        if seat == "ps"
        else {"name": "travel", "metric": "min", "signal": "seat.travel_margin"}
    )
    out = np.empty((len(X), len(scenarios.names)))
    params = problem.params(problem.to_search(X))
    for group in scenarios.groups:

        def timed(data: dict) -> None:
            data["metrics"] = [metric]
            data["simulation"]["method"] = "time"

        cfg = edit_config(group.cfg.text, timed, group.cfg.source)
        spec = cfg.metrics[0]
        roads = {"roads": group.roads} if group.roads else {}
        columns = scenarios.columns(group, params, len(X))
        result = streaming.reduce(cfg, columns, [(spec, [spec.signal])], **roads)
        values = result.metric(spec, spec.signal).reshape(len(group.members), len(X))
        out[:, group.members] = values.T
    return out


def _row(label, wall, FS, GS, travel, seat, names) -> tuple[str, dict]:
    RC, X_ST = FS[:, 0], FS[:, 1]
    feasible = int((GS <= 0).all(axis=1).sum())
    worst_travel = travel.max() if seat == "ps" else travel.min()
    nominal = names.index("A/95kg")
    figures = {"RC_worst": RC.max(), "RC_mean": RC.mean(), "travel": worst_travel}
    text = (
        f"| {label} | {RC[nominal]:.3f} | {RC.max():.3f} ({names[int(RC.argmax())]}) | "
        f"{RC.mean():.3f} | {1e3 * X_ST.max():.1f} | {1e3 * X_ST.mean():.1f} | "
        f"{1e3 * worst_travel:.1f} | {feasible} / {len(names)} | {wall:.0f} |"
    )
    return text, figures


def compare(seat: str, outdir: Path, population, generations, reuse: bool) -> None:
    robust_cfg, nominal_cfg = _configs(seat, population, generations)
    runs = {
        "nominal": _optimised(nominal_cfg, outdir / f"{seat}_nominal.h5", reuse),
        "robust": _optimised(robust_cfg, outdir / f"{seat}_robust.h5", reuse),
    }
    problem = suspopt.Problem.from_config(robust_cfg)
    names = problem.scenarios.names
    knees = {}
    for key, (_, X_front, F_front, G_front) in runs.items():
        sound = np.flatnonzero((G_front <= 0).all(axis=1))
        rows = sound if sound.size else np.arange(len(X_front))
        knees[key] = X_front[rows[pareto_picks(F_front[rows])["knee"]]]
    X = np.array([knees["nominal"], knees["robust"]])
    FS, GS = problem.scenario_values(X)
    travel = _travel(problem, X, seat)
    travel_head = "largest seat travel [mm]" if seat == "ps" else "smallest travel margin [mm]"
    opt = robust_cfg.optimiser
    print(f"\n#### {seat.upper()} (NSGA-II, population {opt.population}, "
          f"{opt.generations} generations)\n")  # fmt: skip
    print(
        "| knee of the | RC_se A/95kg [m/s²] | worst RC_se [m/s²] | mean RC_se [m/s²] | "
        f"worst X_ST [mm] | mean X_ST [mm] | {travel_head} | scenarios feasible | run [s] |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    figures = {}
    for i, key in enumerate(("nominal", "robust")):
        wall, X_front = runs[key][:2]
        text, figures[key] = _row(
            f"{key} front ({len(X_front)} designs)", wall, FS[i], GS[i], travel[i],
            seat, names,
        )  # fmt: skip
        print(text)
    _fronts_in_the_worst_case(problem, runs, FS[1])
    simulated = sum(
        group.cfg.simulation.duration * len(group.members) for group in problem.scenarios.groups
    )
    ratio = f"The robust run took {runs['robust'][0] / runs['nominal'][0]:.1f} times the nominal one's time"
    if nominal_cfg.simulation.method == "time":
        ratio += (
            f"; its scenarios are {simulated / nominal_cfg.simulation.duration:.1f} times "
            f"the nominal's simulated time per design"
        )
    print(ratio + ".")

    def change(key: str) -> str:
        before, after = figures["nominal"][key], figures["robust"][key]
        percent = 100 * (before - after) / before
        return f"{abs(percent):.1f} % {'lower' if percent >= 0 else 'higher'}"

    print(
        f"\nIn its worst scenario the robust knee's RC_se is {change('RC_worst')} than the "
        f"nominal knee's ({figures['robust']['RC_worst']:.3f} against "
        f"{figures['nominal']['RC_worst']:.3f} m/s²); averaged over the {len(names)} "
        f"scenarios it is {change('RC_mean')}."
    )


def _fronts_in_the_worst_case(problem, runs, robust_knee: np.ndarray) -> None:
    """The nominal front's designs under every scenario against the robust front, both as
    (worst RC_se, worst X_ST): how many of the nominal designs the robust front dominates, and
    the best worst-case RC_se the nominal designs reach at the robust knee's worst X_ST."""
    X_nominal = runs["nominal"][1]
    FS, GS = problem.scenario_values(X_nominal)
    worst = FS.max(axis=1)  # (N, 2): worst RC_se, worst X_ST
    holds = (GS <= 0).all(axis=(1, 2))
    robust = runs["robust"][2][(runs["robust"][3] <= 0).all(axis=1)]  # its F is the worst case
    beaten = _dominated(worst, robust)
    front = worst[holds & ~_dominated(worst, worst[holds])]
    order = np.argsort(front[:, 1])
    at = robust_knee[:, 1].max()
    print(
        f"\nUnder all nine scenarios, {holds.sum()} of the nominal front's {len(worst)} designs "
        f"hold every constraint, and the robust front dominates {beaten.sum()} of them in "
        f"(worst RC_se, worst X_ST)."
    )
    if front.size and front[order[0], 1] <= at <= front[order[-1], 1]:
        rc = float(np.interp(at, front[order, 1], front[order, 0]))
        knee = robust_knee[:, 0].max()
        percent = 100 * (rc - knee) / rc
        print(
            f"At the robust knee's worst X_ST ({1e3 * at:.1f} mm) the nominal designs' worst "
            f"RC_se is at best {rc:.3f} m/s² (interpolated along their worst-case front); the "
            f"robust knee's is {knee:.3f} m/s², {abs(percent):.1f} % "
            f"{'lower' if percent >= 0 else 'higher'}."
        )
    elif not front.size:
        print(
            "None of the nominal designs holds every constraint in every scenario: no "
            "comparison at equal deflection."
        )
    else:
        print(
            f"The robust knee's worst X_ST ({1e3 * at:.1f} mm) lies outside the worst X_ST "
            f"the nominal designs reach ({1e3 * front[:, 1].min():.1f}-"
            f"{1e3 * front[:, 1].max():.1f} mm): no comparison at equal deflection."
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("outdir", type=Path)
    parser.add_argument("--population", type=int)
    parser.add_argument("--generations", type=int)
    parser.add_argument("--seats", nargs="+", default=["ps", "nss4"], choices=["ps", "nss4"])
    parser.add_argument("--reuse", action="store_true", help="read the fronts OUTDIR already holds")
    args = parser.parse_args()
    args.outdir.mkdir(parents=True, exist_ok=True)
    for seat in args.seats:
        compare(seat, args.outdir, args.population, args.generations, args.reuse)


if __name__ == "__main__":
    main()
