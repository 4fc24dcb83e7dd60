"""Common base of every config section: unknown keys are rejected, numbers stay numbers."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field

from ..errors import check_known

__all__ = [
    "Section",
    "check_known",
    "quantity",
    "Mass",
    "Inertia",
    "Stiffness",
    "TorsionalStiffness",
    "CubicStiffness",
    "Damping",
    "VehicleLength",
    "SeatLength",
    "RoadHeight",
    "RoadLength",
    "Speed",
    "Duration",
    "Step",
    "Ratio",
    "Seed",
    "Finite",
    "bounds",
]


def bounds(low: float | None, high: float, *, closed: bool = True) -> Any:
    """The field constraint of a finite float in ``[low, high]`` (``(low, high]`` with
    ``closed=False``), for ``Annotated[float, bounds(...)]``: the range is checked on load and
    stated in the JSON schema."""
    bound: dict[str, Any] = {} if low is None else {"ge" if closed else "gt": low}
    return Field(le=high, allow_inf_nan=False, **bound)


def quantity(low: float | None, high: float, *, closed: bool = True) -> Any:
    """``Annotated[float, bounds(low, high)]`` built at run time (for models made by
    ``create_model``; in a class body write the ``Annotated`` form, which type checkers read)."""
    return Annotated[float, bounds(low, high, closed=closed)]


# Physically plausible ranges of the config's quantities, SI. They are wide (a bicycle's seat
# to a mining truck) and exist so that a value no suspension has (0 kg, 1e308 N/m, inf) is bad
# input with its key and line, never an overflow or a singular matrix deep in a run.
#: [kg] from a gram (a passenger's diaphragm is 0.46 kg) to 1000 t
Mass = Annotated[float, bounds(1e-3, 1e6)]
#: [kg m^2]
Inertia = Annotated[float, bounds(1e-3, 1e8)]
#: [N/m], > 0
Stiffness = Annotated[float, bounds(1e-3, 1e10)]
#: [N m/rad] (anti-roll bars), 0 for none
TorsionalStiffness = Annotated[float, bounds(0.0, 1e10)]
#: [N/m^3] (Duffing term, Eq 2.31; the thesis's k_nl reach 3e7)
CubicStiffness = Annotated[float, bounds(-1e14, 1e14)]
#: [N s/m]
Damping = Annotated[float, bounds(0.0, 1e8)]
#: [m] body geometry: centre of gravity to an axle or a wheel track
VehicleLength = Annotated[float, bounds(1e-3, 100.0)]
#: [m] seat mechanism geometry
SeatLength = Annotated[float, bounds(1e-4, 10.0)]
#: [m] bump height, negative for a pothole
RoadHeight = Annotated[float, bounds(-10.0, 10.0)]
#: [m] bump length on the road
RoadLength = Annotated[float, bounds(1e-3, 1e5, closed=False)]
#: [m/s] vehicle speed, up to 720 km/h
Speed = Annotated[float, bounds(1e-3, 200.0)]
#: [s] times within a run
Duration = Annotated[float, bounds(0.0, 1e5, closed=False)]
#: [s] integration and output steps
Step = Annotated[float, bounds(1e-7, 1.0)]
#: [-] a dimensionless factor
Ratio = Annotated[float, bounds(0.0, 1e3)]
#: [-] any finite number
Finite = Annotated[float, Field(allow_inf_nan=False)]
#: a random seed (numpy SeedSequence entropy, stored in HDF5 as int64)
Seed = Annotated[int, Field(ge=0, le=2**63 - 1)]


class Section(BaseModel):
    """Base class of all config sections.

    Unknown keys are errors (a misspelt key must never be silently ignored) and fields are
    validated on assignment so that a programmatic edit is checked like a YAML value. Types
    are strict: a number field takes a number (an integer field a whole number written
    without a point), never a boolean or a string, and a text field takes text.
    """

    # defer_build: a section's validator is built inside the one of the config that holds it,
    # when a config is first read, not once more per section class at import
    model_config = ConfigDict(
        extra="forbid", validate_assignment=True, frozen=False, strict=True, defer_build=True
    )
