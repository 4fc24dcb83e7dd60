"""Pareto files of ``suspopt optimise`` read back, and their designs re-evaluated in one batch.

A Pareto file (layout in :mod:`suspopt.optimise.run`) holds ``/pareto/X (N, n)`` (physical
values), ``/pareto/F (N, m)``, ``/pareto/G (N, k)``, each with ``names`` and per-column
``units``, and the YAML text of its config as the root attribute ``config``.
:func:`read_pareto` loads it; :func:`evaluate_front` re-simulates all ``N`` designs with a
config - the stored one or a modified one (another road, controller, passenger) - in ONE
:meth:`suspopt.Problem.evaluate` call, which is what the thesis's "pseudo Pareto fronts" are
(Fig. 7.4b, Sec 8.4.2-8.4.3).

Reproducibility: re-evaluating a stored front (two designs or more) with its own config gives
its stored ``F`` and ``G`` bit for bit. A front of ONE design agrees to rounding only (relative
1e-15 here): the simulator shares matrices common to all designs of a batch, so a single design
takes a different (but equivalent) matrix-product path than the optimiser's population did.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from ..config import Config, ConfigError
from ..config.loader import load_config_text
from ..optimise import Problem

#: The Problem's constraint that flags a failed simulation.
_FAILED = "simulation_failed"

__all__ = ["ParetoSet", "FrontValues", "read_pareto", "config_with", "evaluate_front"]


@dataclass
class ParetoSet:
    """A stored Pareto set: ``X (N, n)`` physical design values, ``F (N, m)`` objectives,
    ``G (N, k)`` constraints (``<= 0`` feasible), their names and SI units; ``config`` the
    validated config whose text the file holds; ``path`` the file."""

    X: np.ndarray
    F: np.ndarray
    G: np.ndarray
    var_names: list[str]
    var_units: list[str]
    obj_names: list[str]
    obj_units: list[str]
    constraint_names: list[str]
    constraint_units: list[str]
    config: Config
    path: Path

    @property
    def N(self) -> int:
        return len(self.X)

    @property
    def feasible(self) -> np.ndarray:
        """(N,) True where every constraint holds."""
        return np.all(self.G <= 0, axis=1)


@dataclass
class FrontValues:
    """Values of a front's designs under one config: ``F (N, m)``, ``G (N, k)`` and the
    supplementary objectives ``S (N, s)``, with names and units (as :class:`Problem`)."""

    F: np.ndarray
    G: np.ndarray
    S: np.ndarray
    obj_names: list[str]
    obj_units: list[str]
    constraint_names: list[str]
    constraint_units: list[str]
    supplementary_names: list[str]
    supplementary_units: list[str]

    @property
    def feasible(self) -> np.ndarray:
        """(N,) True where every constraint holds."""
        return np.all(self.G <= 0, axis=1)

    @property
    def failed(self) -> np.ndarray:
        """(N,) True where the simulation failed (diverged, NaN): the Problem's last
        constraint ``simulation_failed`` is violated and F holds penalty values."""
        return self.G[:, self.constraint_names.index(_FAILED)] > 0


def _strings(values) -> list[str]:
    return [v.decode() if isinstance(v, bytes) else str(v) for v in np.atleast_1d(values)]


def read_pareto(path: str | Path) -> ParetoSet:
    """Read a ``suspopt optimise`` output file; ConfigError (one line) if it is not one."""
    path = Path(path)
    try:
        with h5py.File(path, "r") as h5:
            grp = h5["pareto"]
            data = {key: (grp[key][()], _strings(grp[key].attrs["names"]),
                          _strings(grp[key].attrs["units"])) for key in ("X", "F", "G")}
            text = h5.attrs["config"]
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such file") from None
    except (OSError, KeyError):
        raise ConfigError(f"{path}: not a suspopt optimise file (needs /pareto/X, /pareto/F, "
                          f"/pareto/G with names and units, and the root attribute config)"
                          ) from None
    text = text.decode() if isinstance(text, bytes) else str(text)
    cfg = load_config_text(text, path)
    (X, var_names, var_units), (F, obj_names, obj_units), (G, con_names, con_units) = (
        data["X"], data["F"], data["G"])
    if len(X) == 0:
        raise ConfigError(f"{path}: the Pareto set is empty")
    return ParetoSet(X=np.atleast_2d(X), F=np.atleast_2d(F), G=np.atleast_2d(G),
                     var_names=var_names, var_units=var_units, obj_names=obj_names,
                     obj_units=obj_units, constraint_names=con_names,
                     constraint_units=con_units, config=cfg, path=path)


def config_with(pareto: ParetoSet, edit: Callable[[dict], None], what: str) -> Config:
    """The stored config with ``edit`` applied to its YAML data (a dict, edited in place);
    the result's text is the edited YAML. ``what`` names the edit in error messages, which
    then refer to the lines of that text (written to the analysis's HDF5 as ``config``)."""
    import yaml

    data = yaml.safe_load(pareto.config.text)
    edit(data)
    text = yaml.safe_dump(data, sort_keys=False, allow_unicode=True)
    try:
        return load_config_text(text, pareto.path)
    except ConfigError as exc:
        raise ConfigError(f"{exc} (the config of {pareto.path.name} with {what})") from None


class _WithParameters(Problem):
    """The config's Problem whose designs carry extra parameters: ``extra(params)`` maps the
    designs' own params (dotted path -> (N,)) to more, which win over them."""

    extra: Callable[[dict[str, np.ndarray]], dict[str, np.ndarray]] | None = None

    def params(self, X) -> dict[str, np.ndarray]:
        params = super().params(X)
        return params if self.extra is None else {**params, **self.extra(params)}


def _search_coordinates(problem: Problem, X: np.ndarray) -> np.ndarray:
    """Physical values (N, n) -> the Problem's coordinates (log10 of ``scale: log`` ones),
    the inverse of :meth:`Problem.to_physical`."""
    X = np.array(X, dtype=float)
    for j, var in enumerate(problem.variables):
        if var.scale == "log":
            X[:, j] = np.log10(X[:, j])
    return X


def evaluate_front(pareto: ParetoSet, cfg: Config | None = None,
                   extra: Callable[[Mapping[str, np.ndarray]], dict[str, np.ndarray]]
                   | None = None) -> FrontValues:
    """Objectives, constraints and supplementary objectives of every stored design under
    ``cfg`` (default the stored config), in one batch. ``extra`` adds design parameters
    computed from the designs' own (e.g. a passenger change, Sec 8.4.3).

    The config must have the stored design variables (same paths, in order) and objectives;
    ConfigError otherwise."""
    cfg = pareto.config if cfg is None else cfg
    problem = _WithParameters.from_config(cfg)
    problem.extra = extra
    if problem.var_names != pareto.var_names or problem.obj_names != pareto.obj_names:
        raise ConfigError(f"{pareto.path}: the modified config's design variables "
                          f"({', '.join(problem.var_names)}) or objectives "
                          f"({', '.join(problem.obj_names)}) differ from the stored ones")
    X = _search_coordinates(problem, pareto.X)
    if problem.supplementary_names:
        F, G, S = problem.evaluate(X, return_values_of=["F", "G", "S"])
    else:
        F, G = problem.evaluate(X, return_values_of=["F", "G"])
        S = np.empty((len(X), 0))
    return FrontValues(F=F, G=G, S=S, obj_names=problem.obj_names,
                       obj_units=problem.obj_units,
                       constraint_names=problem.constraint_names,
                       constraint_units=problem.constraint_units,
                       supplementary_names=problem.supplementary_names,
                       supplementary_units=problem.supplementary_units)
