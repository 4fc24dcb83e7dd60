"""Markdown tables and number cells for the example scripts (examples/report.py,
examples/ch4_tables.py), and the thesis's printed values (examples/thesis_values.yaml).

Numbers are SI inside; :data:`UNITS` converts them to the unit a thesis table prints.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import yaml

from suspopt.analyse import relative_change

THESIS_VALUES = Path(__file__).resolve().with_name("thesis_values.yaml")

#: Factor from the SI value to the printed unit (the thesis's units and ours).
UNITS = {
    "m": 1.0,
    "mm": 1e3,
    "m^2": 1.0,
    "mm^2": 1e6,
    "m/s^2": 1.0,
    "(m/s^2)^2": 1.0,
    "s": 1.0,
    "Hz": 1.0,
    "rad": 1.0,
    "rad^2": 1.0,
    "10^-6 rad^2": 1e6,
    "N": 1.0,
    "N/m": 1.0,
    "N s/m": 1.0,
    "10^6 N/m^3": 1e-6,
    "N/m^3": 1.0,
    "%": 100.0,
    "#": 1.0,
    "1": 1.0,
    "W": 1.0,
    "rad/s": 1.0,
    "m/s^1.75": 1.0,
    "kg": 1.0,
}


def thesis_values() -> dict:
    """The thesis's printed numbers (examples/thesis_values.yaml)."""
    return yaml.safe_load(THESIS_VALUES.read_text())


def missing(value) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value))


def num(value, digits: int = 3) -> str:
    """A number with ``digits`` significant digits (no exponent for 1e-3 <= |x| < 1e6);
    '-' when missing."""
    if missing(value):
        return "-"
    value = float(value)
    if value == 0:
        return "0"
    if value.is_integer() and abs(value) < 1e6:
        return f"{value:.0f}"
    magnitude = math.floor(math.log10(abs(value)))
    if -3 <= magnitude < 6:
        decimals = max(digits - 1 - magnitude, 0)
        return f"{value:.{decimals}f}"
    return f"{value:.{digits - 1}e}"


def printed(value) -> str:
    """A thesis value as printed (the digits of thesis_values.yaml); '-' when missing."""
    return "-" if missing(value) else f"{value:g}"


def difference(ours, thesis) -> float:
    """(ours - thesis) / thesis * 100 [%] (suspopt.analyse.relative_change); NaN when either
    is missing or the thesis's is 0."""
    if missing(ours) or missing(thesis) or float(thesis) == 0:
        return math.nan
    return float(relative_change(float(ours), float(thesis)))


def pct(value, signed: bool = True) -> str:
    """A percentage cell: '+12.3 %'; '-' when missing."""
    if missing(value):
        return "-"
    return f"{value:+.1f} %" if signed else f"{value:.1f} %"


def table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A markdown table (cells already formatted); '|' inside cells is escaped."""

    def line(cells):
        return "| " + " | ".join(str(c).replace("|", "\\|") for c in cells) + " |"

    return "\n".join([line(header), "|" + "---|" * len(header)] + [line(r) for r in rows])
