"""``suspopt.Problem``: the YAML optimisation problem as a vectorised pymoo ``Problem``.

``Problem.from_config(cfg)`` reads ``design_variables``, ``objectives`` and ``constraints``
(:mod:`suspopt.config.optimise`); ``evaluate(X)`` runs ONE batched simulation for the
whole population ``X (N, n_var)`` (in batches of at most :data:`!MAX_BATCH` designs, or fewer
when memory asks), keeping no (P, T) signal its metrics do not need
(:func:`suspopt.streaming.reduce`), and returns ``F (N, n_obj)`` and ``G (N, n_ieq_constr)``
(``G <= 0`` feasible, Eq 6.3).

Search coordinates. ``X`` holds each variable's value in its SI unit, except that a variable
with ``scale: log`` is its ``log10``; :meth:`Problem.to_physical` gives the values (integer
variables rounded). ``xl``/``xu`` are in the same coordinates.

Failed designs never stop a run. A design whose simulation diverges, or whose objectives or
constraints come out NaN or infinite (an undefined seat geometry, Sec 8.2.2), gets every
objective set to :data:`!PENALTY` and the last constraint, ``simulation_failed``, set to
:data:`!PENALTY` (it is -1 for a sound design); its other non-finite constraints are
:data:`!PENALTY` too. Constrained algorithms therefore rank it below every sound design.
"""

from __future__ import annotations

import difflib
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from pymoo.core.problem import Problem as _PymooProblem

from .. import execution, streaming
from ..checks import check_exact
from ..config import Config, ConfigError
from ..config.loader import require_config
from ..config.optimise import DesignVariable, batches
from ..config.scenarios import CONSTRAINT_DEFAULT, OBJECTIVE_DEFAULT
from ..controller import build_controller
from ..params import ParamView, field_unit, numeric_paths, one_per_run
from ..seat import CONSTRAINT_UNITS, build_attachments, seat_constraints, seat_static_deflection
from ..simulation import signal_table
from ..specs import evaluate_spec, metric_unit, spec_signals
from ..vehicle import build_vehicle
from .scenarios import ScenarioSet, aggregate

__all__ = ["Problem", "PENALTY", "BATCH_BYTES", "MAX_BATCH"]

#: Objective and constraint value given to a failed (diverged, NaN) design.
PENALTY = 1.0e10
#: Memory one batch of an evaluation may take [bytes] (:meth:`Problem.batch_width`): a
#: population larger than that (a Ch. 8 seat on 1000 m of road takes about 11 MB per design)
#: is simulated in batches of equal width, one after the other.
BATCH_BYTES = 2 << 30

#: The most designs of one batch: beyond about this many the working set of a batch leaves
#: the caches and the time per design grows (``benchmarks/bench_simulate.py``).
MAX_BATCH = 2048

_FAILED = "simulation_failed"
#: The most designs whose values under every scenario an evaluation keeps (for the Pareto file).
_REMEMBERED = 100_000


@dataclass(frozen=True)
class _Term:
    """A compiled objective or constraint spec: its value names and units, one per column.
    ``spec`` is the config's :class:`~suspopt.config.optimise.Objective`, or its
    :class:`~suspopt.config.optimise.Constraint` (``min``, ``max``, ...) for a constraint."""

    spec: Any
    names: tuple[str, ...]
    units: tuple[str, ...]
    keys: tuple[str, ...] = ()  # seat.geometry: the seat_constraints keys, in order
    signals: tuple[str, ...] = ()  # the signals a metric reads


class Problem(_PymooProblem):
    """The optimisation problem of a config (see the module docstring).

    Names and units, in column order: ``var_names``/``var_units`` (X, physical values),
    ``obj_names``/``obj_units`` (F), ``constraint_names``/``constraint_units`` (G),
    ``supplementary_names``/``supplementary_units`` (``S``, computed when asked for with
    ``evaluate(X, return_values_of=["S"])``). ``constraint_scale (n_ieq_constr,)`` is each
    constraint's bound magnitude (1 where the bound is 0), for algorithms that scale ``G``.

    Parameters
    ----------
    cfg : Config
        The study, with its ``design_variables`` (bounds in the fields' SI units).
    objectives : sequence of _Term
        The objectives, each a metric spec with its sense (minimised or maximised).
    constraints : sequence of _Term
        The constraints ``g <= 0``, each a metric spec with its bound (in the metric's unit).
    supplementary : sequence of _Term
        Further metrics computed only when asked for (``S``).
    """

    def __init__(
        self,
        cfg: Config,
        objectives: Sequence[_Term],
        constraints: Sequence[_Term],
        supplementary: Sequence[_Term] = (),
    ):
        self.cfg = cfg
        self.variables: list[DesignVariable] = list(cfg.design_variables)
        self._objectives, self._constraints = list(objectives), list(constraints)
        self._supplementary = list(supplementary)
        self._sim_cfg = cfg.model_copy(update={"metrics": []})
        self._width: int | None = None
        #: the scenarios every design is evaluated under (None: the config alone)
        self.scenarios = ScenarioSet.from_config(cfg)
        self._scenario_values: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}
        self._simulates = any(t.spec.metric for t in self._all_terms())
        self._log = np.array([v.scale == "log" for v in self.variables])
        self._integer = np.array([v.integer for v in self.variables])
        lower = np.array([v.lower for v in self.variables], dtype=float)
        upper = np.array([v.upper for v in self.variables], dtype=float)
        self.var_names = [v.label for v in self.variables]
        self.var_units = [field_unit(cfg, v.path) for v in self.variables]
        self.obj_names = [n for t in self._objectives for n in t.names]
        self.obj_units = [u for t in self._objectives for u in t.units]
        self.supplementary_names = [n for t in self._supplementary for n in t.names]
        self.supplementary_units = [u for t in self._supplementary for u in t.units]
        self.constraint_names, self.constraint_units, scale = [], [], []
        for term in self._constraints:
            for name, unit in zip(term.names, term.units):
                for op, bound in ((">=", term.spec.min), ("<=", term.spec.max)):
                    if bound is not None:
                        self.constraint_names.append(f"{name} {op} {bound:g}")
                        self.constraint_units.append(unit)
                        scale.append(abs(bound) or 1.0)
        self.constraint_names.append(_FAILED)
        self.constraint_units.append("1")
        self._how = (
            [t.spec.over_scenarios or OBJECTIVE_DEFAULT for t in self._objectives for _ in t.names],
            [
                t.spec.over_scenarios or CONSTRAINT_DEFAULT
                for t in self._constraints
                for _ in t.names
                for b in (getattr(t.spec, "min", None), getattr(t.spec, "max", None))
                if b is not None
            ],
            [
                t.spec.over_scenarios or OBJECTIVE_DEFAULT
                for t in self._supplementary
                for _ in t.names
            ],
        )
        self.constraint_scale = np.array(scale + [1.0])
        lower[self._log], upper[self._log] = np.log10(lower[self._log]), np.log10(upper[self._log])
        super().__init__(
            n_var=len(self.variables),
            n_obj=len(self.obj_names),
            n_ieq_constr=len(self.constraint_names),
            xl=lower,
            xu=upper,
        )

    @classmethod
    def from_config(cls, cfg: Config) -> Problem:
        """Build the problem of ``cfg``; raise ConfigError (with the YAML line) for a bad path,
        a bound the model rejects, an unknown signal or an objective with several values."""
        if not require_config(cfg).design_variables:
            raise cfg.error(
                ("design_variables",),
                "required key is missing: list the config fields to optimise, with their bounds",
            )
        if cfg.objectives is None:
            raise cfg.error(("objectives",), "required key is missing: give the main objectives")
        _check_paths(cfg)
        _check_batches(cfg)
        available, unit_of, corners = _signals_at_bounds(cfg)

        def compile_all(specs, loc, objective):
            return [
                _compile(cfg, spec, loc + (i,), available, unit_of, corners, objective)
                for i, spec in enumerate(specs)
            ]

        if cfg.simulation.method == "spectral":
            from .. import spectral

            specs: list[tuple[Any, tuple]] = [
                (s, ("objectives", "main", i)) for i, s in enumerate(cfg.objectives.main)
            ]
            specs += [(s, ("constraints", i)) for i, s in enumerate(cfg.constraints)]
            specs += [
                (s, ("objectives", "supplementary", i))
                for i, s in enumerate(cfg.objectives.supplementary)
            ]
            spectral.check(cfg, specs)
            for group in (ScenarioSet.from_config(cfg) or ScenarioSet([], [])).groups:
                for member_cfg in group.configs:
                    if member_cfg is not cfg:
                        spectral.check(member_cfg, specs)
        return cls(
            cfg,
            compile_all(cfg.objectives.main, ("objectives", "main"), True),
            compile_all(cfg.constraints, ("constraints",), False),
            compile_all(cfg.objectives.supplementary, ("objectives", "supplementary"), True),
        )

    @property
    def search_units(self) -> list[str]:
        """Units of the search coordinates ``X``: ``log10(unit)`` on a log scale."""
        return [f"log10({u})" if log else u for u, log in zip(self.var_units, self._log)]

    def to_physical(self, X) -> np.ndarray:
        """Values of the design variables (N, n_var) in SI units: ``10**X`` on a log scale,
        rounded for integer variables."""
        values = self._rows(X, "X")
        values[:, self._log] = 10.0 ** values[:, self._log]
        values[:, self._integer] = np.round(values[:, self._integer])
        return values

    def to_search(self, values) -> np.ndarray:
        """The search coordinates ``X`` of physical values (N, n_var): the inverse of
        :meth:`to_physical` (``log10`` on a log scale), e.g. to re-evaluate a Pareto file's
        designs."""
        X = self._rows(values, "values")
        X[:, self._log] = np.log10(X[:, self._log])
        return X

    def evaluate(self, X, *args, **kwargs):
        """pymoo's :meth:`~pymoo.core.problem.Problem.evaluate`, an ``X`` that is not
        ``(N, n_var)`` a ValueError naming its shape (pymoo asserts it)."""
        odd = isinstance(X, np.ndarray) and (X.ndim > 2 or X.shape[-1:] != (self.n_var,))
        if odd and X.dtype != object:  # (a population of the right shape is not copied)
            self._rows(X, "X")
        return super().evaluate(X, *args, **kwargs)

    def _rows(self, X, what: str) -> np.ndarray:
        """``X`` as a float copy (N, n_var); ValueError naming the shape for any other."""
        rows = np.array(np.atleast_2d(X), dtype=float)
        if rows.ndim != 2 or rows.shape[1] != self.n_var:
            raise ValueError(
                f"{what} must be (N designs, {self.n_var}: {', '.join(self.var_names)}); "
                f"got shape {rows.shape}"
            )
        return rows

    def params(self, X) -> dict[str, np.ndarray]:
        """``simulate``'s ``params``: each variable's dotted path -> its (N,) values."""
        values = self.to_physical(X)
        return {v.path: values[:, j] for j, v in enumerate(self.variables)}

    def _all_terms(self) -> list[_Term]:
        return self._objectives + self._constraints + self._supplementary

    def batch_width(self) -> int:
        """Designs simulated in one batch: as many as fit in :data:`!BATCH_BYTES` (or half of
        ``--max-memory`` when that is smaller) by :func:`!suspopt.simulation.run_memory`, at
        least one, at most :data:`!MAX_BATCH` (so that the time per design does not grow with
        the population). It depends on the config (and an explicit memory limit) only, never
        on the memory free at the moment, so that a run repeats bit for bit."""
        if self._width is None:
            from .. import memory
            from ..simulation import prepare, run_memory
            from ..specs import METRICS

            terms = [t for t in self._all_terms() if t.spec.metric]
            signals = len({n for t in terms for n in t.signals})
            kept = sum(
                len(t.signals) for t in terms if METRICS[str(t.spec.metric)].stream == "keep"
            )
            runs = [(self._sim_cfg, 1)]
            if self.scenarios is not None:  # a design takes a column per scenario of a group
                runs = [(g.sim_cfg, len(g.members)) for g in self.scenarios.groups]
            per_design = 0.0
            for sim_cfg, columns in runs:
                _, model, controller, attachments = prepare(sim_cfg)
                # streamed: one window, and the kept signals whole
                window = streaming.BLOCK if controller is None else None
                _, per_column = run_memory(
                    sim_cfg, model, attachments, 1, signals, window, 2 * kept if window else 0
                )
                per_design = max(per_design, columns * per_column)
            cap = memory.explicit_limit()
            budget = BATCH_BYTES if cap is None else min(BATCH_BYTES, cap // 2)
            self._width = max(1, min(MAX_BATCH, int(budget // per_design)))
        return self._width

    def _evaluate(self, X, out, *args, **kwargs):
        supplementary = "S" in out
        if not self._simulates:
            parts = [self._evaluate_batch(X, supplementary)] if len(X) else []
        elif execution.is_local(self.cfg.execution):
            width = self.batch_width()
            parts = [
                self._evaluate_batch(X[i : i + width], supplementary)
                for i in range(0, len(X), width)
            ]
        else:  # chunks of a fixed width on the executor in force (suspopt.execution)
            width = min(execution.chunk_width(self.cfg.execution), self.batch_width())
            rows = [(X[s], supplementary) for s in execution.chunks(len(X), width)]
            parts = execution.map_chunks(_chunk_values, self, rows, self.cfg.execution)
        if self.scenarios is not None:
            self._remember(X, parts)
        for j, key in enumerate(("F", "G", "S")):
            if key in out or key != "S":
                out[key] = (
                    np.concatenate([p[j] for p in parts])
                    if parts
                    else np.empty(
                        (0, (self.n_obj, self.n_ieq_constr, len(self.supplementary_names))[j])
                    )
                )

    def _evaluate_batch(self, X, supplementary: bool):
        """``(F, G, S, FS, GS)`` of one batch of designs: F, G (and S, or None), in one
        simulation that keeps no signal it does not need (:func:`suspopt.streaming.reduce`);
        with scenarios, one simulation per scenario group, the values of every scenario
        ``FS (P, S, m)``, ``GS (P, S, k)`` (NaN where a scenario failed) and F, G, S their
        aggregates (:func:`suspopt.optimisation.scenarios.aggregate`); else FS, GS are None."""
        params = self.params(X)
        terms = self._objectives + self._constraints
        terms += self._supplementary if supplementary else []
        requests = [(t.spec, t.signals) for t in terms if t.spec.metric]
        reduce: Any = streaming.reduce
        if self.cfg.simulation.method == "spectral":
            from .. import spectral

            reduce = spectral.reduce
        if self.scenarios is not None:
            return self._evaluate_scenarios(params, len(X), supplementary, requests, reduce)
        with np.errstate(all="ignore"):  # failed designs are flagged, not warned about
            result = reduce(self._sim_cfg, params, requests) if requests else None
        return (*self.values(result, params, len(X), supplementary), None, None)

    def _evaluate_scenarios(self, params, P: int, supplementary: bool, requests, reduce):
        """:meth:`_evaluate_batch` under the scenarios: every group's P x S_g columns in one
        simulation; a design that fails in one scenario fails."""
        assert self.scenarios is not None
        S = len(self.scenarios.names)
        shapes = (self.n_obj, self.n_ieq_constr - 1, len(self.supplementary_names))
        values = [np.full((P, S, k), np.nan) for k in shapes]
        failed = np.zeros((P, S), dtype=bool)
        for group in self.scenarios.groups:  # one simulation per group (a time grid)
            columns = self.scenarios.columns(group, params, P)
            n = P * len(group.members)
            roads = {"roads": group.roads} if group.roads else {}  # a road per scenario
            with np.errstate(all="ignore"):  # failed designs are flagged, not warned about
                result = reduce(group.sim_cfg, columns, requests, **roads) if requests else None
                raw = self._raw(result, columns, n, supplementary, group.cfg)
            for whole, part in zip(values + [failed], raw):
                if part is not None:  # (S_g P, ...) scenario after scenario -> (P, S_g, ...)
                    part = part.reshape((len(group.members), P) + part.shape[1:])
                    whole[:, group.members] = np.moveaxis(part, 0, 1)
        FS, GS, SS = values
        weights = self.scenarios.weights
        with np.errstate(all="ignore"):
            F, G, Sv = (aggregate(v, how, weights) for v, how in zip(values, self._how))
            F, G, _ = self._penalised(F, G, None, failed.any(axis=1))
        FS[failed], GS[failed] = np.nan, np.nan
        GS = np.concatenate([GS, np.where(failed, PENALTY, -1.0)[..., None]], axis=-1)
        return F, G, Sv if supplementary else None, FS, GS

    def _remember(self, X, parts) -> None:
        """Keep every scenario's values of the designs just evaluated, by their physical
        values, for the Pareto file (:meth:`scenario_values`); at most
        :data:`_REMEMBERED` designs, the oldest dropped first."""
        if not len(X):
            return
        FS = np.concatenate([p[3] for p in parts])
        GS = np.concatenate([p[4] for p in parts])
        for row, fs, gs in zip(self.to_physical(X), FS, GS):
            self._scenario_values[row.tobytes()] = (fs, gs)
        while len(self._scenario_values) > _REMEMBERED:
            del self._scenario_values[next(iter(self._scenario_values))]

    def scenario_values(self, values) -> tuple[np.ndarray, np.ndarray]:
        """``FS (N, S, m)``, ``GS (N, S, k)``: the objectives and constraint margins of the
        designs of physical ``values (N, n_var)`` under every scenario (NaN where one failed,
        and ``simulation_failed`` :data:`!PENALTY` there), from the evaluations that found
        them, else simulated now."""
        if self.scenarios is None:
            raise ValueError("scenario_values: this problem's config has no scenarios: section")
        values = self._rows(values, "values")
        missing = [i for i, row in enumerate(values) if row.tobytes() not in self._scenario_values]
        if missing:
            self.evaluate(self.to_search(values[missing]), return_values_of=["F", "G"])
        S = len(self.scenarios.names)
        empty = (np.full((S, self.n_obj), np.nan), np.full((S, self.n_ieq_constr), np.nan))
        found = [self._scenario_values.get(row.tobytes(), empty) for row in values]
        return (
            np.array([f[0] for f in found]).reshape(len(values), S, self.n_obj),
            np.array([f[1] for f in found]).reshape(len(values), S, self.n_ieq_constr),
        )

    def aggregation(self) -> tuple[list[str], list[str]]:
        """How each objective and each constraint combines over the scenarios, as text
        (``mean``, ``max``, ``quantile 0.9``, ...; ``any`` for ``simulation_failed``)."""

        def text(rule) -> str:
            return rule if isinstance(rule, str) else f"quantile {rule.quantile:g}"

        return [text(r) for r in self._how[0]], [text(r) for r in self._how[1]] + ["any"]

    def values(self, result, params: dict[str, np.ndarray], P: int, supplementary: bool = False):
        """``(F, G, S)`` of P designs from their simulation ``result`` (None when no term
        needs one) and ``params`` (dotted path -> (P,) physical values): the objectives, the
        constraints with ``simulation_failed`` last, and the supplementary objectives (None
        unless asked), failed designs penalised (module docstring)."""
        with np.errstate(all="ignore"):  # failed designs are flagged below, not warned about
            F, G, S, failed = self._raw(result, params, P, supplementary, self.cfg)
            return self._penalised(F, G, S, failed)

    def _raw(self, result, params, P: int, supplementary: bool, cfg: Config):
        """``(F, G, S, failed)`` of P designs, unpenalised: G without ``simulation_failed``,
        S None unless asked, ``failed (P,)`` where a design diverged or a value is not
        finite."""
        F = _stack(self._objectives, cfg, result, params, P)
        G = self._constraint_values(result, params, P, cfg)
        failed = ~(np.isfinite(F).all(axis=1) & np.isfinite(G).all(axis=1))
        if result is not None:
            failed |= result.diverged
        S = _stack(self._supplementary, cfg, result, params, P) if supplementary else None
        return F, G, S, failed

    @staticmethod
    def _penalised(F, G, S, failed):
        """F, G (with ``simulation_failed`` last) and S, failed designs penalised."""
        return (
            np.where(failed[:, None], PENALTY, F),
            np.column_stack(
                [np.where(np.isfinite(G), G, PENALTY), np.where(failed, PENALTY, -1.0)]
            ),
            S,
        )

    def _constraint_values(self, result, params, P: int, cfg: Config) -> np.ndarray:
        """``g = min - value`` and ``g = value - max`` of every constraint column, (P, k)."""
        columns = []
        for term in self._constraints:
            values = _values(term, cfg, result, params)
            for j in range(values.shape[1]):
                if term.spec.min is not None:
                    columns.append(term.spec.min - values[:, j])
                if term.spec.max is not None:
                    columns.append(values[:, j] - term.spec.max)
        return np.column_stack(columns) if columns else np.empty((P, 0))


def _chunk_values(problem: Problem, rows: tuple[np.ndarray, bool]):
    """In a worker: ``(F, G, S, FS, GS)`` of one chunk of designs (:mod:`suspopt.execution`)."""
    return problem._evaluate_batch(*rows)


def _stack(terms: Sequence[_Term], cfg: Config, result, params, P: int) -> np.ndarray:
    """Values of terms side by side, (P, columns)."""
    if not terms:
        return np.empty((P, 0))
    return np.column_stack([_values(t, cfg, result, params) for t in terms])


def _values(term: _Term, cfg: Config, result, params) -> np.ndarray:
    """The (P, len(term.names)) values of one term."""
    spec = term.spec
    if spec.quantity == "seat.static_deflection":
        return seat_static_deflection(cfg, params)[:, None]
    if spec.quantity == "seat.geometry":
        values = seat_constraints(cfg, params, mu=spec.mu or 0.8)
        return np.column_stack([values[k] for k in term.keys])
    return np.column_stack([v for _, v, _ in evaluate_spec(spec, result, result.signal_unit)])


# --- construction checks ----------------------------------------------------------------------


def _check_paths(cfg: Config) -> None:
    """Every design variable is a numeric config field that the simulator reads per design."""
    numeric = numeric_paths(cfg)
    seen: dict[str, int] = {}
    for i, var in enumerate(cfg.design_variables):
        loc = ("design_variables", i, "path")
        if var.path not in numeric:
            close = difflib.get_close_matches(var.path, list(numeric), n=3, cutoff=0.5)
            raise cfg.error(
                loc,
                f"{var.path!r} is not a numeric field of this config"
                + (
                    f"; did you mean {', '.join(close)}?"
                    if close
                    else " (derived quantities such as a seat's K_v stay derived)"
                ),
            )
        why = one_per_run(var.path)
        if why is not None:
            raise cfg.error(loc, f"{var.path} cannot vary between designs: {why}")
        if var.path in seen:
            raise cfg.error(loc, f"{var.path} is already design_variables[{seen[var.path]}]")
        seen[var.path] = i


def _check_batches(cfg: Config) -> None:
    """Every ``batch`` of the design variables names two of them or more (a batch of one is
    a variable drawn alone: most likely a misspelt name)."""
    for name, members in batches(cfg.design_variables).items():
        if len(members) == 1:
            raise cfg.error(
                ("design_variables", members[0], "batch"),
                f"batch {name!r} has this variable alone: a batch is the parts of two design "
                f"variables or more that are made together (give the other its name too)",
            )


def _signals_at_bounds(cfg: Config):
    """Build the model with every variable at its lower bound (design 0) and at its upper
    bound (design 1), so that a bound the model rejects fails now; return the signal names
    of the model, a signal-unit function and the corners."""
    bounds = {v.path: np.array([v.lower, v.upper]) for v in cfg.design_variables}
    try:
        pv = ParamView(cfg, bounds)
        model = build_vehicle(cfg, pv)
        controller = build_controller(cfg, pv, model)
        attachments = build_attachments(cfg, pv)
    except ConfigError as exc:
        raise _at_variable(cfg, str(exc)) from None
    check_exact(cfg, (pv, model, controller, attachments))  # (simulation.method exact)
    table = signal_table(model, dict(getattr(controller, "units", {})), attachments)

    def unit_of(name: str) -> str:
        return table[name].unit

    return list(table), unit_of, model.corners


def _at_variable(cfg: Config, message: str) -> ConfigError:
    """Locate a model error about a design parameter at the design variable it names; one
    already located in the config (``FILE:LINE: key: ...``) about no design variable keeps
    its own place (it was put inside a second one before)."""
    original, place = message, f"{cfg.source if cfg.source is not None else '<config>'}:"
    line, _, rest = message.removeprefix(place).partition(": ")
    located = message.startswith(place) and (line.isdigit() or line == "?")
    message = (rest if located else message).removeprefix("params: ")
    for i, var in sorted(enumerate(cfg.design_variables), key=lambda iv: -len(iv[1].path)):
        if var.path in message:
            return cfg.error(
                ("design_variables", i),
                f"with every variable at its lower (design 0) or upper (design 1) bound: {message}",
            )
    if located:
        return ConfigError(original)
    return cfg.error(("design_variables",), message)


def _compile(
    cfg: Config,
    spec: Any,  # (an Objective, or a Constraint when not ``objective``)
    loc: tuple,
    available: list[str],
    unit_of,
    corners: tuple[str, ...],
    objective: bool,
) -> _Term:
    """Check one spec against the model and name its value columns."""
    if spec.quantity is not None:
        if cfg.seat is None:
            raise cfg.error(loc + ("quantity",), f"{spec.quantity} needs a seat: section")
        if spec.quantity == "seat.static_deflection":
            return _Term(spec, (spec.label,), ("m",))
        known = list(seat_constraints(cfg))
        keys = tuple(spec.conditions or known)
        for j, key in enumerate(keys):
            if key not in known:
                close = difflib.get_close_matches(key, known, n=3)
                raise cfg.error(
                    loc + ("conditions", j),
                    f"{cfg.seat.kind} has no condition {key!r}; it has {', '.join(close or known)}",
                )
        return _Term(
            spec,
            tuple(f"{spec.label}.{k}" for k in keys),
            tuple(CONSTRAINT_UNITS[k] for k in keys),
            keys,
        )
    try:
        signals = spec_signals(spec, available, corners)
    except ValueError as exc:
        raise cfg.error(loc + ("signal",), str(exc)) from None
    unit = metric_unit(spec, unit_of(signals[0]))
    if (len(signals) == 1 and spec.signal in available) or spec.reduce != "none":
        return _Term(spec, (spec.label,), (unit,), signals=tuple(signals))
    if objective:
        corner_list = ", ".join(s.rsplit(".", 1)[1] for s in signals)
        raise cfg.error(
            loc + ("reduce",),
            f"{spec.label} gives one value per corner "
            f"({corner_list}); an objective is one number per design: add "
            f"reduce: mean (or max, min, sum)",
        )
    return _Term(
        spec,
        tuple(f"{spec.label}.{s.rsplit('.', 1)[1]}" for s in signals),
        (unit,) * len(signals),
        signals=tuple(signals),
    )
