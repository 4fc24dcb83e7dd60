"""The groups of an optimisation's HDF5 output (its format: :data:`suspopt.formats.OPTIMISE`): the optimum
``/pareto``, the ``/history`` per generation and the data-only ``/checkpoint`` that a
``--resume`` replays."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..config import Config, ConfigError
from ..files import Unreadable, status
from ..formats import OPTIMISE, Table
from ..io import put, write_tables
from .problem import Problem

#: Format of the ``/checkpoint`` group: every evaluated design and its objectives, in batches.
CHECKPOINT_FORMAT = "replay-1"


def _columns(problem: Problem, x_units):
    """(name, columns, units, names) of the design, objective and constraint tables."""
    return (
        ("X", problem.n_var, x_units, problem.var_names),
        ("F", problem.n_obj, problem.obj_units, problem.obj_names),
        ("G", problem.n_ieq_constr, problem.constraint_units, problem.constraint_names),
    )


def _xfg(group: str, problem: Problem, values, rules=None) -> list[Table]:
    """X, F and G of ``group`` (``pareto``, ``baseline``; physical variables, SI units) as
    the optimise file format declares them, F's and G's rule over the scenarios
    (``over_scenarios``) when ``rules`` has them."""
    rules = rules or {}
    return [
        OPTIMISE.table(
            group,
            key,
            values[key],
            units,
            names=names,
            attrs={"over_scenarios": rules[key]} if key in rules else {},
        )
        for key, _, units, names in _columns(problem, problem.var_units)
    ]


def pareto_tables(problem: Problem, optimum) -> list[Table]:
    """The tables of ``/pareto``: X, F, G of the optimum designs (physical variables, SI
    units), F's and G's rule over the scenarios (``over_scenarios``) in a robust run."""
    values = {"X": optimum.X, "F": optimum.F, "G": optimum.G}
    rules = dict(zip("FG", problem.aggregation())) if problem.scenarios is not None else {}
    return _xfg("pareto", problem, values, rules)


def write_pareto(h5, problem: Problem, optimum, weights) -> None:
    """``/pareto`` (:func:`pareto_tables`), its ``weights`` and, in a robust run, its
    ``scenarios`` (:func:`scenario_tables`)."""
    pareto = h5.create_group("pareto")
    if weights is not None:
        pareto.attrs["weights"] = weights
    write_tables(pareto, pareto_tables(problem, optimum))
    if problem.scenarios is not None:
        write_tables(pareto.create_group("scenarios"), scenario_tables(problem, optimum.X))


def baseline_tables(problem: Problem, baseline) -> list[Table]:
    """``/baseline/X, F, G`` (one row each, as ``/pareto``'s): the config's own design
    (:func:`suspopt.optimisation.run.config_design`), evaluated as the run's designs are."""
    return _xfg("baseline", problem, {"X": baseline.X, "F": baseline.F, "G": baseline.G})


def write_baseline(h5, problem: Problem, baseline) -> None:
    """``/baseline`` (:func:`baseline_tables`)."""
    write_tables(h5.create_group("baseline"), baseline_tables(problem, baseline))


def scenario_tables(problem: Problem, X) -> list[Table]:
    """``/pareto/scenarios``: the objectives ``F (N, S, m)`` and constraint margins
    ``G (N, S, k)`` of the designs ``X`` (physical values) under each scenario, the scenarios'
    names (dimension ``scenario``) and ``weight (S,)``; ``/pareto/F`` and ``G`` hold their
    aggregates, each column's rule in the attribute ``over_scenarios``."""
    assert problem.scenarios is not None
    FS, GS = problem.scenario_values(X)
    t = OPTIMISE.table
    tables = [
        t("pareto/scenarios", "scenario", problem.scenarios.names),
        t("pareto/scenarios", "weight", problem.scenarios.weights),
    ]
    for (key, _, units, columns), data in zip(_columns(problem, problem.var_units)[1:], (FS, GS)):
        tables.append(t("pareto/scenarios", key, data, units, names=columns))
    return tables


def history_tables(history: dict, best_names, best_units) -> list[Table]:
    """``/history``: per generation the best objectives (or weighted sum), the hypervolume,
    the evaluations, the time [s] and the feasible share."""
    tables = [OPTIMISE.table("history", "generation", history["generation"])]
    for key, values in history.items():
        if key == "best":
            best = np.reshape(values, (len(values), len(best_names)))  # (zero generations too)
            tables.append(OPTIMISE.table("history", key, best, best_units, names=best_names))
        elif key != "generation":
            tables.append(OPTIMISE.table("history", key, values))
    return tables


def write_history(h5, history: dict, best_names, best_units) -> None:
    """``/history`` (:func:`history_tables`)."""
    write_tables(h5.create_group("history"), history_tables(history, best_names, best_units))


def write_checkpoint(h5, problem: Problem, batches: list, generations: int) -> None:
    """``/checkpoint``: every evaluated design (search variables) with its objectives and
    constraints, and the sizes of the evaluation batches, from which ``--resume`` replays
    the run (data only: nothing in it is code)."""
    checkpoint = h5.create_group("checkpoint")
    checkpoint.attrs.update(format=CHECKPOINT_FORMAT, generations=generations)
    for j, (key, columns, units, names) in enumerate(_columns(problem, problem.search_units)):
        data = np.concatenate([b[j] for b in batches]) if batches else np.empty((0, columns))
        dim = OPTIMISE.data(f"checkpoint/{key}").axes[-1]
        put(OPTIMISE, checkpoint, key, data, units, coords={dim: names})
    sizes = np.array([len(b[0]) for b in batches], dtype=np.int64)
    put(OPTIMISE, checkpoint, "batches", sizes)


def read_checkpoint(output: Path, cfg: Config, problem: Problem):
    """The stored batches ``[(X, F, G), ...]``, generations and history of ``output``;
    ConfigError naming the file and the dataset for anything missing or malformed, for a
    file of another config (one that differs in more than the budget, :data:`BUDGET`), or
    for a budget that ends before the checkpoint does."""
    from ..h5read import H5Reader

    where = f"--resume: {output}"
    try:
        missing = status(output) is None
    except Unreadable as exc:  # (a name too long: Path.exists raised)
        raise ConfigError(f"{where}: {exc}") from None
    if missing:
        raise ConfigError(f"{where}: does not exist (run without --resume to start)")
    with H5Reader(output, where) as h5:
        stored = h5.text_attr("config")
        if stored != cfg.text and not _same_but_budget(stored, cfg):
            raise ConfigError(
                f"{where}: was written for another config (it differs in more than "
                f"optimiser.generations and max_evaluations); use the same config or run "
                f"without --resume"
            )
        if "checkpoint/state" in h5.file:
            raise ConfigError(
                f"{where}: /checkpoint/state: an old checkpoint (a pickle), "
                f"which suspopt no longer loads: a file must never run code; "
                f"run without --resume"
            )
        group = h5.group("checkpoint")
        if h5.attribute(group, "format", "/checkpoint: attribute 'format'") != CHECKPOINT_FORMAT:
            raise ConfigError(
                f"{where}: /checkpoint: not a suspopt checkpoint of format {CHECKPOINT_FORMAT}"
            )
        generations = h5.int_attr("checkpoint", "generations", 0, 10**7)
        sizes = h5.array("checkpoint/batches", ndim=1, integer=True)
        X = h5.array("checkpoint/X", ndim=2, columns=problem.n_var)
        F = h5.array("checkpoint/F", ndim=2, columns=problem.n_obj)
        G = h5.array("checkpoint/G", ndim=2, columns=problem.n_ieq_constr)
        history = {
            key: h5.array(f"history/{key}", ndim=2 if key == "best" else 1)
            for key in ("generation", "best", "hypervolume", "evaluations", "time", "feasible")
        }
    if (sizes < 1).any() or sizes.sum() != len(X) or not len(X) == len(F) == len(G):
        raise ConfigError(
            f"{where}: /checkpoint: batches of {int(sizes.sum())} designs, "
            f"X, F, G of {len(X)}, {len(F)}, {len(G)}"
        )
    if not np.isfinite(X).all():
        raise ConfigError(f"{where}: /checkpoint/X: values must be finite")
    if len(history["time"]) != generations:
        raise ConfigError(
            f"{where}: /history/time: {len(history['time'])} generations, the "
            f"checkpoint {generations}"
        )
    _check_budget(where, cfg, generations, int(sizes.sum()))
    edges = np.concatenate([[0], np.cumsum(sizes)])
    batches = [(X[a:b], F[a:b], G[a:b]) for a, b in zip(edges[:-1], edges[1:])]
    return batches, generations, history


#: The optimiser's fields a ``--resume`` may change: how long the run goes on, not how.
BUDGET = ("generations", "max_evaluations")


def _same_but_budget(stored: str, cfg: Config) -> bool:
    """Whether the config text ``stored`` (a checkpoint's) is ``cfg`` but for the budget
    (:data:`BUDGET`): a run resumed with a longer budget goes on from where it stopped."""
    from ..config.loader import load_config_text

    try:
        before = load_config_text(stored, cfg.source)
    except ConfigError:
        return False
    if before.optimiser is None or cfg.optimiser is None:
        return False
    skip = {"optimiser": set(BUDGET)}
    return before.model_dump(exclude=skip) == cfg.model_dump(exclude=skip)


def _check_budget(where: str, cfg: Config, generations: int, evaluations: int) -> None:
    """ConfigError when the config's budget ends before the checkpoint does (a resumed run
    cannot end earlier than the run it continues)."""
    opt = cfg.optimiser
    assert opt is not None
    for field, budget, done in (
        ("generations", opt.generations, generations),
        ("max_evaluations", opt.max_evaluations, evaluations),
    ):
        if budget is not None and budget < done:
            raise ConfigError(
                f"{where}: the file holds {done} {field.replace('max_', '')} and "
                f"optimiser.{field} is {budget}: give a budget of at least that to go on"
            )
