"""Shared parts of the reproduction report (examples/report.py): the conclusions' thresholds and wording, reading the runs' files, re-simulating stored optima, the Markdown document."""

from __future__ import annotations

import math
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mdtables as md

import suspopt
from suspopt.choosing.selection import read_pareto
from suspopt.config.metrics import MetricSpec

THESIS = md.thesis_values()
CHAPTERS = {
    3: "Vehicle models",
    4: "The CDF strategy for semi-active dampers",
    5: "Optimisation methods and fitness functions",
    6: "Main and supplementary objectives (k-ε)",
    7: "Semi-active suspensions (k-ε)",
    8: "Seat suspensions",
}
SCENARIOS = ("S1", "S2", "S3", "S4", "S5")


# --- the report's conclusions: thresholds and wording -------------------------------------------
# Every judgement the report prints beside a number (converged, agrees, the same, above, ...)
# is computed from that number with one of these thresholds, so the wording turns when the
# measurement crosses it.

#: [%] a value is converged in the step size when halving dt moves it by less than 1 %:
#: well below the 2-3 significant digits the thesis prints, so finer steps cannot change a
#: comparison with it.
CONVERGED = 1.0
#: [%] two values agree (ours and the thesis's, or a set of values hardly varies) when they
#: differ by less than 5 %: a value the thesis prints with two digits (0.14) carries up to
#: 3.6 % of rounding alone, and its road realisation and solver are unknown.
AGREE = 5.0
#: [%] two results of our own runs are the same (one optimum, the bar's effect on the roll,
#: an active constraint) when they differ by less than 1 %: they share the model, the road
#: and the integrator, so only the optimiser's stopping point or rounding separates them.
SAME = 1.0
#: [relative] a stored optimum simulated again reproduces its stored objectives when they
#: differ by less than 1e-6: same config and integrator, only batching and rounding differ.
REPRODUCED = 1e-6
#: [points of %] a threshold fit delivers the requested share of samples at C_max when its
#: run lands within 2 points of it (the adaptive threshold is refitted every few seconds, so
#: the share drifts around the request).
SHARE_HIT = 2.0
#: [%] a GA or NSGA-II run had stopped improving when its best value (hypervolume) improved by
#: less than 1 % over its last 20 % of evaluations (Run.late_gain): at that rate another 20 %
#: of budget moves it by less than the SAME threshold.
STALLED = 1.0
#: [s] the thesis prints peak times to 0.01 s: the coarsest output step its tables allow.
THESIS_GRID = 0.01


def finite(values) -> np.ndarray:
    v = np.asarray([x for x in np.ravel(values) if not md.missing(x)], dtype=float)
    return v[np.isfinite(v)]


def side(diffs, tol: float) -> str:
    """Where values lie against their references, from the differences (value - reference):
    'within' (every |d| < tol), 'above' or 'below' (all on one side, some by tol or more),
    'both' (on both sides, some by tol or more), 'none' (no finite difference)."""
    d = finite(diffs)
    if not len(d):
        return "none"
    if np.all(np.abs(d) < tol):
        return "within"
    return "above" if np.all(d > 0) else "below" if np.all(d < 0) else "both"


def placed(diffs, what: str = "the thesis's", tol: float = AGREE, unit: str = " %") -> str:
    """'within 5 % of the thesis's' / 'above the thesis's' / ... (see :func:`side`)."""
    return {
        "within": f"within {tol:g}{unit} of {what}",
        "above": f"above {what}",
        "below": f"below {what}",
        "both": f"on both sides of {what}",
        "none": f"not comparable with {what}",
    }[side(diffs, tol)]


def listed(items, none: str = "none") -> str:
    items = list(items)
    return ", ".join(map(str, items)) if items else none


def spread(values) -> float:
    """max/min - 1 [%] of the finite values (NaN when fewer than two)."""
    v = finite(values)
    return float(100 * (v.max() / v.min() - 1)) if len(v) > 1 else math.nan


def dt_sentence(change: float, thesis_diff: float, thesis: str) -> str:
    """Ch. 3's step-size conclusion: ``change`` [%] of the peak when dt is halved,
    ``thesis_diff`` [%] ours from the thesis's value ``thesis`` (printed, with its unit)."""
    if abs(change) < CONVERGED:
        verdict = (
            f"the peak is converged in the step size ({md.pct(abs(change), False)} <"
            f" {CONVERGED:g} %)"
        )
        if abs(thesis_diff) < CONVERGED:
            return verdict + f" and within {CONVERGED:g} % of the thesis's {thesis}"
        return (
            verdict + f", so its {md.pct(thesis_diff)} from the thesis's {thesis} is no"
            " integration error of ours"
        )
    return (
        f"the peak is not converged in the step size ({md.pct(abs(change), False)} ≥"
        f" {CONVERGED:g} %), so integration error may be part of its"
        f" {md.pct(thesis_diff)} from the thesis's {thesis}"
    )


def grid_sentence(coarse_diff: float, fine_diff: float) -> str:
    """Whether sampling on the thesis's grid moves our peak toward the thesis's value: the
    differences [%] from it of the peak sampled every THESIS_GRID and of ours."""
    if md.missing(coarse_diff) or md.missing(fine_diff):
        return "the two cannot be compared"
    if abs(coarse_diff) < abs(fine_diff):
        return "so a coarser output grid than ours moves the peak toward the thesis's value"
    return "so a coarser output grid does not explain the difference"


def seed_sentence(what: str, spread_pct: float, outside: list[str], compared: int) -> str:
    """The seed check's conclusion for a group of quantities: their largest spread [%] over
    the seeds, and the ``compared`` quantities whose printed thesis value lies ``outside`` our
    seeds' range (outside: no realisation of ours gives it)."""
    s = f"{what} move by at most {spread_pct:.1f} % between seeds; "
    if outside:
        return (
            s + f"the thesis's value lies outside our five seeds for {', '.join(outside)}"
            f" ({len(outside)} of {compared}), so no realisation of ours explains those"
        )
    return (
        s + f"the thesis's value lies inside our five seeds for all {compared}, so the"
        " realisation can account for their differences"
    )


def share_sentence(what: str, share, target: float) -> str:
    """Ch. 7: how a threshold set for ``target`` (fraction) acts on designs whose base law runs
    at C_max for ``share`` (fractions, one per design): it pulls the share toward the target."""
    median = float(np.median(share))
    s = (
        f"The {what} designs run at C_max for"
        f" {span(100 * np.asarray(share), lambda v: md.num(v, 3))} %"
        f" (median {md.num(100 * median, 3)} %), "
    )
    if abs(100 * (median - target)) < SHARE_HIT:
        return s + (
            f"within {SHARE_HIT:g} points of the threshold's {md.num(100 * target, 2)} %,"
            " so the threshold changes them little."
        )
    return s + (
        "so the threshold softens them (fewer stiff samples)."
        if median > target
        else "so the threshold stiffens them more often instead."
    )


def narrowed(before, after) -> str:
    """Whether a change of the model (the longer bump) closes its differences from the thesis:
    ``before`` and ``after`` [%], pairwise."""
    b, a = np.abs(np.asarray(before, dtype=float)), np.abs(np.asarray(after, dtype=float))
    if np.all(a < AGREE):
        return f"closes the gap (all within {AGREE:g} % after)"
    if np.all(a < b):
        return "accounts for part of the gap"
    if np.all(a >= b):
        return "does not explain the gap"
    return "narrows some of the differences and widens others"


# --- reading -----------------------------------------------------------------------------------


def text(value) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def names(ds) -> list[str]:
    return [text(n) for n in np.atleast_1d(ds.attrs["names"])]


@dataclass
class Run:
    """One ``suspopt optimise`` file: its optimum or front and what the run cost."""

    path: Path
    X: np.ndarray
    var_names: list[str]
    F: np.ndarray
    obj_names: list[str]
    G: np.ndarray
    algorithm: str
    population: int | None
    max_generations: int | None
    max_evaluations: int | None
    generations: int
    evaluations: int
    seconds: float
    best: np.ndarray  # (generations, m) history of the best feasible values
    hypervolume: np.ndarray  # (generations,) NaN for one objective
    history_evaluations: np.ndarray
    weights: np.ndarray | None

    @property
    def stop(self) -> str:
        """Why the run ended: its evaluation or generation budget, or a stall."""
        if self.max_evaluations and self.evaluations >= self.max_evaluations:
            return "evaluation budget"
        if self.algorithm in ("ga", "nsga2") and self.generations >= (self.max_generations or 0):
            return "generation budget"
        if self.algorithm == "gradient":
            return (
                "SLSQP converged"
                if self.generations < (self.max_generations or 0)
                else "iteration budget"
            )
        return "stalled (tolerance)" if self.algorithm in ("ga", "nsga2") else "converged"

    def late_gain(self, share: float = 0.2) -> float:
        """How far from convergence a GA or NSGA-II run stopped: the relative improvement [%]
        over the last ``share`` of its evaluations of the best value (GA: the objective or
        the weighted sum) or of the front's hypervolume (NSGA-II). NaN for the gradient and
        hybrid runs, whose SLSQP improves to its end by design."""
        if self.algorithm == "ga":
            value = -self.best[:, 0]  # with a weighted sum: the sum (optimise's /history)
        elif self.algorithm == "nsga2":
            value = self.hypervolume
        else:
            return math.nan
        ok = np.isfinite(value)
        if ok.sum() < 2:
            return math.nan
        ev, value = self.history_evaluations[ok], value[ok]
        before = value[ev <= ev[-1] * (1 - share)]
        if not len(before):
            return math.nan
        return float(100 * (value[-1] - before[-1]) / abs(before[-1]))


def read_run(path: Path) -> Run:
    pareto = read_pareto(path)
    opt = pareto.config().optimiser
    with h5py.File(path, "r") as h5:
        weights = h5["pareto"].attrs.get("weights")
        return Run(
            path,
            pareto.X,
            pareto.var_names,
            pareto.F,
            pareto.obj_names,
            pareto.G,
            text(h5.attrs["algorithm"]),
            opt.population,
            opt.generations,
            opt.max_evaluations,
            int(h5.attrs["generations"]),
            int(h5.attrs["evaluations"]),
            float(h5["history/time"][-1]),
            np.atleast_2d(h5["history/best"][()].T).T,
            h5["history/hypervolume"][()],
            h5["history/evaluations"][()],
            None if weights is None else np.asarray(weights, dtype=float),
        )


@dataclass
class Models:
    """One ``suspopt analyse models`` file: value and difference per metric, model keys."""

    keys: list[str]
    value: dict[str, np.ndarray]
    difference: dict[str, np.ndarray]
    units: dict[str, str]


def read_models(path: Path, part: str, road: str) -> Models:
    with h5py.File(path, "r") as h5:
        labels = [text(m) for m in h5.attrs["models"]]
        value = {k: v[()] for k, v in h5["comparison/value"].items()}
        diff = {k: v[()] for k, v in h5["comparison/difference"].items()}
        units = {k: text(v.attrs["units"]) for k, v in h5["comparison/value"].items()}
    keys = []
    for label in labels:  # part1a_qc_bump -> qc; part2a_fc_no_arb_bump -> no_arb
        key = label[len(part) + 1 : -(len(road) + 1)]
        keys.append(key.split("_", 1)[1] if part.startswith("part2") else key)
    return Models(keys, value, diff, units)


def read_metrics(path: Path) -> dict[str, float]:
    """``/metrics`` of a ``suspopt simulate`` file (design 0)."""
    with h5py.File(path, "r") as h5:
        return {k: float(v[()][0]) for k, v in h5["metrics"].items()}


def read_kesort(path: Path) -> dict:
    with h5py.File(path, "r") as h5:
        g = h5["kesort"]
        data = {
            "F": g["F"][()],
            "names": names(g["F"]),
            "X": g["X"][()],
            "var_names": names(g["X"]),
            "case": [text(c) for c in g["case"][()]],
            "source": g["source"][()],
            "row": g["row"][()],
            "chosen": int(g["chosen"][()]),
            "k_eps": g["k_eps"][()],
            "P": float(g.attrs["P"]),
            "files": [text(f) for f in g["sets/file"][()]],
            "ties": g["ties"][()],
            "cases": {},
        }
        for label, c in g.get("cases", {}).items():
            rows = c["rows"][()]
            chosen = int(c["chosen"][()])
            data["cases"][label] = {
                "chosen": chosen,
                "P": float(c.attrs["P"]),
                "k_eps": float(c["k_eps"][()][list(rows).index(chosen)]),
                "ties": c["ties"][()],
                "picks": {k: int(v[()]) for k, v in c["picks"].items()},
            }
        data["picks"] = {k: int(v[()]) for k, v in g["picks"].items()}
    return data


def read_steps(out: Path) -> dict[str, float]:
    steps = {}
    path = out / "run.tsv"
    if path.is_file():
        for line in path.read_text().splitlines():
            name, seconds, *_ = line.split("\t")
            steps[name] = float(seconds)
    return steps


# --- re-simulation for the metrics the optimiser does not store -------------------------------


def performance(
    path: Path, X: np.ndarray, road_length: float | None = None
) -> dict[str, np.ndarray]:
    """Metrics of designs ``X (P, n)`` of the optimise file ``path``, simulated again with its
    config (one batch): RC_s (Wk r.m.s. of z̈_s, Eq 2.78), RMS_acc (r.m.s. of z̈_s), f1-f3
    (Eq 5.4-5.6), per corner MST (max |travel|, Eq 2.88 on magnitudes), ratio (spring usage,
    Eq 5.3), F_T (K_T max |tyre deflection|, the dynamic tyre force) and max_z (max |wheel
    heave|); SI units. ``road_length`` replaces the bump's length on the road [m]."""
    cfg = read_pareto(path).config()
    if road_length is not None:
        cfg = cfg.model_copy(update={"road": cfg.road.model_copy(update={"length": road_length})})
    corners = list(cfg.vehicle.corners)
    specs = [
        MetricSpec(name="RC_s", metric="rms_weighted", signal="body.heave_acc", weighting="Wk"),
        MetricSpec(name="RMS_acc", metric="rms", signal="body.heave_acc"),
        MetricSpec(name="f1", metric="var", signal="body.heave_acc"),
        MetricSpec(name="f2", metric="var", signal="travel", reduce="mean"),
        MetricSpec(name="f3", metric="var", signal="tyre_deflection", reduce="mean"),
        MetricSpec(name="MST", metric="max_abs", signal="travel"),
        MetricSpec(name="MTD", metric="max_abs", signal="tyre_deflection"),
        MetricSpec(name="ratio", metric="spring_usage"),
    ]
    specs += [
        MetricSpec(name=f"max_z.{c}", metric="max_abs", signal=f"wheel.{c}.heave") for c in corners
    ]
    cfg = cfg.model_copy(update={"metrics": specs})
    params = {dv.path: X[:, j] for j, dv in enumerate(cfg.design_variables)}
    values = dict(suspopt.simulate(cfg, params=params).metrics)
    for c in corners:
        values[f"F_T.{c}"] = values[f"MTD.{c}"] * cfg.vehicle.corners[c].tyre.stiffness
    return values


def batched_performance(designs: dict, road_length: float | None = None) -> dict:
    """:func:`performance` of several optimise files' designs ``{key: (path, X (p, n))}`` in
    one batch, ``{key: metrics}``. The files' configs must share the vehicle, road, simulation
    and design variables (checked): the first one simulates them all."""

    def model(path: Path) -> dict:
        dump = read_pareto(path).config().model_dump(mode="json")
        return {k: dump[k] for k in ("vehicle", "road", "simulation", "design_variables")}

    items = list(designs.items())
    first = model(items[0][1][0])
    for _key, (path, _) in items[1:]:
        if model(path) != first:
            raise ValueError(f"{path}: another model than {items[0][1][0]}; cannot batch")
    values = performance(
        items[0][1][0], np.concatenate([X for _, X in designs.values()]), road_length
    )
    out, start = {}, 0
    for key, (_, X) in items:
        out[key] = {name: v[start : start + len(X)] for name, v in values.items()}
        start += len(X)
    return out


# --- the report's pieces -----------------------------------------------------------------------


class Doc:
    """Markdown lines of one report file, and the figures it copies next to itself."""

    def __init__(self, report: Path):
        self.report, self.lines = report, []

    def __call__(self, *lines: str) -> None:
        self.lines.extend(lines)

    def para(self, *sentences: str) -> None:
        self.lines.extend([" ".join(sentences), ""])

    def table(self, header, rows) -> None:
        self.lines.extend([md.table(header, rows), ""])

    def figure(self, source: Path, name: str, caption: str) -> None:
        if not source.is_file():
            self.para(f"*(figure {source.name} missing)*")
            return
        (self.report / "figures").mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, self.report / "figures" / name)
        self.lines.extend([f"![{caption}](figures/{name})", "", f"*{caption}*", ""])

    def text(self) -> str:
        return "\n".join(self.lines).rstrip() + "\n"


class Chapter:
    """A chapter of the report, read from ``out/NAME`` against ``THESIS[NAME]``: its
    ``SECTIONS`` are the methods that write its tables and paragraphs, in order (what one
    measures and a later one reads is kept on the instance); ``headline(doc)`` returns the
    chapter's lines for the report's summary."""

    NAME = ""
    SECTIONS: tuple[str, ...] = ()

    def __init__(self, out: Path):
        self.out, self.d, self.ref = out, out / self.NAME, THESIS[self.NAME]

    def write(self, doc: Doc) -> list[str]:
        for section in self.SECTIONS:
            getattr(self, section)(doc)
        return self.headline(doc)

    def headline(self, doc: Doc) -> list[str]:
        raise NotImplementedError


def span(values, fmt=md.pct) -> str:
    """'a to b' of the finite values."""
    v = np.asarray([x for x in values if not md.missing(x)], dtype=float)
    v = v[np.isfinite(v)]
    return "-" if not len(v) else f"{fmt(v.min())} to {fmt(v.max())}"


def budget_row(label: str, run: Run, thesis_seconds=None) -> list[str]:
    return [
        label,
        run.algorithm,
        str(run.population or "-"),
        str(run.generations),
        str(run.evaluations),
        md.num(run.seconds),
        "-" if thesis_seconds is None else md.printed(thesis_seconds),
        run.stop,
        "-" if md.missing(run.late_gain()) else f"{md.num(run.late_gain(), 2)} %",
    ]


BUDGET_HEADER = [
    "run",
    "algorithm",
    "population",
    "generations",
    "evaluations",
    "wall [s]",
    "thesis [s]",
    "stopped by",
    "gain over the last 20 % (GA: best; NSGA-II: hypervolume)",
]


def command_list(doc: Doc, commands: list[str]) -> None:
    doc("```bash", *commands, "```", "")
