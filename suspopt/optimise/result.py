"""What an optimisation returns: :class:`OptimisationResult`, the optimum (or Pareto set) of
a run, which becomes an xarray Dataset, a pandas DataFrame or a figure without its file."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from . import algorithms
from .problem import Problem

__all__ = ["OptimisationResult"]


@dataclass
class OptimisationResult:
    """The optimum (or Pareto set) of a run: ``X`` physical values (N, n), ``F (N, m)``,
    ``G (N, k)``, their names and units; ``history`` as written to ``/history``; ``status``
    finished or interrupted; ``path`` the file written, whose root attributes are ``attrs``
    (provenance: ``suspopt_version``, ``created``, ``command``, ``config``, ``seed``, and the
    run's ``status``, ``algorithm``, ...); ``problem`` the :class:`~suspopt.Problem` it
    solved (layout of the file: :mod:`suspopt.optimise.run`)."""

    X: np.ndarray
    F: np.ndarray
    G: np.ndarray
    var_names: list[str]
    var_units: list[str]
    obj_names: list[str]
    obj_units: list[str]
    constraint_names: list[str]
    history: dict[str, np.ndarray]
    status: str
    path: Path
    weights: np.ndarray | None = None
    baseline: algorithms.Solutions | None = None
    problem: Problem | None = field(default=None, repr=False)
    attrs: dict[str, Any] = field(default_factory=dict, repr=False)

    def _groups(self, only: Collection[str]) -> dict[str, list]:
        """The file's groups that the result holds (``/checkpoint`` is the file's only),
        group -> its tables, those of ``only`` computed (:mod:`suspopt.layout`)."""
        from .output import baseline_tables, history_tables, pareto_tables, scenario_tables

        if self.problem is None:
            raise ValueError("this OptimisationResult has no problem: make it with optimise()")
        problem = self.problem
        best = (
            (problem.obj_names, problem.obj_units)
            if self.weights is None
            else (["weighted_sum"], ["1"])
        )
        optimum = algorithms.Solutions(self.X, self.F, self.G)
        groups: dict[str, list] = {"": []}
        groups["pareto"] = pareto_tables(problem, optimum) if "pareto" in only else []
        if problem.scenarios is not None:
            wanted = "pareto/scenarios" in only
            groups["pareto/scenarios"] = scenario_tables(problem, self.X) if wanted else []
        groups["history"] = history_tables(self.history, *best) if "history" in only else []
        if self.baseline is not None:
            wanted = "baseline" in only
            groups["baseline"] = baseline_tables(problem, self.baseline) if wanted else []
        return groups

    def to_xarray(self, group: str = "pareto"):
        """This result as an ``xarray.Dataset``, without reading its file: the one
        ``suspopt.io.open_dataset(result.path, group)`` reads (:mod:`suspopt.layout`).
        ``group``: ``pareto`` (``X``, ``F``, ``G`` over ``design`` and ``variable``,
        ``objective``, ``constraint``, the names as coordinates and each column's SI unit
        in ``units``), ``history`` (per ``generation``), ``baseline``, ``pareto/scenarios``
        (a robust run) or ``""`` (the root); the file's root attributes in the Dataset's.
        KeyError for a group the result does not hold (``checkpoint``: read the file)."""
        from ..layout import group_dataset, group_name

        name = group_name(group)
        group_attrs: dict[str, Mapping[str, Any]] = {"": self.attrs}
        if self.weights is not None:
            group_attrs["pareto"] = {"weights": self.weights}
        groups = self._groups({"", *(name.split("/")[:1]), name})
        return group_dataset(groups, group, group_attrs, "this OptimisationResult")

    def to_dataframe(self, group: str = "pareto"):
        """:meth:`to_xarray` of ``group`` as a tidy pandas DataFrame
        (:func:`suspopt.layout.frame`): ``pareto`` one row per design, a column per design
        variable, objective and constraint (``X[name]`` where two tables share a name);
        ``history`` one row per generation; each column's SI unit in ``df.attrs["units"]``."""
        from ..layout import frame

        return frame(self.to_xarray(group))

    def plot(self, picks: Mapping[str, int] | None = None):
        """The figure of ``suspopt optimise --plot``
        (:func:`suspopt.plots.optimisation_result_figure`), a ``matplotlib.figure.Figure``:
        the front as every pair of objectives (feasible designs filled, infeasible hollow;
        axes ``name [unit]``), or the best value per generation for one objective, then the
        hypervolume and the feasible share per generation. ``picks`` (name -> row, e.g.
        ``suspopt.pareto_picks(result.F, result.obj_names)``) are starred and named on the
        front. ``fig.savefig(path)`` writes it."""
        from ..plots import optimisation_result_figure

        return optimisation_result_figure(self, picks)
