"""``optimise(cfg, output)``: the run behind ``suspopt optimise``, checkpointed to HDF5.

The run builds :class:`~suspopt.optimisation.problem.Problem` and the optimiser of the config,
then advances one generation at a time. After the first generation, and then after a
generation at least :data:`REWRITE_SECONDS` after the last rewrite, it rewrites ``output``
(atomically, :func:`suspopt.io.atomic_h5`) with the optimum so far, the history and a
checkpoint; ``resume=True`` continues from that checkpoint to the same result as an
uninterrupted run. Ctrl-C (KeyboardInterrupt) stops the run and rewrites the file from the
last completed generation with ``status = "interrupted"``; an error that stops the run (a
lost Dask scheduler) first rewrites it from the last completed generation, ``status =
"running"``. Nothing here prints: progress goes to ``callback(Progress)``.

The file's layout is declared once, in :data:`suspopt.formats.OPTIMISE` (the public
contract, docs/architecture.md#public-contract). What it does not say: ``/pareto`` is the best
design (one objective) or the non-dominated set, sorted by the first objective; with a
weighted sum F holds the main objectives, not the sum. ``/history/best`` is the lowest
feasible value of each objective (NaN while none is feasible; the weighted sum with
weights), ``hypervolume`` that of the non-dominated feasible designs evaluated so far (so it
never falls; objectives normalised by the first feasible generation's ideal and nadir points,
reference point 1.1 in each; NaN for one objective). ``--resume`` rebuilds the run from
``/checkpoint`` by running the optimiser again from the seed for the stored generations with
each batch answered from the file (no simulation), checks that it asks for exactly the stored
designs and arrives at the stored history, then goes on: it continues bit for bit, and
nothing read from the file is ever executed (there is no pickle). ``/baseline`` is absent
where a design variable's field holds no value; ``status`` ``failed`` means every design of
the optimum failed to simulate.
"""

from __future__ import annotations

import contextlib
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pymoo.core.problem import Problem as _PymooProblem
from pymoo.indicators.hv import HV

from ..config import Config, ConfigError
from ..config.optimise import ALGORITHMS
from ..config.optimise import Hybrid as HybridSettings
from ..config.optimise import Optimiser as OptimiserSettings
from ..io import atomic_h5, check_not_input, config_inputs
from ..params import numeric_paths
from . import algorithms
from .output import (
    read_checkpoint,
    write_baseline,
    write_checkpoint,
    write_history,
    write_pareto,
)
from .problem import PENALTY, Problem
from .result import OptimisationResult

__all__ = ["optimise", "build_optimiser", "Progress", "OptimisationResult"]

_HV_REFERENCE = 1.1

#: Seconds between two rewrites of the output during a run: a generation that ends sooner
#: after the last rewrite waits for the next one. The last completed generation is written at
#: the end, on Ctrl-C and when an error stops the run, so only a kill -9 (or a power cut) loses
#: work, at most this much. Rewriting the file costs about 35 ms (23 datasets, the
#: checkpoint's batches, two fsyncs): after every generation it took 4.6 s of the 16.6 s of
#: a Ch. 5 case 1 S1 run, 137 generations of 200 designs.
REWRITE_SECONDS = 2.0


@dataclass
class Progress:
    """What the run reports after each generation."""

    generation: int
    max_generations: int | None
    evaluations: int
    max_evaluations: int | None
    best: np.ndarray  # (m,) lowest feasible objective values, NaN if none
    hypervolume: float  # NaN for one objective
    feasible: float  # share of the generation's designs that are feasible
    elapsed: float  # [s], including time before a resume
    time_left: float | None  # [s], from the budget; None without one
    phase: str  # the algorithm running now


class _Recorder(_PymooProblem):
    """The problem as the optimiser sees it: every batch it evaluates is kept (the
    checkpoint); on a resume the stored batches answer, in order, for as long as they last,
    each checked to be the batch the optimiser asks for."""

    def __init__(
        self, problem: Problem, stored: list[tuple] | None = None, source: Path | None = None
    ):
        super().__init__(
            n_var=problem.n_var,
            n_obj=problem.n_obj,
            n_ieq_constr=problem.n_ieq_constr,
            xl=problem.xl,
            xu=problem.xu,
        )
        self.problem, self.source = problem, source
        self.batches: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        self._stored = deque(stored or [])

    @property
    def replaying(self) -> bool:
        return bool(self._stored)

    def _evaluate(self, X, out, *args, **kwargs):
        X = np.array(X, dtype=float)
        if self._stored:
            stored_X, F, G = self._stored.popleft()
            if stored_X.shape != X.shape or not np.array_equal(stored_X, X):
                raise ConfigError(
                    f"--resume: {self.source}: /checkpoint/X: batch "
                    f"{len(self.batches)} holds other designs than the run asks "
                    f"for (the file was written by another version of suspopt "
                    f"or pymoo, or was changed); run without --resume"
                )
        else:
            F, G = self.problem.evaluate(X, return_values_of=["F", "G"])
        self.batches.append((X, np.asarray(F, float), np.asarray(G, float)))
        out["F"], out["G"] = self.batches[-1][1:]


@dataclass
class _Run:
    """A run: the optimiser, the recorder it evaluates through, and what is reported."""

    optimiser: algorithms.Optimiser
    recorder: _Recorder
    weights: np.ndarray | None
    history: dict[str, list] = field(
        default_factory=lambda: {
            k: [] for k in ("generation", "best", "hypervolume", "evaluations", "time", "feasible")
        }
    )
    elapsed: float = 0.0
    normalisation: tuple[np.ndarray, np.ndarray] | None = None
    archive: np.ndarray | None = None  # non-dominated feasible F found so far
    archived: int = 0  # the recorder's batches in the archive
    weighted_optimum: tuple[bytes, np.ndarray, np.ndarray] | None = None  # X key, F, G


@dataclass
class _Snapshot:
    """The run after a completed generation, ready to write."""

    batches: int  # the recorder's batches so far
    optimum: algorithms.Solutions  # X physical, F main objectives
    history: dict[str, np.ndarray]
    generation: int
    evaluations: int


def optimise(
    cfg: Config,
    output: str | Path,
    resume: bool = False,
    callback: Callable[[Progress], None] | None = None,
    command: str | None = None,
) -> OptimisationResult:
    """Optimise ``cfg`` and write ``output`` (HDF5, layout in the module docstring).

    Parameters
    ----------
    cfg : Config
        The study, with its ``design_variables``, ``objectives`` and ``optimiser``.
    output : str or Path
        The HDF5 file written after every generation (and its checkpoint).
    resume : bool
        Continue from the checkpoint in ``output``, written for the same config or one that
        differs only in the budget (a finished run goes on to the longer run's result).
    callback : callable, optional
        Called with each generation's ``Progress`` (its number, evaluations, best values).
    command : str, optional
        The command line recorded in the file (default this process's).

    Returns
    -------
    OptimisationResult
        The optimum or Pareto set (X in the variables' SI units, F and G with units) and the
        history. ConfigError for bad input before any simulation; KeyboardInterrupt only
        before the first generation completed.
    """
    output = Path(output)
    check_not_input(output, config_inputs(cfg))  # (before any simulation, not at a write)
    problem = Problem.from_config(cfg)
    optimiser = build_optimiser(cfg, problem)
    run = (
        _resume(output, cfg, problem, optimiser)
        if resume
        else _start(cfg, _Recorder(problem), optimiser)
    )
    snapshot = None
    status = "finished"
    written, last_write = True, -np.inf
    try:
        start = time.perf_counter() - run.elapsed
        while run.optimiser.has_next():
            run.optimiser.next()
            run.elapsed = time.perf_counter() - start
            progress = _record(run, cfg)
            snapshot, written = _snapshot(run, problem), False
            if time.perf_counter() - last_write >= REWRITE_SECONDS:
                _write(output, cfg, problem, snapshot, run, "running", command)
                written, last_write = True, time.perf_counter()
            if callback is not None:
                callback(progress)
    except KeyboardInterrupt:
        if snapshot is None:
            raise
        status = "interrupted"
    except BaseException:  # an error: the file first gets the last completed generation
        if not written:
            assert snapshot is not None  # (written is True until the first snapshot)
            with contextlib.suppress(Exception):  # (the error raised is the first one)
                _write(output, cfg, problem, snapshot, run, "running", command)
        raise
    if snapshot is None:  # resumed a finished run, or nothing to do
        snapshot = _snapshot(run, problem)
    if status == "finished" and (snapshot.optimum.F >= PENALTY).all():
        status = "failed"  # every design of the optimum failed to simulate
    baseline = config_design(problem) if status != "interrupted" else None
    return _write(output, cfg, problem, snapshot, run, status, command, baseline)


def config_design(problem: Problem) -> algorithms.Solutions | None:
    """The config's own design (the values its design variables' fields hold: the design
    the engineer starts from), evaluated as the run's designs are: X physical (1, n), F
    (1, m), G (1, k); None when a field holds no value, or one of ``scale: log`` holds a
    value <= 0 (no point of the search). Not counted in the run's budget."""
    values = numeric_paths(problem.cfg)
    if any(v.path not in values for v in problem.variables):
        return None
    own = np.array([[values[v.path] for v in problem.variables]])
    if any(v.scale == "log" and x <= 0 for v, x in zip(problem.variables, own[0])):
        return None
    X = problem.to_search(own)
    F, G = problem.evaluate(X, return_values_of=["F", "G"])
    return algorithms.Solutions(problem.to_physical(X), F, G)


def settings(cfg: Config) -> OptimiserSettings:
    """``cfg.optimiser``; ConfigError when the config has none (it is no optimisation)."""
    if cfg.optimiser is None:
        raise cfg.error(
            ("optimiser",), "required key is missing: give at least algorithm, seed and a budget"
        )
    return cfg.optimiser


#: Memory a generation of a population algorithm holds per pair of designs [bytes]: pymoo's
#: duplicate elimination measures the distance of every offspring to every design (float64
#: distances, masks and indices). tracemalloc's peak over two generations (pymoo 0.6) was
#: 17.8-18.7 bytes per P^2 for GA and NSGA-II at 2000 and 4000 designs, 18.7 for SMS-EMOA and
#: 8.1 for GDE3 at 2000 (20.4 for SMS-EMOA at 1000, where the terms in P still count). With
#: ``eliminate_duplicates: false`` the peak grows with P only (16 MB at 4000 designs).
PAIR_BYTES = 20


def _check_pairs_memory(cfg: Config, population: int) -> None:
    """ConfigError at ``optimiser.population`` when its pairs (:data:`PAIR_BYTES`) need more
    memory than the limit: a population of 10^6 would ask for about 20 TB in its first
    generation (a MemoryError traceback before)."""
    from .. import memory

    memory.check(
        PAIR_BYTES * float(population) ** 2,
        f"a population of {population:,} (the optimiser compares every pair of designs)",
        "give a smaller population",
        cfg,
        ("optimiser", "population"),
    )


def build_optimiser(cfg: Config, problem: Problem) -> algorithms.Optimiser:
    """The optimiser of ``cfg.optimiser`` for ``problem`` (not yet set up); ConfigError for a
    combination that cannot work (e.g. GA on three objectives without a weighted sum)."""
    opt = settings(cfg)
    _check_objectives(cfg, problem)
    if opt.algorithm == "gradient":
        return _gradient(cfg, problem, opt.generations, opt.max_evaluations)
    n_obj = 1 if opt.weighted_sum else problem.n_obj
    if opt.population is not None and (opt.options or {}).get("eliminate_duplicates") is not False:
        _check_pairs_memory(cfg, opt.population)
    try:
        algorithm = algorithms.pymoo_algorithm(
            ALGORITHMS[opt.algorithm].target, opt.options, opt.population, n_obj
        )
    except ValueError as exc:
        raise cfg.error(("optimiser", "options"), str(exc)) from None
    if opt.algorithm == "hybrid":
        hybrid = opt.hybrid or HybridSettings()
        ga_generations = min(hybrid.ga_generations, opt.generations or float("inf"))
        ga = algorithms.PymooOptimiser(
            algorithm,
            algorithms.termination(
                1, ga_generations, opt.max_evaluations, opt.tolerance, opt.stall_generations
            ),
        )
        return algorithms.Hybrid(
            ga,
            _gradient(cfg, problem, None, None),
            hybrid.shrink,
            opt.generations,
            opt.max_evaluations,
        )
    return algorithms.PymooOptimiser(
        algorithm,
        algorithms.termination(
            n_obj, opt.generations, opt.max_evaluations, opt.tolerance, opt.stall_generations
        ),
    )


def _gradient(cfg: Config, problem: Problem, iterations, evaluations) -> algorithms.Gradient:
    opt = settings(cfg)
    return algorithms.Gradient(
        max_iterations=iterations,
        max_evaluations=evaluations,
        tolerance=opt.tolerance,
        step=opt.gradient.step,
        constraint_scale=problem.constraint_scale,
    )


def _check_objectives(cfg: Config, problem: Problem) -> None:
    """The algorithm suits the number of objectives; weights match the objectives."""
    opt = settings(cfg)
    single = ALGORITHMS[opt.algorithm].single_objective
    if opt.weighted_sum is None:
        if single and problem.n_obj > 1:
            raise cfg.error(
                ("optimiser", "algorithm"),
                f"{opt.algorithm} minimises one "
                f"objective and objectives.main has {problem.n_obj}: add "
                f"optimiser.weighted_sum (Eq 5.7) or use nsga2",
            )
        return
    if not single:
        raise cfg.error(
            ("optimiser", "weighted_sum"),
            f"a weighted sum leaves one objective; "
            f"{opt.algorithm} is for several: use ga, gradient or hybrid",
        )
    weights, balance = opt.weighted_sum.weights, opt.weighted_sum.balance
    if weights is not None and len(weights) != problem.n_obj:
        raise cfg.error(
            ("optimiser", "weighted_sum", "weights"),
            f"{len(weights)} weights for "
            f"{problem.n_obj} main objectives ({', '.join(problem.obj_names)})",
        )
    if (
        balance is not None
        and balance.dominant is not None
        and balance.dominant not in problem.obj_names
    ):
        raise cfg.error(
            ("optimiser", "weighted_sum", "balance", "dominant"),
            f"{balance.dominant!r} is not a main objective; they are "
            f"{', '.join(problem.obj_names)}",
        )


def _start(cfg: Config, recorder: _Recorder, optimiser: algorithms.Optimiser) -> _Run:
    """A run from the start: the Generator of the seed balances the weights (if asked), then
    drives the optimiser; every evaluation goes through ``recorder``."""
    opt = settings(cfg)
    rng = np.random.default_rng(opt.seed)
    weights, working = None, recorder
    if opt.weighted_sum is not None:
        ws = opt.weighted_sum
        if ws.weights is not None:
            weights = np.array(ws.weights, dtype=float)
        else:
            balance = ws.balance
            assert balance is not None  # (the section has weights or a balance)
            dominant = (
                None
                if balance.dominant is None
                else recorder.problem.obj_names.index(balance.dominant)
            )
            try:
                weights = algorithms.balanced_weights(
                    recorder, balance.samples, rng, dominant, balance.factor
                )
            except ValueError as exc:
                raise cfg.error(("optimiser", "weighted_sum", "balance"), str(exc)) from None
        working = algorithms.WeightedSum(recorder, weights)
    optimiser.setup(working, rng)
    return _Run(optimiser=optimiser, recorder=recorder, weights=weights)


def _record(run: _Run, cfg: Config) -> Progress:
    """Append this generation to the history; return the progress report."""
    opt, optimiser = settings(cfg), run.optimiser
    optimum, population = optimiser.optimum(), optimiser.population()
    feasible_f = optimum.F[optimum.feasible]
    best = feasible_f.min(axis=0) if len(feasible_f) else np.full(optimum.F.shape[1], np.nan)
    hv = np.nan
    if optimum.F.shape[1] > 1 and _archive(run).size:
        if run.normalisation is None:
            ideal, nadir = feasible_f.min(axis=0), feasible_f.max(axis=0)
            run.normalisation = (ideal, np.where(nadir > ideal, nadir, ideal + 1.0))
        ideal, nadir = run.normalisation
        hv = float(
            HV(ref_point=np.full(len(ideal), _HV_REFERENCE))(
                (run.archive - ideal) / (nadir - ideal)
            )
        )
    h = run.history
    h["generation"].append(optimiser.n_gen)
    h["best"].append(best)
    h["hypervolume"].append(hv)
    h["evaluations"].append(optimiser.n_eval)
    h["time"].append(run.elapsed)
    h["feasible"].append(float(population.feasible.mean()) if len(population.X) else 0.0)
    return Progress(
        generation=optimiser.n_gen,
        max_generations=opt.generations,
        evaluations=optimiser.n_eval,
        max_evaluations=opt.max_evaluations,
        best=best,
        hypervolume=hv,
        feasible=h["feasible"][-1],
        elapsed=run.elapsed,
        time_left=_time_left(run, opt),
        phase=optimiser.phase,
    )


def _archive(run: _Run) -> np.ndarray:
    """The non-dominated feasible designs among all evaluated so far (their main objectives),
    updated with the batches since the last call: the set whose hypervolume the history
    reports, so that it never falls (an algorithm's own front can lose a design)."""
    from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

    batches = run.recorder.batches[run.archived :]
    run.archived = len(run.recorder.batches)
    found = [F[(G <= 0).all(axis=1)] for _, F, G in batches]
    pool = (
        np.vstack([run.archive] + found)
        if run.archive is not None
        else np.vstack(found)
        if found
        else np.empty((0, 0))
    )
    if len(pool) > 1:
        pool = pool[NonDominatedSorting().do(pool, only_non_dominated_front=True)]
    run.archive = pool
    return pool


def _time_left(run: _Run, opt) -> float | None:
    """Seconds left at the pace so far, from whichever budget ends first."""
    optimiser, left = run.optimiser, []
    if opt.generations is not None and optimiser.n_gen:
        left.append(run.elapsed / optimiser.n_gen * max(opt.generations - optimiser.n_gen, 0))
    if opt.max_evaluations is not None and optimiser.n_eval:
        left.append(run.elapsed / optimiser.n_eval * max(opt.max_evaluations - optimiser.n_eval, 0))
    return min(left) if left else None


def _snapshot(run: _Run, problem: Problem) -> _Snapshot:
    """The run's optimum and history now (re-evaluating the main objectives of a weighted
    sum's best design: F is the sum there)."""
    optimum = run.optimiser.optimum()
    order = np.argsort(optimum.F[:, 0], kind="stable")
    X, F, G = optimum.X[order], optimum.F[order], optimum.G[order]
    if run.weights is not None:
        key = X.tobytes()
        if run.weighted_optimum is None or run.weighted_optimum[0] != key:
            run.weighted_optimum = (key, *problem.evaluate(X, return_values_of=["F", "G"]))
        F, G = run.weighted_optimum[1:]
    return _Snapshot(
        batches=len(run.recorder.batches),
        optimum=algorithms.Solutions(problem.to_physical(X), F, G),
        history={k: np.array(v, dtype=float) for k, v in run.history.items()},
        generation=run.optimiser.n_gen,
        evaluations=run.optimiser.n_eval,
    )


def _resume(output: Path, cfg: Config, problem: Problem, optimiser: algorithms.Optimiser) -> _Run:
    """The run checkpointed in ``output`` (module docstring), rebuilt by replaying it."""
    batches, generations, stored = read_checkpoint(output, cfg, problem)
    run = _start(cfg, _Recorder(problem, batches, output), optimiser)
    for generation in range(generations):
        if not run.optimiser.has_next():
            break
        run.optimiser.next()
        run.elapsed = float(stored["time"][generation])
        _record(run, cfg)
    rebuilt = {k: np.array(v, dtype=float) for k, v in run.history.items()}
    same = all(
        np.array_equal(rebuilt[k].reshape(stored[k].shape), stored[k], equal_nan=True)
        if rebuilt[k].size == stored[k].size
        else False
        for k in stored
    )
    if run.recorder.replaying or not same:
        raise ConfigError(
            f"--resume: {output}: /history: replaying the checkpoint does not "
            f"give the stored run (the file was written by another version "
            f"of suspopt or pymoo, or was changed); run without --resume"
        )
    return run


def _write(
    output: Path,
    cfg: Config,
    problem: Problem,
    snap: _Snapshot,
    run: _Run,
    status: str,
    command: str | None,
    baseline: algorithms.Solutions | None = None,
) -> OptimisationResult:
    weights, run_batches = run.weights, run.recorder.batches
    opt = settings(cfg)
    best_names = problem.obj_names if weights is None else ["weighted_sum"]
    best_units = problem.obj_units if weights is None else ["1"]
    with atomic_h5(output, cfg, command) as h5:
        h5.attrs.update(
            status=status,
            algorithm=opt.algorithm,
            optimiser_seed=opt.seed,
            generations=snap.generation,
            evaluations=snap.evaluations,
        )
        write_pareto(h5, problem, snap.optimum, weights)
        write_history(h5, snap.history, best_names, best_units)
        write_checkpoint(h5, problem, run_batches[: snap.batches], snap.generation)
        if baseline is not None:
            write_baseline(h5, problem, baseline)
        attrs = {k: h5.attrs[k] for k in h5.attrs}
    o = snap.optimum
    return OptimisationResult(
        status=status,
        path=output,
        X=o.X,
        var_names=problem.var_names,
        var_units=problem.var_units,
        F=o.F,
        obj_names=problem.obj_names,
        obj_units=problem.obj_units,
        weights=weights,
        G=o.G,
        constraint_names=problem.constraint_names,
        history=snap.history,
        baseline=baseline,
        problem=problem,
        attrs=attrs,
    )
