"""The optimisation sections: ``design_variables``, ``objectives``, ``constraints``, ``optimiser``.

Sec 5.2 and 6.1 (Eq 6.1-6.4): minimise the main objectives over the design variables, subject
to inequality constraints ``g <= 0``. Objectives and constraints are metric specs
(:class:`~suspopt.config.metrics.MetricSpec`: a metric of a simulated signal) or design
quantities that need no simulation (``quantity:``, :data:`QUANTITIES`).

- An objective is one number per design. A per-corner spec (``signal: travel`` or a derived
  metric such as ``spring_usage``) must say how to combine its corners with ``reduce``
  (Eq 5.5-5.6 use ``mean``); it is never expanded into one objective per corner, so the number
  of objectives is what the YAML lists.
- A constraint with a per-corner spec gives one constraint per corner (Eq 5.3: each of F1, R1
  must hold). ``max`` gives ``g = value - max``, ``min`` gives ``g = min - value``.

Design variables are numeric config fields by dotted path; derived quantities (a seat's
``K_v = m g / X_ST``, Sec 8.2.2) are not config fields, so they stay derived.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Annotated, Any, Literal

from pydantic import Field, field_validator, model_validator

from .base import Section, Seed, bounds, check_known
from .metrics import MetricSpec
from .scenarios import Aggregate

__all__ = [
    "QUANTITIES",
    "Algorithm",
    "ALGORITHMS",
    "DesignVariable",
    "batches",
    "Objective",
    "Constraint",
    "Objectives",
    "WeightedSum",
    "Balance",
    "Hybrid",
    "Gradient",
    "Optimiser",
]

#: a bound or limit in a field's or a metric's SI unit
_Finite = Annotated[float, bounds(-1e15, 1e15)]
#: [%] of a value, above 0 and below 100: a part's tolerance
Tolerance = Annotated[float, Field(gt=0.0, lt=100.0, allow_inf_nan=False)]
_TOLERANCE = (
    "how far a built part may be off its value [%] (analyse tolerances and builds, unless "
    "their --tolerance says otherwise; default 10)"
)
_BATCH = (
    "parts of one batch: the design variables given the same batch name are off alike in "
    "every build of analyse builds (one draw, each within its own tolerance), unless its "
    "--batch says otherwise; a batch names two variables or more"
)


def _count(high: int) -> Any:
    """A whole number from 1 to ``high``."""
    return Annotated[int, Field(ge=1, le=high)]


#: Design quantities that need no simulation.
QUANTITIES: dict[str, str] = {
    "seat.static_deflection": "X_ST of the seat isolator [m] (Eq 8.2, Sec 8.2.2)",
    "seat.geometry": "the seat's conditions g <= 0 of suspopt.seat.seat_constraints (Tables "
    "8.7, 8.9, 8.11), one value each; constraints only",
}


@dataclass(frozen=True)
class Algorithm:
    """An optimiser by name: ``target`` the "module:Class" (or function) that implements it
    and whether it minimises one objective (a weighted sum turns several into one)."""

    target: str
    single_objective: bool


#: Algorithms by name: the four of Ch. 5-7 and the pymoo algorithms that are reproducible
#: from one seeded Generator in pymoo 0.6.2. Left out: DE, PSO, ES, SRES, ISRES, NSGA-III and
#: U-NSGA-III (some of their comparisons and survivals draw from an unseeded Generator, e.g.
#: to break ties between designs of equal violation), SPEA2 (runs with one seed differ),
#: Nelder-Mead, pattern search and G3PCX (not yet checked against the replayed checkpoints),
#: MOEA/D, C-TAEA and RVEA (they need settings suspopt does not pass) and AGE-MOEA (needs
#: numba). tests/test_optimise.py checks every entry.
ALGORITHMS: dict[str, Algorithm] = {
    "ga": Algorithm("pymoo.algorithms.soo.nonconvex.ga:GA", True),
    "nsga2": Algorithm("pymoo.algorithms.moo.nsga2:NSGA2", False),
    "gradient": Algorithm("scipy.optimize:minimize", True),
    "hybrid": Algorithm("pymoo.algorithms.soo.nonconvex.ga:GA", True),
    "smsemoa": Algorithm("pymoo.algorithms.moo.sms:SMSEMOA", False),
    "gde3": Algorithm("pymoo.algorithms.moo.gde3:GDE3", False),
}


class DesignVariable(Section):
    """One design variable: a numeric config field between bounds (Table 5.2, 7.3, 8.2-8.10)."""

    path: str = Field(
        description="dotted path of a numeric config field, e.g. vehicle.corners.F1.spring.linear"
    )
    lower: _Finite = Field(description="lower bound, in the field's SI unit")
    upper: _Finite = Field(description="upper bound, in the field's SI unit")
    scale: Literal["linear", "log"] = Field(
        "linear",
        description="log: the optimiser searches log10 of the value (for ranges of "
        "several decades, e.g. k_nl 5e5-3e7)",
    )
    integer: bool = Field(False, description="round the value to a whole number")
    name: str | None = Field(
        None, description="short label for tables and HDF5 (default: the path)"
    )
    tolerance: Tolerance | None = Field(None, description=_TOLERANCE)
    batch: str | None = Field(None, min_length=1, max_length=64, description=_BATCH)

    @model_validator(mode="after")
    def _check_bounds(self) -> DesignVariable:
        if self.lower > self.upper:
            raise ValueError(
                f"lower ({self.lower:g}) > upper ({self.upper:g}): did you swap the bounds?"
            )
        if self.lower == self.upper:
            raise ValueError(
                f"lower = upper = {self.lower:g}: a fixed value is no design "
                f"variable; write it in the config instead"
            )
        if self.scale == "log" and self.lower <= 0:
            raise ValueError(f"scale 'log' needs lower > 0 (got {self.lower:g})")
        if self.integer and self.scale == "log":
            raise ValueError("an integer variable cannot have scale 'log'")
        if self.integer and math.ceil(self.lower) > math.floor(self.upper):
            raise ValueError(f"no whole number lies in [{self.lower:g}, {self.upper:g}]")
        return self

    @property
    def label(self) -> str:
        return self.name or self.path


def batches(variables: Sequence[DesignVariable]) -> dict[str, list[int]]:
    """The batches of ``variables``: {batch name: the indices of its variables}, in the order
    first named (the variables without a ``batch`` are left out)."""
    out: dict[str, list[int]] = {}
    for i, v in enumerate(variables):
        if v.batch is not None:
            out.setdefault(v.batch, []).append(i)
    return out


class Objective(MetricSpec):
    """A metric spec (metric of a signal) or a design ``quantity``; one value per design."""

    metric: str | None = Field(  # type: ignore[assignment]  # (optional: or a quantity)
        None, description="metric of a signal (see metrics:); or give quantity"
    )
    quantity: Literal[tuple(QUANTITIES)] | None = Field(  # type: ignore[valid-type]
        None,
        description="design quantity computed without simulating: "
        + "; ".join(f"{k}: {v}" for k, v in QUANTITIES.items()),
    )
    over_scenarios: Aggregate | None = Field(
        None,
        description="how the value combines over the scenarios: mean, max, min, std, "
        "weighted or {quantile: q} (default: mean for an objective; max of the margin g for "
        "a constraint, which then holds in every scenario)",
    )

    @model_validator(mode="after")
    def _metric_or_quantity(self) -> Objective:
        if (self.metric is None) == (self.quantity is None):
            raise ValueError("give either metric (with its signal) or quantity")
        if self.quantity is not None:
            given = [k for k in ("signal", "corners", "weighting") if getattr(self, k)]
            if given or self.reduce != "none":
                raise ValueError(
                    f"quantity {self.quantity!r} takes no {', '.join(given or ['reduce'])}"
                )
        return self

    @property
    def label(self) -> str:
        """The name in F, G and the HDF5 file (default ``metric.signal[.weighting]``)."""
        return (
            self.name
            or self.quantity
            or ".".join(filter(None, [self.metric, self.signal, self.weighting]))
        )


class Constraint(Objective):
    """A spec with ``min`` and/or ``max``: ``g = value - max <= 0``, ``g = min - value <= 0``."""

    min: _Finite | None = Field(None, description="lowest allowed value (g = min - value)")
    max: _Finite | None = Field(None, description="highest allowed value (g = value - max)")
    mu: Annotated[float, bounds(0.0, 1.0, closed=False)] | None = Field(
        None,
        description="μ of the NSS3 condition d < μ R (Table 8.9 #4; quantity "
        "seat.geometry only; default 0.8, Sec 8.3.4)",
    )
    conditions: list[str] | None = Field(
        None,
        description="which seat conditions of quantity seat.geometry to impose "
        "(default all; see suspopt.seat.seat_constraints)",
    )

    @model_validator(mode="after")
    def _bounds(self) -> Constraint:
        if self.min is None and self.max is None:
            raise ValueError("a constraint needs min, max or both")
        if self.min is not None and self.max is not None and self.min >= self.max:
            raise ValueError(f"min ({self.min:g}) >= max ({self.max:g}): did you swap them?")
        for key in ("mu", "conditions"):
            if getattr(self, key) is not None and self.quantity != "seat.geometry":
                raise ValueError(f"{key} belongs to quantity seat.geometry")
        if self.over_scenarios == "std":
            raise ValueError(
                "over_scenarios: a constraint's margin combines by max (every scenario), "
                "mean, min, weighted or quantile, not std"
            )
        return self


class Objectives(Section):
    """Main objectives (optimised) and supplementary ones (evaluated for the selection, Sec 6.2,
    Fig. 6.5: the k-ε sorting ranks the Pareto set by main + supplementary)."""

    main: list[Objective] = Field(min_length=1, description="objectives the optimiser minimises")
    supplementary: list[Objective] = Field(
        default_factory=list, description="objectives evaluated on the designs but not optimised"
    )

    @model_validator(mode="after")
    def _check(self) -> Objectives:
        seen: set[str] = set()
        for spec in self.main + self.supplementary:
            if spec.quantity == "seat.geometry":
                raise ValueError(
                    "quantity seat.geometry gives several values: use it as a constraint"
                )
            if spec.label in seen:
                raise ValueError(
                    f"two objectives are named {spec.label!r}; give them distinct names"
                )
            seen.add(spec.label)
        return self


class Balance(Section):
    """Weights balanced from random designs (Sec 5.2.1, Cases 4-5).

    ``w_i = 1 / median f_i`` over ``samples`` designs drawn uniformly in the bounds with the
    run's random generator, so every term of Eq 5.7 is about 1 at a typical design (Case 4). With
    ``dominant``, that objective's weight is multiplied by ``factor``: its term is one order of
    magnitude above the others for ``factor: 10`` (Case 5).
    """

    samples: _count(1_000_000) = Field(100, description="random designs simulated to balance")  # type: ignore[valid-type]
    dominant: str | None = Field(
        None, description="name of the objective that dominates (Case 5: f1)"
    )
    factor: Annotated[float, bounds(0.0, 1e6, closed=False)] = Field(
        10.0, description="how much the dominant term outweighs the others [-] (Case 5: 10)"
    )


class WeightedSum(Section):
    """Pseudo multi-objective optimisation, Eq 5.7: minimise ``sum_i w_i f_i``."""

    weights: list[Annotated[float, bounds(0.0, 1e12)]] | None = Field(
        None, description="one weight per main objective, in the order of objectives.main"
    )
    balance: Balance | None = Field(
        None, description="derive the weights from random designs instead (Cases 4-5)"
    )

    @model_validator(mode="after")
    def _one_way(self) -> WeightedSum:
        if (self.weights is None) == (self.balance is None):
            raise ValueError("give either weights or balance")
        if self.weights is not None and not any(self.weights):
            raise ValueError("at least one weight must be > 0")
        return self


class Hybrid(Section):
    """GA, then SLSQP from the GA's best inside a box around it (Sec 5.1.1, S3-S4)."""

    ga_generations: _count(1_000_000) = Field(  # type: ignore[valid-type]
        10, description="generations of the GA before the gradient takes over (Sec 5.1.1: 10)"
    )
    shrink: float = Field(
        0.2,
        gt=0,
        le=1,
        description="the gradient's box: the GA best ± "
        "shrink/2 of each variable's range, cut by the original bounds [-]",
    )


class Gradient(Section):
    """SLSQP (scipy) with forward differences, each gradient one batch of n + 1 designs."""

    step: float = Field(
        1.0e-4,
        gt=0,
        lt=0.5,
        description="finite-difference step, as a share of each variable's range [-]",
    )


class Optimiser(Section):
    """The algorithm and its budget. ``seed`` fixes every random draw of the run."""

    algorithm: str = Field(
        description="ga | nsga2 | gradient | hybrid, or a pymoo algorithm: "
        + ", ".join(k for k in ALGORITHMS if k not in ("ga", "nsga2", "gradient", "hybrid"))
    )
    seed: Seed = Field(
        description="seed of the run's random generator (required: runs are "
        "reproducible bit for bit)"
    )
    population: _count(1_000_000) | None = Field(  # type: ignore[valid-type]
        None, description="population size (S1/S3: 200, S2/S4: 1000); not for gradient"
    )
    generations: _count(1_000_000) | None = Field(  # type: ignore[valid-type]
        None,
        description="most generations (gradient: SLSQP iterations; hybrid: GA "
        "generations plus SLSQP iterations)",
    )
    max_evaluations: _count(10**10) | None = Field(None, description="most designs simulated")  # type: ignore[valid-type]
    tolerance: Annotated[float, bounds(0.0, 1.0, closed=False)] = Field(
        1.0e-6,
        description="stop when the best objective improves less than this over "
        "stall_generations (GA; Ch. 5: 1e-6), or SLSQP's ftol on the objective scaled by its "
        "value at the start",
    )
    stall_generations: _count(100_000) = Field(  # type: ignore[valid-type]
        30, description="window of the tolerance test of population algorithms"
    )
    weighted_sum: WeightedSum | None = Field(
        None, description="combine the main objectives into one (Eq 5.7)"
    )
    hybrid: Hybrid | None = Field(None, description="settings of algorithm hybrid")
    gradient: Gradient = Field(
        default_factory=Gradient,
        description="settings of the gradient part (algorithms gradient and hybrid)",
    )
    options: dict[str, Any] = Field(
        default_factory=dict,
        description="keyword arguments of "
        "the pymoo algorithm's constructor (e.g. "
        "eliminate_duplicates, n_offsprings)",
    )

    @field_validator("algorithm")
    @classmethod
    def _known(cls, name: str) -> str:
        return check_known("algorithm", name, ALGORITHMS)

    @model_validator(mode="after")
    def _check(self) -> Optimiser:
        if self.generations is None and self.max_evaluations is None:
            raise ValueError("give a budget: generations, max_evaluations or both")
        if self.algorithm == "gradient" and self.population is not None:
            raise ValueError("algorithm gradient has no population; remove it")
        if self.algorithm in ("ga", "nsga2", "hybrid") and self.population is None:
            raise ValueError(f"algorithm {self.algorithm} needs a population")
        if self.hybrid is not None and self.algorithm != "hybrid":
            raise ValueError("hybrid settings belong to algorithm hybrid")
        if self.options and self.algorithm == "gradient":
            raise ValueError("options are passed to pymoo algorithms; gradient takes none")
        return self
