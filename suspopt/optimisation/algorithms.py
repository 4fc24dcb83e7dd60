"""Optimisers that advance one generation (or one SLSQP iteration) per ``next()``.

They work on any vectorised pymoo ``Problem`` (``evaluate(X)`` of a whole batch), not only on
:class:`suspopt.Problem`, and draw every random number from the ``numpy.random.Generator`` given
to ``setup``. Stepping one generation at a time lets a run report progress, write a
checkpoint (data only: every evaluated batch) and resume to the same result as an uninterrupted run.

- :class:`PymooOptimiser`: a pymoo algorithm (GA for one objective, Ch. 5 S1/S2; NSGA-II for
  Pareto fronts, Ch. 6-8; SMS-EMOA, GDE3; see ``suspopt.config.optimise.ALGORITHMS``).
- :class:`Gradient`: SLSQP (``scipy.optimize.minimize``), Ch. 5 S5, with forward differences:
  one batch of ``n + 1`` designs per gradient, shared by the objective, its gradient and the
  constraints at that point.
- :class:`Hybrid`: GA for a few generations, then SLSQP from the GA's best inside a box around
  it (Sec 5.1.1, S3/S4).
- :class:`WeightedSum`: the pseudo multi-objective problem of Eq 5.7, and
  :func:`balanced_weights` (Cases 4-5).

Seeding, as found in pymoo 0.6.2: ``Algorithm.setup`` creates ``np.random.default_rng(seed)``
as ``algorithm.random_state`` and hands it to sampling, selection, crossover, mutation and
survival through their ``random_state`` argument; it never seeds or draws from NumPy's global
generator (older pymoo 0.6.0/0.6.1 called ``np.random.seed``). But a pymoo function decorated
``@default_random_state`` that is called without ``random_state`` silently makes a fresh,
unseeded Generator: several algorithms do that (DE, PSO, ES, SRES, NSGA-III, ...), e.g. to break
ties, and are then not reproducible; suspopt offers only algorithms that never do (GA, NSGA-II,
SMS-EMOA, GDE3; a test spies on ``np.random.default_rng``). :class:`PymooOptimiser` replaces the
algorithm's generator by the run's own right after ``setup``, so one Generator drives the whole
run (the weighted-sum balancing samples first, then the algorithm), and pickling the optimiser
keeps its state for an exact resume.
"""

from __future__ import annotations

import importlib
import inspect
from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np
from pymoo.core.problem import Problem as _PymooProblem
from pymoo.termination.default import (
    DefaultMultiObjectiveTermination,
    DefaultSingleObjectiveTermination,
)

from .problem import PENALTY

__all__ = [
    "Solutions",
    "Optimiser",
    "PymooOptimiser",
    "Gradient",
    "Hybrid",
    "WeightedSum",
    "balanced_weights",
    "pymoo_algorithm",
    "termination",
    "minimize",
]

_SLSQP_ITERATION_LIMIT = 9  # scipy's status when maxiter stops SLSQP


@dataclass
class Solutions:
    """Designs and their values: ``X (N, n_var)`` search coordinates, ``F (N, n_obj)``,
    ``G (N, n_ieq_constr)``."""

    X: np.ndarray
    F: np.ndarray
    G: np.ndarray

    @property
    def feasible(self) -> np.ndarray:
        """(N,) True where every constraint holds (``G <= 0``)."""
        return np.asarray((self.G <= 0).all(axis=1))


class Optimiser(ABC):
    """One run on one problem: ``setup``, then ``next()`` while ``has_next()``."""

    problem: _PymooProblem
    n_gen: int = 0

    @abstractmethod
    def setup(self, problem: _PymooProblem, rng: np.random.Generator) -> None:
        """Start a run on ``problem`` drawing from ``rng``."""

    @abstractmethod
    def has_next(self) -> bool:
        """False once the budget is spent or the run has converged."""

    @abstractmethod
    def next(self) -> None:
        """Advance one generation (one iteration of SLSQP)."""

    @property
    @abstractmethod
    def n_eval(self) -> int:
        """Designs evaluated so far."""

    @abstractmethod
    def optimum(self) -> Solutions:
        """The best design (one objective) or the non-dominated set found so far."""

    @abstractmethod
    def population(self) -> Solutions:
        """The designs of the latest generation (SLSQP: of the latest batch)."""

    @property
    def phase(self) -> str:
        """What runs now (for progress reports)."""
        return type(self).__name__.lower()


class PymooOptimiser(Optimiser):
    """A pymoo algorithm with its termination, stepped one generation per ``next()``."""

    def __init__(self, algorithm, termination):
        self.algorithm = algorithm
        self.termination = termination

    @property
    def phase(self) -> str:
        return type(self.algorithm).__name__

    def setup(self, problem, rng):
        self.problem = problem
        self.n_gen = 0
        self.algorithm.setup(problem, termination=self.termination)
        self.algorithm.random_state = rng

    def has_next(self) -> bool:
        return self.algorithm.has_next()

    def next(self) -> None:
        self.algorithm.next()
        self.n_gen += 1

    @property
    def n_eval(self) -> int:
        return self.algorithm.evaluator.n_eval

    def optimum(self) -> Solutions:
        return _solutions(self.algorithm.opt)

    def population(self) -> Solutions:
        return _solutions(self.algorithm.pop)


def _solutions(pop) -> Solutions:
    """X, F and G of a pymoo population, read from its individuals' attributes (what
    ``Population.get`` returns, without its per-key look-ups: a third of a second of Ch. 6
    Part B's 100 generations)."""
    return Solutions(*(np.atleast_2d(np.array([getattr(i, k) for i in pop])) for k in "XFG"))


@dataclass
class _Point:
    """SLSQP's view of one design: objective, constraints and their forward differences."""

    f: float
    g: np.ndarray
    df: np.ndarray
    dg: np.ndarray


class Gradient(Optimiser):
    """SLSQP with batched forward differences (Ch. 5 S5; MATLAB's fmincon in the thesis).

    SLSQP works in the unit box ``u = (x - lo)/(hi - lo)`` of ``box`` (default the problem's
    bounds), starting at ``start`` (default the box's centre). The objective is divided by its
    magnitude at the start and each constraint by ``constraint_scale``, so ``tolerance`` is
    SLSQP's ``ftol`` on a relative objective. Asking for ``f`` at a new point evaluates the
    point and its ``n`` forward neighbours ``u + step e_i`` (backward where that leaves the
    box) as one batch; ``f``, the constraints and both gradients at that point are then free.

    One ``next()`` is one SLSQP iteration. scipy's SLSQP cannot pause, so ``next()`` re-runs it
    from the start with one more allowed iteration; the cache of evaluated points replays the
    earlier iterations without evaluating anything (SLSQP is deterministic), which also makes
    the cache of evaluated points an exact checkpoint.
    """

    def __init__(
        self,
        max_iterations: int | None = None,
        max_evaluations: int | None = None,
        tolerance: float = 1e-6,
        step: float = 1e-4,
        constraint_scale: np.ndarray | None = None,
        box: tuple[np.ndarray, np.ndarray] | None = None,
        start: np.ndarray | None = None,
    ):
        if not 0 < step < 0.5:
            raise ValueError(f"step must be in (0, 0.5) of each variable's range, got {step}")
        self.max_iterations, self.max_evaluations = max_iterations, max_evaluations
        self.tolerance, self.step = tolerance, step
        self.constraint_scale, self.box, self.start = constraint_scale, box, start

    @property
    def phase(self) -> str:
        return "SLSQP"

    def setup(self, problem, rng):
        if problem.n_obj != 1:
            raise ValueError(
                f"SLSQP minimises one objective, the problem has {problem.n_obj}: "
                f"combine them with a weighted sum"
            )
        self.problem = problem
        lo, hi = self.box if self.box is not None else (problem.xl, problem.xu)
        self._lo, self._span = np.asarray(lo, float), np.asarray(hi, float) - lo
        n = problem.n_var
        self._u0 = (
            np.full(n, 0.5)
            if self.start is None
            else np.clip((np.asarray(self.start, float) - self._lo) / self._span, 0.0, 1.0)
        )
        self._g_scale = (
            np.ones(problem.n_ieq_constr)
            if self.constraint_scale is None
            else np.asarray(self.constraint_scale, float)
        )
        self._cache: dict[bytes, _Point] = {}
        self._evaluations, self.n_gen, self._status = 0, 0, None
        self._u = self._u0
        self._f_scale = abs(self._point(self._u0).f) or 1.0

    def _point(self, u: np.ndarray) -> _Point:
        key = u.tobytes()
        if key not in self._cache:
            h = np.where(u + self.step <= 1.0, self.step, -self.step)
            U = np.vstack([u, u + np.diag(h)])
            X = self._lo + U * self._span
            F, G = self.problem.evaluate(X, return_values_of=["F", "G"])
            G = np.asarray(G, float).reshape(len(U), -1)
            self._evaluations += len(U)
            self._last = Solutions(X, F, G)
            self._cache[key] = _Point(
                f=F[0, 0], g=G[0], df=(F[1:, 0] - F[0, 0]) / h, dg=((G[1:] - G[0]) / h[:, None]).T
            )
        return self._cache[key]

    def next(self) -> None:
        self.n_gen += 1
        scale = self._f_scale
        constraints = (
            []
            if not self.problem.n_ieq_constr
            else [
                {
                    "type": "ineq",
                    "fun": lambda u: -self._point(u).g / self._g_scale,
                    "jac": lambda u: -self._point(u).dg / self._g_scale[:, None],
                }
            ]
        )
        from scipy.optimize import Bounds  # (SLSQP alone: scipy.optimize loads in 0.5 s)
        from scipy.optimize import minimize as _scipy_minimize

        result = _scipy_minimize(
            lambda u: self._point(u).f / scale,
            self._u0,
            jac=lambda u: self._point(u).df / scale,
            method="SLSQP",
            bounds=Bounds(np.zeros_like(self._u0), np.ones_like(self._u0)),
            constraints=constraints,
            options={"maxiter": self.n_gen, "ftol": self.tolerance},
        )
        self._u, self._status = result.x, result.status

    def has_next(self) -> bool:
        if self._status is not None and self._status != _SLSQP_ITERATION_LIMIT:
            return False
        if self.max_iterations is not None and self.n_gen >= self.max_iterations:
            return False
        return self.max_evaluations is None or self._evaluations < self.max_evaluations

    @property
    def n_eval(self) -> int:
        return self._evaluations

    def optimum(self) -> Solutions:
        p = self._point(self._u)
        return Solutions((self._lo + self._u * self._span)[None], np.array([[p.f]]), p.g[None])

    def population(self) -> Solutions:
        return self._last


class Hybrid(Optimiser):
    """GA, then SLSQP from the GA's best (Sec 5.1.1; the thesis runs the GA 10 generations).

    The gradient's box is the GA best ± ``shrink/2`` of each variable's range, symmetric
    around it except where the problem's bounds cut it. The ``gradient``'s own budget is what
    ``max_iterations``/``max_evaluations`` leave after the GA.
    """

    def __init__(
        self,
        ga: PymooOptimiser,
        gradient: Gradient,
        shrink: float = 0.2,
        max_iterations: int | None = None,
        max_evaluations: int | None = None,
    ):
        if not 0 < shrink <= 1:
            raise ValueError(f"shrink must be in (0, 1], got {shrink}")
        self.ga, self.gradient, self.shrink = ga, gradient, shrink
        self.max_iterations, self.max_evaluations = max_iterations, max_evaluations

    @property
    def phase(self) -> str:
        return self.ga.phase if self._in_ga else self.gradient.phase

    def setup(self, problem, rng):
        self.problem, self._rng, self._in_ga = problem, rng, True
        self.ga.setup(problem, rng)

    def has_next(self) -> bool:
        return self._in_ga or self.gradient.has_next()

    def next(self) -> None:
        if not self._in_ga:
            self.gradient.next()
            return
        self.ga.next()
        if not self.ga.has_next():
            self._switch()

    def _switch(self) -> None:
        """Start SLSQP from the GA's best, inside the shrunk box."""
        best = self.ga.optimum().X[0]
        xl, xu = self.problem.xl, self.problem.xu
        half = 0.5 * self.shrink * (xu - xl)
        lo, hi = np.maximum(xl, best - half), np.minimum(xu, best + half)
        # a box below the floating-point resolution at the best (a tiny shrink, or a range
        # tiny beside its values) is the best's neighbouring numbers: SLSQP's unit box then
        # has a span (before: 0, and the designs NaN)
        narrow = ~(hi > lo)
        lo = np.where(narrow, np.maximum(xl, np.nextafter(best, -np.inf)), lo)
        hi = np.where(narrow, np.minimum(xu, np.nextafter(best, np.inf)), hi)
        self.gradient.box = (lo, hi)
        self.gradient.start = best
        if self.max_iterations is not None:
            self.gradient.max_iterations = max(self.max_iterations - self.ga.n_gen, 1)
        if self.max_evaluations is not None:
            self.gradient.max_evaluations = max(self.max_evaluations - self.ga.n_eval, 1)
        self._in_ga = False
        self.gradient.setup(self.problem, self._rng)

    @property
    def n_gen(self) -> int:  # type: ignore[override]  # (counted by its two stages)
        return self.ga.n_gen + (0 if self._in_ga else self.gradient.n_gen)

    @property
    def n_eval(self) -> int:
        return self.ga.n_eval + (0 if self._in_ga else self.gradient.n_eval)

    def optimum(self) -> Solutions:
        return self.ga.optimum() if self._in_ga else self.gradient.optimum()

    def population(self) -> Solutions:
        return self.ga.population() if self._in_ga else self.gradient.population()


class WeightedSum(_PymooProblem):
    """Eq 5.7: one objective ``sum_i w_i f_i`` of ``problem``'s objectives, with the same
    variables, bounds and constraints (pseudo multi-objective optimisation, Cases 4-5)."""

    def __init__(self, problem: _PymooProblem, weights):
        weights = np.asarray(weights, dtype=float)
        if weights.shape != (problem.n_obj,):
            raise ValueError(f"{weights.size} weights for {problem.n_obj} objectives")
        if (weights < 0).any() or not weights.any():
            raise ValueError("weights must be >= 0 and not all 0")
        self.problem, self.weights = problem, weights
        super().__init__(
            n_var=problem.n_var,
            n_obj=1,
            n_ieq_constr=problem.n_ieq_constr,
            xl=problem.xl,
            xu=problem.xu,
        )

    def _evaluate(self, X, out, *args, **kwargs):
        F, G = self.problem.evaluate(X, return_values_of=["F", "G"])
        out["F"] = (F @ self.weights)[:, None]
        out["G"] = G


def balanced_weights(
    problem: _PymooProblem,
    samples: int,
    rng: np.random.Generator,
    dominant: int | None = None,
    factor: float = 10.0,
) -> np.ndarray:
    """Weights that put the objectives on one scale (Sec 5.2.1, Cases 4-5).

    ``w_i = 1 / median |f_i|`` over ``samples`` designs drawn uniformly in the bounds from
    ``rng`` (designs that failed, ``F >= PENALTY``, are left out), so each term of Eq 5.7 is
    about 1 at a typical design (Case 4). ``dominant`` (an objective index) gets ``factor``
    times its weight: one order of magnitude above the others for ``factor = 10`` (Case 5).
    """
    X = problem.xl + rng.random((samples, problem.n_var)) * (problem.xu - problem.xl)
    F = np.asarray(problem.evaluate(X, return_values_of=["F"]))
    F = F[(np.isfinite(F) & (F < PENALTY)).all(axis=1)]
    median = np.median(np.abs(F), axis=0) if len(F) else np.zeros(problem.n_obj)
    if not (median > 0).all():
        raise ValueError(
            f"cannot balance the weights: {len(F)} of {samples} random designs "
            f"gave finite objectives and some objective's median is 0"
        )
    weights = 1.0 / median
    if dominant is not None:
        weights[dominant] *= factor
    return weights


def termination(
    n_obj: int,
    generations: int | None,
    max_evaluations: int | None,
    tolerance: float,
    stall_generations: int,
):
    """pymoo's default termination: budget, or no progress over ``stall_generations``."""
    cls = DefaultSingleObjectiveTermination if n_obj == 1 else DefaultMultiObjectiveTermination
    return cls(
        ftol=tolerance,
        period=stall_generations,
        n_max_gen=generations or float("inf"),
        n_max_evals=max_evaluations or float("inf"),
    )


#: Constructor arguments suspopt sets itself.
_RESERVED = (
    "termination",
    "seed",
    "callback",
    "display",
    "verbose",
    "evaluator",
    "output",
    "save_history",
    "pop_size",
)


def _flag(value) -> bool:
    return isinstance(value, bool)


def _real(low: float, high: float):
    return lambda value: (
        isinstance(value, (int, float)) and not isinstance(value, bool) and low <= value <= high
    )


def _choice(*values):
    return lambda value: isinstance(value, str) and value in values


_DE_VARIANTS = tuple(
    f"DE/{selection}/{n}/{crossover}"
    for selection in ("rand", "best", "target-to-best")
    for n in (1, 2)
    for crossover in ("bin", "exp")
)
#: The options a config may pass to a pymoo constructor: plain data (a config cannot hold a
#: pymoo object, and nothing read from a file runs as code), each with its check and what it
#: takes.
DATA_OPTIONS: dict[str, tuple] = {
    "eliminate_duplicates": (_flag, "true or false"),
    "return_least_infeasible": (_flag, "true or false"),
    "n_offsprings": (
        lambda v: isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= 1_000_000,
        "a whole number from 1 to 1000000",
    ),
    "CR": (_real(0.0, 1.0), "a number in [0, 1]"),
    "F": (_real(1e-6, 2.0), "a number in (0, 2]"),
    "gamma": (_real(0.0, 1.0), "a number in [0, 1]"),
    "variant": (_choice(*_DE_VARIANTS), "one of " + ", ".join(_DE_VARIANTS)),
    "de_repair": (
        _choice("bounce-back", "midway", "rand-init", "to-bounds"),
        "bounce-back, midway, rand-init or to-bounds",
    ),
}


def pymoo_algorithm(target: str, options: dict, population: int | None, n_obj: int):
    """Construct the pymoo algorithm ``"module:Class"`` with ``options`` and ``population``;
    ValueError naming a bad option (with close matches) or a value of the wrong kind
    (:data:`DATA_OPTIONS`)."""
    import difflib

    module, name = target.split(":")
    cls = getattr(importlib.import_module(module), name)
    allowed = _init_parameters(cls)
    options = dict(options)
    for key, value in options.items():
        if key in _RESERVED:
            raise ValueError(f"option {key!r} is set by suspopt (from the optimiser section)")
        if key not in allowed:
            close = difflib.get_close_matches(key, sorted(allowed), n=3)
            raise ValueError(
                f"{name} has no option {key!r}"
                + (f"; did you mean {', '.join(close)}?" if close else "")
            )
        if key not in DATA_OPTIONS:
            usable = sorted(k for k in DATA_OPTIONS if k in allowed)
            raise ValueError(
                f"{name}'s option {key!r} takes a pymoo object, which a config "
                f"cannot give; the options it takes from a config are "
                f"{', '.join(usable) or 'none'}"
            )
        check, takes = DATA_OPTIONS[key]
        if not check(value):
            raise ValueError(f"option {key!r} takes {takes}, got {value!r:.40}")
    if population is not None:
        if "pop_size" not in allowed:
            raise ValueError(f"{name} has no population; remove optimiser.population")
        options["pop_size"] = population
    return cls(**options)


def _init_parameters(cls) -> set[str]:
    """Keyword arguments accepted along ``cls``'s constructors (following ``**kwargs`` up
    the class hierarchy)."""
    allowed = set()
    for klass in cls.__mro__:
        if "__init__" not in vars(klass):
            continue
        params = inspect.signature(klass.__init__).parameters.values()
        allowed |= {
            p.name
            for p in params
            if p.name != "self" and p.kind not in (p.VAR_KEYWORD, p.VAR_POSITIONAL)
        }
        if not any(p.kind is p.VAR_KEYWORD for p in params):
            break
    if any(k.__name__ == "DE" for k in cls.__mro__):  # DE (GDE3) hands **kwargs to Variant
        from pymoo.algorithms.soo.nonconvex.de import Variant

        allowed |= set(inspect.signature(Variant.__init__).parameters) - {"self", "kwargs"}
    return allowed


def minimize(problem: _PymooProblem, optimiser: Optimiser, seed: int, callback=None) -> Solutions:
    """Run ``optimiser`` on ``problem`` with ``np.random.default_rng(seed)``; call
    ``callback(optimiser)`` after every generation; return the optimum."""
    optimiser.setup(problem, np.random.default_rng(seed))
    while optimiser.has_next():
        optimiser.next()
        if callback is not None:
            callback(optimiser)
    return optimiser.optimum()
