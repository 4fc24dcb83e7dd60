"""``suspopt analyse tolerances PARETO.h5 [--tolerance 10]``: a front's designs as built.

A design leaves the drawing office as numbers and the factory as parts: a spring within its
rate tolerance, a damper within its force band. This analysis shows what that does to the
objectives: each design variable in turn is off by ``-t`` and ``+t`` % of every design's own
value (one at a time, the others as designed), and the whole front is evaluated again under
each of those ``2 n`` changes, one batch each: pseudo-fronts (:mod:`.pseudo`), with the same
HDF5 layout, table and figure as ``analyse roads``, and a last note of the largest change
of each objective and where it came from. The thesis has no such analysis; it is
ours, in the form of its pseudo-fronts (Sec 8.4).

A value the change would take outside what its config field accepts (a ratio above 1) is
held at the field's limit, and the report says for how many designs. ``--tolerance`` is in %
of the value, for a variable on a log scale too; an integer variable is rounded as the
optimiser rounds it. Each variant's ``/pseudo/<label>`` has the attributes ``variable``,
``tolerance`` [%] (signed) and ``held_at_limit`` (how many designs), and the dataset ``X``
(the changed designs).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import partial
from pathlib import Path

import numpy as np

from ..config import ConfigError
from ..files import listed
from ..params import field_range
from ..selection import ParetoSet
from . import KINDS, Kind, Report
from .pseudo import PseudoFronts, Variant, run_variants

__all__ = [
    "TOLERANCE",
    "checked_tolerance",
    "inside",
    "variable_limits",
    "tolerance_variants",
    "run_tolerances",
]

#: The default tolerance [%]: a spring's or a damper's usual rate band.
TOLERANCE = 10.0


def inside(values: np.ndarray, limits: tuple[float, bool, float, bool]) -> np.ndarray:
    """``values`` held within a field's range ``(low, low_closed, high, high_closed)`` (an
    open end: the nearest float inside it)."""
    low, low_closed, high, high_closed = limits
    low = low if low_closed else np.nextafter(low, np.inf)
    high = high if high_closed else np.nextafter(high, -np.inf)
    return np.clip(values, low, high)


def checked_tolerance(tolerance: float | None) -> float:
    """``--tolerance`` [%] as a number above 0 and below 100 (None: :data:`TOLERANCE`);
    ConfigError naming the option for anything else."""
    values = listed(TOLERANCE if tolerance is None else tolerance)
    if len(values) != 1:
        raise ConfigError(f"--tolerance: give one tolerance in %, got {len(values)}")
    try:
        if isinstance(values[0], bool):
            raise TypeError
        t = float(values[0])
    except (TypeError, ValueError):
        raise ConfigError(f"--tolerance {values[0]!r}: give a number of %") from None
    if not (0.0 < t < 100.0 and math.isfinite(t)):
        raise ConfigError(f"--tolerance {t:g}: give a tolerance above 0 and below 100 %")
    return t


def variable_limits(pareto: ParetoSet) -> list[tuple[float, bool, float, bool]]:
    """The range each column of ``pareto.X`` may take: its config field's
    (:func:`suspopt.params.field_range`); ConfigError where the stored config does not vary
    a column."""
    cfg = pareto.config()
    path_of = {v.label: v.path for v in cfg.design_variables}
    missing = [name for name in pareto.var_names if name not in path_of]
    if missing:
        raise ConfigError(
            f"{pareto.path}: /pareto/X holds {', '.join(missing)}, which the stored config's "
            f"design_variables do not have"
        )
    return [field_range(cfg, path_of[name]) for name in pareto.var_names]


def tolerance_variants(pareto: ParetoSet, tolerance: float | None = TOLERANCE) -> list[Variant]:
    """Two variants per design variable: its value in every design times ``1 - t/100`` and
    ``1 + t/100`` (``t`` = ``tolerance`` [%], above 0 and below 100; None: :data:`TOLERANCE`),
    the stored config."""
    t = checked_tolerance(tolerance)
    cfg = pareto.config()
    variants = []
    for j, (name, limits) in enumerate(zip(pareto.var_names, variable_limits(pareto))):
        for sign in (-1.0, 1.0):
            X = pareto.X.copy()
            X[:, j] = inside(X[:, j] * (1.0 + sign * t / 100.0), limits)
            held = int(np.sum(X[:, j] != pareto.X[:, j] * (1.0 + sign * t / 100.0)))
            variants.append(
                Variant(
                    f"{name} {sign * t:+g} %",
                    cfg,
                    X,
                    attrs={"variable": name, "tolerance": sign * t, "held_at_limit": held},
                )
            )
    return variants


def _largest_changes(fronts: PseudoFronts) -> str:
    """Each objective's largest change over every variant and design (its sign kept), and
    where: the design variable most to watch for it."""
    parts = []
    for j, name in enumerate(fronts.stored.names):
        changes = np.array([fronts.change(i)[:, j] for i in range(len(fronts.variants))])
        if not np.isfinite(changes).any():
            continue
        i, row = np.unravel_index(np.nanargmax(np.abs(changes)), changes.shape)
        parts.append(f"{name} {changes[i, row]:+.3g} % ({fronts.variants[i].label}, design {row})")
    return "largest change of each objective: " + "; ".join(parts)


def _held_notes(variants: Sequence[Variant]) -> list[str]:
    """What the report says of the values held at their field's limit."""
    return [
        f"{v.label}: {v.attrs['held_at_limit']} design(s) held at the field's limit"
        for v in variants
        if v.attrs["held_at_limit"]
    ]


def run_tolerances(
    source: Path,
    output: Path | None = None,
    plot: Path | None = None,
    tolerance: float | None = TOLERANCE,
    pick: Sequence[str] | None = None,
) -> Report:
    """``suspopt analyse tolerances PARETO.h5 [--tolerance 10] [--pick NAMES]`` (module
    docstring)."""
    variants = partial(tolerance_variants, tolerance=tolerance)
    report, fronts = run_variants(
        "tolerances",
        Path(source),
        output,
        plot,
        variants,
        "with each design variable off by its tolerance in turn",
        pick,
    )
    report.notes += [_largest_changes(fronts), *_held_notes(fronts.variants)]
    return report


KINDS["tolerances"] = Kind(run_tolerances, options=("tolerance", "pick"))
