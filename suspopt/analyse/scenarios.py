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

HDF5 layout (root attributes as every suspopt file, ``config`` the stored config's text,
``analysis = "scenarios"``, ``source`` the Pareto file): ``/scenarios/pick`` (names),
``row (picks,)`` [1], ``F (picks, S, m)`` in the objectives' units (per column),
``holds (picks, S)`` [1] (1 where every constraint holds), ``scenario`` (names).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .. import plots
from ..choosing.kepsilon import pareto_picks
from ..choosing.selection import read_pareto
from ..errors import ConfigError
from ..h5read import H5Reader
from ..io import atomic_h5, text_array, write_dataset
from .registry import KINDS, Kind, Report

__all__ = ["run", "read_scenarios"]

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


def run(
    source: Path, output: Path | None = None, plot: Path | None = None, *, pick: Picks = None
) -> Report:
    """The picks of a robust front under every scenario, or the designs ``pick`` names
    (:func:`_picks`; module docstring)."""
    if plot is not None:
        plots.check_path(plot)
    pareto, names, FS, GS = read_scenarios(source)
    cfg = pareto.config()
    with H5Reader(source) as h5:
        units = h5.labels("pareto/F", "units", pareto.F.shape[1])
    picks = _picks(source, pareto.F, pareto.obj_names, pick)
    rows_of = list(picks.values())
    holds = (GS <= 0).all(axis=2)  # (N, S)
    rules = _rules(source, len(pareto.obj_names))
    table = []
    for pick, row in picks.items():
        for j, (name, unit) in enumerate(zip(pareto.obj_names, units)):
            values = FS[row, :, j]
            table.append(
                [
                    pick if j == 0 else "",
                    str(row) if j == 0 else "",
                    f"{name} [{unit}]",
                    f"{pareto.F[row, j]:.4g}" + (f" ({rules[j]})" if rules[j] else ""),
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
    if output is not None:
        with atomic_h5(output, cfg) as h5:
            h5.attrs.update(analysis="scenarios", source=str(source))
            group = h5.create_group("scenarios")
            write_dataset(group, "scenario", names, "1", dims=("scenario",))
            write_dataset(group, "pick", list(picks), "1", dims=("pick",))
            write_dataset(group, "row", np.array(rows_of), "1", dims=("pick",))
            write_dataset(
                group, "F", FS[rows_of], units, dims=("pick", "scenario", "objective"),
                names=pareto.obj_names,
            )  # fmt: skip
            write_dataset(group, "holds", holds[rows_of].astype(np.int8), "1",
                          dims=("pick", "scenario"))  # fmt: skip
            group["F"].attrs["over_scenarios"] = text_array(rules)
    if plot is not None:
        plots.scenario_spread(
            plot,
            f"{source.name}: the front's picks under each scenario",
            names,
            [
                (
                    name,
                    unit,
                    {f"{pick} (design {row})": FS[row, :, j] for pick, row in picks.items()},
                )
                for j, (name, unit) in enumerate(zip(pareto.obj_names, units))
            ],
        )
    return Report(
        title=f"{source.name}: the picks under {len(names)} scenarios",
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
