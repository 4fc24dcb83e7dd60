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
    """The optimum (or Pareto set) of a run, as :func:`suspopt.optimise` returns it
    (its file's layout: :mod:`!suspopt.optimisation.run`).

    :meth:`to_xarray`, :meth:`to_dataframe` and :meth:`plot` give it as an xarray Dataset, a
    pandas DataFrame and the ``--plot`` figure without reading the file.

    Attributes
    ----------
    X : ndarray
        The designs' variables ``(N, n)``, physical values (SI units: ``var_units``).
    F : ndarray
        Their objectives ``(N, m)`` (SI units: ``obj_units``).
    G : ndarray
        Their constraint margins ``(N, k)`` (G <= 0 feasible), in the constraints' units.
    var_names : list of str
        The design variables' names.
    var_units : list of str
        Their SI units.
    obj_names : list of str
        The objectives' names.
    obj_units : list of str
        Their SI units.
    constraint_names : list of str
        The constraints' names (``RC <= 1.4``, ..., ``simulation_failed``).
    history : dict of str to ndarray
        ``/history`` per generation: ``generation``, ``best``, ``hypervolume``,
        ``evaluations``, ``time`` [s], ``feasible``.
    status : str
        ``finished``, ``interrupted``, ``running`` or ``failed``.
    path : Path
        The file written.
    weights : ndarray or None
        The weighted sum's weights (units 1), None without one.
    baseline : Solutions or None
        The config's own design, evaluated (X, F, G as above), or None.
    problem : Problem or None
        The :class:`~suspopt.Problem` the run solved.
    attrs : dict
        The file's root attributes: ``suspopt_version``, ``created``, ``command``,
        ``config``, ``seed`` (units 1), ``status``, ``algorithm``, ``optimiser_seed``,
        ``generations``, ``evaluations``.
    """

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
        group -> its tables, those of ``only`` computed (:mod:`!suspopt.layout`)."""
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
        """This result as an ``xarray.Dataset``, without reading its file
        (:mod:`!suspopt.layout`): the one ``suspopt.io.open_dataset(result.path, group)``
        reads, the file's root attributes (provenance) in its attrs.

        Parameters
        ----------
        group : str
            ``pareto``: ``X``, ``F``, ``G`` over ``design`` and ``variable``, ``objective``,
            ``constraint`` (the names as coordinates, each column's SI unit in ``units``);
            ``history`` (per ``generation``); ``baseline``; ``pareto/scenarios`` (a robust
            run); ``""`` (the root).

        Returns
        -------
        xarray.Dataset
            KeyError for a group the result does not hold (``checkpoint``: read the file).
        """
        from ..layout import group_dataset, group_name

        name = group_name(group)
        group_attrs: dict[str, Mapping[str, Any]] = {"": self.attrs}
        if self.weights is not None:
            group_attrs["pareto"] = {"weights": self.weights}
        groups = self._groups({"", *(name.split("/")[:1]), name})
        return group_dataset(groups, group, group_attrs, "this OptimisationResult")

    def to_dataframe(self, group: str = "pareto"):
        """:meth:`to_xarray` of ``group`` as a tidy pandas DataFrame
        (:func:`!suspopt.layout.frame`).

        Parameters
        ----------
        group : str
            ``pareto`` and ``baseline``: one row per design, a column per design variable,
            objective and constraint (``X[name]`` where two tables share a name);
            ``history``: one row per generation (``best[f1]``, ``hypervolume``, ...).

        Returns
        -------
        pandas.DataFrame
            Each column's SI unit in ``df.attrs["units"]`` (column -> unit).
        """
        from ..layout import frame

        return frame(self.to_xarray(group))

    def plot(self, picks: Mapping[str, int] | None = None):
        """The figure of ``suspopt optimise --plot``
        (:func:`!suspopt.plots.optimisation_result_figure`).

        Two objectives or more: the front as every pair of objectives (feasible designs
        filled, infeasible hollow; axes ``name [unit]``), then the hypervolume and the
        feasible share per generation; one objective: the best value per generation.

        Parameters
        ----------
        picks : dict of str to int, optional
            Designs to star and name on the front, name -> row (indices of ``F``), e.g.
            ``suspopt.pareto_picks(result.F, result.obj_names)``.

        Returns
        -------
        matplotlib.figure.Figure
            ``fig.savefig("front.png")`` writes it.
        """
        from ..plots import optimisation_result_figure

        return optimisation_result_figure(self, picks)
