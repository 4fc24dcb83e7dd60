"""Values plausible for a road vehicle, and the unit slips that explain the others.

The schema's ranges (:mod:`suspopt.config.base`) are wide on purpose: they only keep out what
no model can take (0 kg, 1e308 N/m). A body mass of 1.2 kg is within them, and so is a speed
of 100 m/s; both are most likely a slip of units (1.2 t, 100 km/h). :data:`PLAUSIBLE` is the
one table of such values: for each quantity, the range a road vehicle's value lies in, the
units a value outside it may have been written in, and the limits beyond which it is no road
vehicle's at all.

A value outside its plausible range is:

- an **error** beyond the entry's ``error_below`` / ``error_above``: the value is physically
  absurd for a road vehicle, so rejecting it loses no study (and a run on it would fail with
  a derived message, such as a body of 1.2 kg's RK4 stability limit on ``simulation.dt``);
- a **warning** when one of the entry's slips takes it into the plausible range: it may be
  meant (a lighter or faster vehicle than the table's), so it is said and nothing is refused;
- nothing otherwise: a value no slip explains is the engineer's to choose.

An error or a warning names the slip (``looks like tonnes (1.2 t = 1200 kg)?``). The same hint
is added to a number the schema refuses (a lever arm of 1610, beyond 100 m: ``looks like mm
(1610 mm = 1.61 m)?``), see :mod:`suspopt.config.messages`.

The thresholds, with their reasons (SI units):

- ``vehicle.body.mass``: plausible 50 kg (a quarter of a light car, ``m_s/4``) to 700 t (the
  largest haul trucks, loaded); an error below 5 kg, less than a rider alone, so no road
  vehicle's sprung mass, whatever share of it the model carries.
- unsprung mass (``vehicle.corners.*.unsprung_mass`` and ``corner_defaults``): plausible 5 kg
  (a small car's wheel, hub and brake) to 3 t (a haul truck's axle end); an error below
  0.5 kg, lighter than any road wheel with its tyre.
- the lever arms to the axles ``a_front``, ``a_rear`` (half the wheelbase, about): plausible
  0.1 m to 10 m; an error above 25 m (no rigid road vehicle is 50 m between axles). The
  lever arms to the wheels ``b_right``, ``b_left`` (half the track): 0.1 m to 3 m; an error
  above 10 m (a lane is 3.5 m wide).
- bump height ``road.height``: plausible 1 mm to 0.5 m either way (a kerb is 0.15 m, an
  off-road step 0.5 m); an error above 2 m, a wall, not a bump a wheel can cross.
- bump length ``road.length``: plausible 5 cm to 200 m (the bundled step plateau is 80 m).
- ``road.speed``: plausible 0.1 m/s to 70 m/s (250 km/h); no error below the schema's
  200 m/s: an aircraft's landing gear on a runway, or a record car, is faster than a road
  vehicle and is still a suspension on a road.
- a suspension travel limit (a constraint's ``min`` or ``max`` on ``travel`` or
  ``seat.travel`` by a metric in metres): plausible up to 0.5 m; never an error (a limit
  that no design reaches is loose, not absurd).
- the seat mechanism's lengths (``wall_distance``, ``spring_free_length``, ``bar_length``,
  ``cam_radius``, ``roller_radius``): plausible 5 mm to 1 m (Tables 8.4-8.10 span 0.01-0.3 m).

The same values apply to a design variable's bounds on these paths (``lower``, ``upper``) and
to a scenario's ``set:`` values.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

__all__ = [
    "Plausible",
    "PLAUSIBLE",
    "SAME_UNIT_METRICS",
    "check_plausible",
    "number",
    "slip_hint",
]

#: The metrics whose value has the unit of their signal (a travel limit on them is in m);
#: tests/test_validate.py checks this against :data:`suspopt.specs.METRICS`.
SAME_UNIT_METRICS = frozenset(
    {
        "max",
        "max_abs",
        "mean",
        "min",
        "mtvv",
        "peak",
        "peak_to_peak",
        "rms",
        "rms_weighted",
        "std",
        "steady_state",
    }
)


def number(value: float) -> str:
    """A number as a message shows it: whole numbers below 1e7 in full, others by ``:.6g``
    (YAML's ``.inf`` and ``.nan`` for those)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        if abs(value) < 10**30:
            return str(value)
        return f"a whole number of {int(value.bit_length() * math.log10(2)) + 1} digits or so"
    if math.isnan(value):
        return ".nan"
    if math.isinf(value):
        return ".inf" if value > 0 else "-.inf"
    if value == int(value) and abs(value) < 1e7:
        return str(int(value))
    return f"{value:.6g}"


@dataclass(frozen=True)
class Slip:
    """A unit a value may have been written in: ``word`` in a hint, ``symbol`` after a
    number, ``factor`` the SI value of one of it."""

    word: str
    symbol: str
    factor: float


TONNES = Slip("tonnes", "t", 1e3)
GRAMS = Slip("grams", "g", 1e-3)
MM = Slip("mm", "mm", 1e-3)
KMH = Slip("km/h", "km/h", 1 / 3.6)


@dataclass(frozen=True)
class Plausible:
    """One quantity of the table (module docstring): its key paths (``*`` any one key or
    index), what it is, its SI unit, the plausible range of its magnitude ``[low, high]``,
    the slips that may explain a value outside it, the limits beyond which it is an error,
    and ``when``: for an entry that holds only in some sections, whether it holds in the
    mapping that has the key."""

    paths: tuple[tuple, ...]
    what: str
    unit: str
    low: float
    high: float
    slips: tuple[Slip, ...] = ()
    error_below: float | None = None
    error_above: float | None = None
    when: Callable[[dict], bool] | None = None
    signed: bool = False

    def hint(self, value: float) -> str | None:
        """``looks like tonnes (1.2 t = 1200 kg)?`` for the first slip that takes ``value``
        into the plausible range, or None."""
        if not (self.signed or value > 0) or self.low <= abs(value) <= self.high:
            return None
        for slip in self.slips:
            si = value * slip.factor
            if self.low <= abs(si) <= self.high:
                return (
                    f"looks like {slip.word} ({number(value)} {slip.symbol} = "
                    f"{number(si)} {self.unit})?"
                )
        return None

    def judge(self, value: float) -> tuple[str, str] | None:
        """``(severity, message)`` of a value outside the plausible range (module
        docstring), or None."""
        size = abs(value)
        if self.low <= size <= self.high or not (self.signed or value > 0):
            return None
        below = size < self.low
        hint = self.hint(value)
        limit = self.error_below if below else self.error_above
        said = f"{number(value)} {self.unit}"
        if limit is not None and (size < limit if below else size > limit):
            message = (
                f"{said} is {'less' if below else 'more'} than any road vehicle's {self.what} "
                f"(at {'least' if below else 'most'} {number(limit)} {self.unit})"
            )
            return "error", message + (f"; {hint}" if hint else "")
        if hint is None:
            return None
        either = " either way" if self.signed else ""
        return "warning", (
            f"{said} is {'less' if below else 'more'}{' in size' if self.signed else ''} than "
            f"a road vehicle's {self.what} ({number(self.low)} to {number(self.high)} "
            f"{self.unit}{either}); {hint}"
        )


def _is_travel_limit(constraint: dict) -> bool:
    """Whether a constraint's mapping limits a suspension travel in metres."""
    signal, metric = constraint.get("signal"), constraint.get("metric")
    return (
        isinstance(signal, str)
        and isinstance(metric, str)
        and metric in SAME_UNIT_METRICS
        and (signal == "travel" or signal.startswith("travel.") or signal == "seat.travel")
    )


_SEAT_LENGTHS = ("wall_distance", "spring_free_length", "bar_length", "cam_radius", "roller_radius")

#: The table (module docstring).
PLAUSIBLE: tuple[Plausible, ...] = (
    Plausible((("vehicle", "body", "mass"),), "body mass", "kg", 50.0, 7e5, (TONNES, GRAMS), 5.0),
    Plausible(
        (
            ("vehicle", "corners", "*", "unsprung_mass"),
            ("vehicle", "corner_defaults", "unsprung_mass"),
        ),
        "unsprung mass",
        "kg",
        5.0,
        3e3,
        (TONNES, GRAMS),
        0.5,
    ),
    Plausible(
        (("vehicle", "body", "a_front"), ("vehicle", "body", "a_rear")),
        "distance from the centre of gravity to an axle",
        "m",
        0.1,
        10.0,
        (MM,),
        error_above=25.0,
    ),
    Plausible(
        (("vehicle", "body", "b_right"), ("vehicle", "body", "b_left")),
        "distance from the centre of gravity to a wheel",
        "m",
        0.1,
        3.0,
        (MM,),
        error_above=10.0,
    ),
    Plausible(
        (("road", "height"),), "bump height", "m", 1e-3, 0.5, (MM,), error_above=2.0, signed=True
    ),
    Plausible((("road", "length"),), "bump length", "m", 0.05, 200.0, (MM,)),
    Plausible((("road", "speed"),), "speed", "m/s", 0.1, 70.0, (KMH,)),
    Plausible(
        (("constraints", "*", "max"), ("constraints", "*", "min")),
        "suspension travel limit",
        "m",
        0.0,
        0.5,
        (MM,),
        when=_is_travel_limit,
        signed=True,
    ),
    Plausible(
        tuple(("seat", key) for key in _SEAT_LENGTHS),
        "seat mechanism length",
        "m",
        5e-3,
        1.0,
        (MM,),
    ),
)


def _matches(pattern: tuple, loc: tuple) -> bool:
    return len(pattern) == len(loc) and all(p == "*" or p == k for p, k in zip(pattern, loc))


def entry_of(loc: tuple) -> Plausible | None:
    """The entry whose paths hold the key path ``loc`` (None if none does)."""
    for entry in PLAUSIBLE:
        if any(_matches(pattern, tuple(loc)) for pattern in entry.paths):
            return entry
    return None


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _at(data: Any, loc: tuple) -> Any:
    for key in loc:
        if (
            isinstance(data, dict)
            and key in data
            or isinstance(data, list)
            and isinstance(key, int)
            and 0 <= key < len(data)
        ):
            data = data[key]
        else:
            return None
    return data


def slip_hint(loc: tuple, value: Any, data: Any = None) -> str | None:
    """The unit-slip hint of ``value`` at the key path ``loc`` (of the config's ``data``,
    for an entry that holds only in some sections), or None."""
    entry = entry_of(loc)
    if entry is None or not _number(value):
        return None
    if entry.when is not None and not (data is not None and _holds(entry, data, loc)):
        return None
    return entry.hint(value)


def _holds(entry: Plausible, data: Any, loc: tuple) -> bool:
    parent = _at(data, loc[:-1])
    return entry.when is None or (isinstance(parent, dict) and entry.when(parent))


def _found(node: Any, pattern: tuple, prefix: tuple = ()) -> Iterator[tuple[tuple, Any]]:
    """``(key path, value)`` of every value of ``node`` at a path matching ``pattern``."""
    if not pattern:
        yield prefix, node
        return
    head, rest = pattern[0], pattern[1:]
    if isinstance(node, dict):
        keys = list(node) if head == "*" else [head] if head in node else []
        for key in keys:
            yield from _found(node[key], rest, prefix + (key,))
    elif isinstance(node, list) and head == "*":
        for i, item in enumerate(node):
            yield from _found(item, rest, prefix + (i,))


def _set_values(data: dict) -> Iterator[tuple[tuple, tuple, Any]]:
    """``(key path, config path, value)`` of the values a design variable's bounds and a
    scenario's ``set:`` give a config path."""
    variables = data.get("design_variables")
    for i, var in enumerate(variables if isinstance(variables, list) else []):
        if isinstance(var, dict) and isinstance(var.get("path"), str):
            path = tuple(var["path"].split("."))
            for bound in ("lower", "upper"):
                if bound in var:
                    yield ("design_variables", i, bound), path, var[bound]
    scenarios = data.get("scenarios")
    if not isinstance(scenarios, dict):
        return
    product = scenarios.get("product")
    lists = (
        [("cases",), *(("product", j) for j in range(len(product)))]
        if isinstance(product, list)
        else [("cases",)]
    )
    for where in lists:
        cases = _at(scenarios, where)
        for k, case in enumerate(cases if isinstance(cases, list) else []):
            changes = case.get("set") if isinstance(case, dict) else None
            for path, value in (changes or {}).items() if isinstance(changes, dict) else ():
                if isinstance(path, str):
                    loc = ("scenarios", *where, k, "set", path)
                    yield loc, tuple(path.split(".")), value


def check_plausible(
    data: Any, skip: set[tuple] | frozenset[tuple] = frozenset()
) -> list[tuple[tuple, str, str]]:
    """``[(key path, severity, message), ...]`` of the values of a config's ``data`` (as
    read from YAML) outside their plausible range (module docstring), leaving out the key
    paths in ``skip`` (those the schema refused already)."""
    out: list[tuple[tuple, str, str]] = []
    if not isinstance(data, dict):
        return out
    for entry in PLAUSIBLE:
        for pattern in entry.paths:
            for loc, value in _found(data, pattern):
                if loc in skip or not _number(value) or not _holds(entry, data, loc):
                    continue
                judged = entry.judge(value)
                if judged is not None:
                    out.append((loc, *judged))
    for loc, path, value in _set_values(data):
        found = entry_of(path)
        if loc in skip or found is None or found.when is not None or not _number(value):
            continue
        judged = found.judge(value)
        if judged is not None:
            out.append((loc, *judged))
    return out
