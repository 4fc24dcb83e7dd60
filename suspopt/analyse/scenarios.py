"""``suspopt analyse scenarios PARETO.h5``: how a robust front's designs fare in each scenario.

A ``suspopt optimise`` file of a config with a ``scenarios:`` section holds every design's
objectives and constraint margins under every scenario (``/pareto/scenarios/F (N, S, m)``,
``G (N, S, k)``, the combined values in ``/pareto/F`` and ``G``;
:mod:`suspopt.optimisation.scenarios`). This analysis reads them, simulates nothing, and reports
for the front's picks (:func:`suspopt.choosing.kepsilon.pareto_picks`: each objective's edge and the
knee, taken on the combined objectives; or the designs ``--pick`` names) each objective's
combined value, its smallest, mean and largest value over the scenarios, the scenario where
it is largest, and in how many scenarios the design holds every constraint; and for the
whole front, how many designs hold every constraint in every scenario.

The file's layout: :data:`suspopt.formats.SCENARIOS`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import plots
from ..choosing.kepsilon import pareto_picks
from ..choosing.selection import ParetoSet, read_pareto
from ..errors import ConfigError
from ..formats import SCENARIOS
from ..h5read import H5Reader
from ..io import atomic_h5, put
from .registry import KINDS, Analysis, Kind, Report, analysis

__all__ = ["run", "read_scenarios", "ScenarioSpread"]

#: ``--pick`` as the analyses take it: names or row numbers, or None for the front's picks
Picks = Sequence[str] | None


def read_scenarios(path: Path):
    """``(pareto, names (S,), FS (N, S, m), GS (N, S, k))`` of a robust optimisation's file;
    ConfigError naming the file and the dataset when it has no scenarios or they do not fit
    its ``/pareto`` tables."""
    pareto = read_pareto(path)
    N, m, k = len(pareto.X), pareto.F.shape[1], len(pareto.constraint_names)
    with H5Reader(path) as h5:
        if h5._node("pareto/scenarios") is None:
            raise ConfigError(
                f"{path}: /pareto/scenarios: missing (the file of an optimisation whose "
                f"config has a scenarios: section is needed)"
            )
        FS = h5.array("pareto/scenarios/F", ndim=3, columns=m)
        GS = h5.array("pareto/scenarios/G", ndim=3, columns=k)
        scenario = h5.dataset("pareto/scenarios/scenario")
        if scenario.ndim != 1 or scenario.dtype.kind not in ("O", "S", "U"):
            raise ConfigError(f"{path}: /pareto/scenarios/scenario: not a list of names")
        names = [h5.text(v, "pareto/scenarios/scenario") for v in scenario[()]]
    S = len(names)
    for key, data in (("F", FS), ("G", GS)):
        if data.shape[:2] != (N, S):
            raise ConfigError(
                f"{path}: /pareto/scenarios/{key}: shape {data.shape} does not fit {N} "
                f"designs and {S} scenarios"
            )
    return pareto, names, FS, GS


@dataclass
class ScenarioSpread:
    """A robust front's picks under each of its scenarios: ``pareto`` (the front), ``names``
    (the S scenarios), ``FS (N, S, m)`` every design's objectives under each (their units:
    ``units``), ``holds (N, S)`` whether it meets every constraint there, ``picks`` (name ->
    row), ``rules`` (each objective's ``over_scenarios`` rule, "" where the file has none)."""

    source: Path
    pareto: ParetoSet
    names: list[str]
    FS: np.ndarray
    holds: np.ndarray
    units: list[str]
    picks: dict[str, int]
    rules: list[str]


def run(source: Path, *, pick: Picks = None) -> Analysis:
    """The picks of a robust front under every scenario, or the designs ``pick`` names
    (:func:`_picks`; module docstring); nothing simulated, nothing written."""
    source = Path(source)
    pareto, names, FS, GS = read_scenarios(source)
    with H5Reader(source) as h5:
        units = h5.labels("pareto/F", "units", pareto.F.shape[1])
    spread = ScenarioSpread(
        source,
        pareto,
        names,
        FS,
        (GS <= 0).all(axis=2),
        list(units),
        _picks(source, pareto.F, pareto.obj_names, pick),
        _rules(source, len(pareto.obj_names)),
    )
    return analysis(
        "scenarios",
        f"{source.name}: the picks under {len(names)} scenarios",
        spread,
        pareto.config(),
        [source],
        lambda path, command: _write(path, spread, command),
        lambda path: _plot(spread, path),
        lambda: _table(spread),
    )


def _write(output: Path, s: ScenarioSpread, command: str | None) -> Path:
    """The picks' rows of ``s`` (:data:`suspopt.formats.SCENARIOS`), atomically."""
    rows_of = list(s.picks.values())
    with atomic_h5(output, s.pareto.config(), command) as h5:
        h5.attrs.update(analysis="scenarios", source=str(s.source))
        group = h5.create_group("scenarios")
        put(SCENARIOS, group, "scenario", s.names)
        put(SCENARIOS, group, "pick", list(s.picks))
        put(SCENARIOS, group, "row", np.array(rows_of))
        put(SCENARIOS, group, "F", s.FS[rows_of], s.units, names=s.pareto.obj_names,
            over_scenarios=s.rules)  # fmt: skip
        put(SCENARIOS, group, "holds", s.holds[rows_of].astype(np.int8))
    return output


def _plot(s: ScenarioSpread, path: Path) -> Path:
    """Each objective of each pick over the scenarios (:func:`suspopt.plots.scenario_spread`)."""
    objectives = [
        (name, unit, {f"{pick} (design {row})": s.FS[row, :, j] for pick, row in s.picks.items()})
        for j, (name, unit) in enumerate(zip(s.pareto.obj_names, s.units))
    ]
    title = f"{s.source.name}: the front's picks under each scenario"
    return plots.scenario_spread(path, title, s.names, objectives)


def _table(s: ScenarioSpread) -> Report:
    """Each pick's objectives: combined, min, mean, max over the scenarios, the worst one."""
    pareto, names, holds = s.pareto, s.names, s.holds
    table = []
    for pick, row in s.picks.items():
        for j, (name, unit) in enumerate(zip(pareto.obj_names, s.units)):
            values = s.FS[row, :, j]
            table.append(
                [
                    pick if j == 0 else "",
                    str(row) if j == 0 else "",
                    f"{name} [{unit}]",
                    f"{pareto.F[row, j]:.4g}" + (f" ({s.rules[j]})" if s.rules[j] else ""),
                    f"{np.nanmin(values):.4g}",
                    f"{np.nanmean(values):.4g}",
                    f"{np.nanmax(values):.4g}",
                    names[int(np.nanargmax(values))] if np.isfinite(values).any() else "-",
                    f"{holds[row].sum()} / {len(names)}" if j == 0 else "",
                ]
            )
    everywhere = int(holds.all(axis=1).sum())
    notes = [
        f"{everywhere} of the front's {len(pareto.X)} designs hold every constraint in all "
        f"{len(names)} scenarios ({', '.join(names)})",
        "combined: the value /pareto/F holds (each objective's over_scenarios); min, mean, "
        "max: over the scenarios",
    ]
    return Report(
        title=f"{s.source.name}: the picks under {len(names)} scenarios",
        columns=["pick", "design", "objective", "combined", "min", "mean", "max",
                 "worst scenario", "feasible in"],
        rows=table,
        notes=notes,
    )  # fmt: skip


def _picks(source: Path, F: np.ndarray, names: list[str], pick: Picks) -> dict[str, int]:
    """The designs reported, name -> row: the front's edges and knee
    (:func:`suspopt.choosing.kepsilon.pareto_picks`), or those ``pick`` names (``--pick``: names of the
    file's table or design ids, its rows, comma-separated or repeated; an id is named
    ``design ID``), each name once."""
    if not pick:
        return pareto_picks(F, names)
    from ..choosing.picks import read_table, split_picks

    table = read_table(source)
    chosen: dict[str, int] = {}
    for name in split_picks(list(pick)):
        row = table.resolve(name)
        chosen.setdefault(f"design {row}" if name.isdigit() else name, row)
    return chosen


def _rules(source: Path, m: int) -> list[str]:
    """Each objective's ``over_scenarios`` rule as the file states it ("" if it does not)."""
    with H5Reader(source) as h5:
        if not h5.has_attr("over_scenarios", "pareto/F"):
            return [""] * m
        return h5.labels("pareto/F", "over_scenarios", m)


KINDS["scenarios"] = Kind(run, options=("pick",))
