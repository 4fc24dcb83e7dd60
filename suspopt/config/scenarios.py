"""The ``scenarios:`` section: the conditions a design is optimised over (robust design).

The thesis optimises every design on one road with one passenger and finds afterwards
(Sec 8.4.2-8.4.3, Tables 8.12-8.13) that the fronts move when the road class or the
passenger's mass changes. With a ``scenarios:`` section, ``suspopt optimise`` evaluates every
design under every scenario and optimises an aggregate of each objective over them
(``over_scenarios`` of an objective or constraint, :data:`AGGREGATES`).

A scenario is a name, a set of dotted config paths with values (``set:``) and optionally the
whole load on the seat's isolator (``load_mass`` [kg]), which seats another passenger by the
rule of ``suspopt analyse masses`` (:func:`suspopt.seat.passenger_mass_change`, Sec 8.4.3).
``cases:`` lists scenarios; ``product:`` lists lists whose every combination is a scenario
(names joined by ``/``, sets merged, weights multiplied). The config as written is the first
scenario, ``nominal``, unless ``nominal: false``.

Scenarios that change only numbers the simulator reads per design (masses, stiffnesses,
``c_max``, the passenger) run as extra columns of one batch; a change of the ``road`` or
``simulation`` section (class, speed, seed, length, bump height) makes a scenario group of
its own (:mod:`suspopt.optimisation.scenarios`).
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import Field, field_validator, model_validator

from .base import Section, bounds

__all__ = [
    "Scenario",
    "Scenarios",
    "Quantile",
    "Aggregate",
    "AGGREGATES",
    "MAX_SCENARIOS",
    "OBJECTIVE_DEFAULT",
    "CONSTRAINT_DEFAULT",
]

#: The most scenarios a section may expand to (a product multiplies quickly).
MAX_SCENARIOS = 256

#: How a value combines over the scenarios (``over_scenarios``).
AGGREGATES: dict[str, str] = {
    "mean": "the mean over the scenarios (weights ignored)",
    "max": "the largest value: the worst case of a minimised objective; for a constraint, "
    "it holds in every scenario",
    "min": "the smallest value",
    "std": "the standard deviation over the scenarios (population, ddof 0); objectives only",
    "weighted": "the weighted mean, sum(w v) / sum(w), with the scenarios' weight",
    "quantile": "{quantile: q}: the q-quantile over the scenarios (linear interpolation)",
}
#: ``over_scenarios`` of an objective when it says none.
OBJECTIVE_DEFAULT = "mean"
#: ``over_scenarios`` of a constraint when it says none: its margin g at its largest, so it
#: holds in every scenario.
CONSTRAINT_DEFAULT = "max"

_Name = Annotated[str, Field(min_length=1, max_length=64, pattern=r"^[^/\s][^/]*$")]


class Quantile(Section):
    """The q-quantile of a value over the scenarios."""

    quantile: Annotated[float, bounds(0.0, 1.0)] = Field(
        description="q in [0, 1]: 0.5 the median, 1 the worst case of a minimised objective"
    )


#: ``over_scenarios``: a name of :data:`AGGREGATES` or ``{quantile: q}``.
Aggregate = Literal["mean", "max", "min", "std", "weighted"] | Quantile


class Scenario(Section):
    """One condition: config values changed from the nominal config."""

    name: _Name = Field(description="the scenario's name in tables and HDF5 (no '/')")
    set: dict[str, Any] = Field(
        default_factory=dict,
        max_length=64,
        description="dotted config paths and their values in this scenario, e.g. "
        "road.road_class: C, road.speed: 13.9 [m/s], simulation.duration: 72 [s], "
        "vehicle.body.mass: 320 [kg]; SI units",
    )
    load_mass: Annotated[float, bounds(0.0, 1e6, closed=False)] | None = Field(
        None,
        description="the whole load on the seat's isolator, seat plus passenger [kg]: "
        "another passenger, seated by the rule of suspopt analyse masses (Sec 8.4.3)",
    )
    weight: Annotated[float, bounds(0.0, 1e6, closed=False)] = Field(
        1.0, description="the scenario's weight in over_scenarios: weighted [1]"
    )

    @field_validator("set")
    @classmethod
    def _paths(cls, value: dict) -> dict:
        for path, item in value.items():
            if not path or any(not part for part in path.split(".")):
                raise ValueError(f"{path!r} is not a dotted config path")
            if not isinstance(item, (bool, int, float, str)):
                raise ValueError(f"{path}: takes a number or a word, not {type(item).__name__}")
            if isinstance(item, float) and not abs(item) < float("inf"):
                raise ValueError(f"{path}: the value must be finite, got {item}")
        return value


class Scenarios(Section):
    """The scenarios a design is evaluated under (robust design, module docstring)."""

    nominal: bool = Field(
        True, description="the config as written is the first scenario, named nominal"
    )
    cases: list[Scenario] = Field(
        default_factory=list, max_length=MAX_SCENARIOS, description="scenarios, one each"
    )
    product: list[Annotated[list[Scenario], Field(min_length=1)]] = Field(
        default_factory=list,
        max_length=8,
        description="lists of scenarios; every combination of one from each list is a "
        "scenario (names joined by '/', sets merged, weights multiplied)",
    )

    @model_validator(mode="after")
    def _count(self) -> Scenarios:
        combinations = math.prod(len(factor) for factor in self.product)
        total = int(self.nominal) + len(self.cases) + (combinations if self.product else 0)
        if total > MAX_SCENARIOS:
            raise ValueError(f"{total} scenarios, more than {MAX_SCENARIOS}: use fewer")
        if total == 0:
            raise ValueError("no scenario: give cases or product, or leave nominal true")
        return self
