"""``suspopt analyse tolerances PARETO.h5 [--tolerance 10] [--tolerance NAME=T]``: a front's
designs as built.

A design leaves the drawing office as numbers and the factory as parts: a spring within its
rate tolerance, a damper within its force band. This analysis shows what that does to the
objectives: each design variable in turn is off by ``-t`` and ``+t`` % of every design's own
value (one at a time, the others as designed), and the whole front is evaluated again under
each of those ``2 n`` changes, one batch each: pseudo-fronts (:mod:`.pseudo`), with the same
HDF5 layout, table and figure as ``analyse roads``, and a last note of the largest change
of each objective and where it came from. The thesis has no such analysis; it is
ours, in the form of its pseudo-fronts (Sec 8.4).

A value the change would take outside what its config field accepts (a ratio above 1) is
held at the field's limit, and the report says for how many designs. A tolerance is in % of
the value, for a variable on a log scale too; an integer variable is rounded as the
optimiser rounds it. Each variable has its own (:func:`variable_tolerances`): the
``--tolerance NAME=T`` given for it, else the bare ``--tolerance T``, else its config's
``design_variables[i].tolerance`` (springs and dampers are made to different bands), else
10 %. Each variant's ``/pseudo/<label>`` has the attributes ``variable``,
``tolerance`` [%] (signed) and ``held_at_limit`` (how many designs), and the dataset ``X``
(the changed designs).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from ..choosing.selection import ParetoSet
from ..design_ids import front_ids
from ..errors import ConfigError
from ..files import listed
from ..params import field_range
from .cells import NOT_COMPUTED, percent
from .pseudo import PseudoFronts, Variant, run_variants
from .registry import KINDS, Analysis, Kind, Report

__all__ = [
    "TOLERANCE",
    "checked_tolerance",
    "variable_tolerances",
    "known_variable",
    "bands",
    "inside",
    "variable_limits",
    "tolerance_variants",
    "run_tolerances",
]

#: The default tolerance [%]: a spring's or a damper's usual rate band.
TOLERANCE = 10.0
#: What ``--tolerance`` takes (:func:`variable_tolerances`).
Tolerances = float | str | Sequence[float | str] | Mapping[str, float] | None


def inside(values: np.ndarray, limits: tuple[float, bool, float, bool]) -> np.ndarray:
    """``values`` held within a field's range ``(low, low_closed, high, high_closed)`` (an
    open end: the nearest float inside it)."""
    low, low_closed, high, high_closed = limits
    low = low if low_closed else np.nextafter(low, np.inf)
    high = high if high_closed else np.nextafter(high, -np.inf)
    return np.clip(values, low, high)


def checked_tolerance(tolerance: float | str | None, label: str = "--tolerance ") -> float:
    """One tolerance [%] as a number above 0 and below 100 (None: :data:`TOLERANCE`);
    ConfigError naming the option (``label``, followed by the value) for anything else."""
    value = TOLERANCE if tolerance is None else tolerance
    try:
        if isinstance(value, bool):
            raise TypeError
        t = float(value)
    except (TypeError, ValueError):
        raise ConfigError(f"{label}{value!r}: give a number of %") from None
    if not (0.0 < t < 100.0 and math.isfinite(t)):
        raise ConfigError(f"{label}{t:g}: give a tolerance above 0 and below 100 %")
    return t


def variable_tolerances(pareto: ParetoSet, tolerance: Tolerances = None) -> np.ndarray:
    """``(n,)`` the tolerance [%] of each design variable of ``pareto``: the ``NAME=T`` given
    for it (``--tolerance``, repeatable), else the one bare ``T`` given (the command line
    over the config), else its stored config's ``design_variables[i].tolerance``, else
    :data:`TOLERANCE`. ``tolerance``: None, a number, ``"T"``, ``"NAME=T"``, a sequence of
    those, or a mapping name -> T; ConfigError naming the option for a wrong one."""
    if isinstance(tolerance, Mapping):
        items: list[tuple[str | None, Any]] = list(tolerance.items())
    else:
        items = [(None, v) for v in listed(tolerance)] if tolerance is not None else []
    default, each = None, {}
    for name, value in items:
        if name is None and isinstance(value, str) and "=" in value:
            name, _, value = (part.strip() for part in value.partition("="))
        if name is None:
            if default is not None:
                raise ConfigError(
                    "--tolerance: give one tolerance T for every variable, and NAME=T for "
                    "those with another; not two of T"
                )
            default = checked_tolerance(value)
            continue
        known_variable(pareto, name, f"--tolerance {name}={value}")
        if name in each:
            raise ConfigError(f"--tolerance {name}=: give each variable's tolerance once")
        each[name] = checked_tolerance(value, f"--tolerance {name}=")
    stored = {v.label: v.tolerance for v in pareto.config().design_variables}
    return np.array(
        [
            each.get(name, default or stored.get(name) or TOLERANCE)  # (each one is above 0)
            for name in pareto.var_names
        ],
        dtype=float,
    )


def known_variable(pareto: ParetoSet, name: str, where: str) -> int:
    """The column of the design variable ``name`` in ``pareto.X``; ConfigError starting with
    ``where`` (the option that names it) when the file has no such variable."""
    if name not in pareto.var_names:
        raise ConfigError(
            f"{where}: {pareto.path.name} has no design variable {name!r}; it has "
            f"{', '.join(pareto.var_names)}"
        )
    return pareto.var_names.index(name)


def bands(names: Sequence[str], tolerance: np.ndarray) -> str:
    """The tolerances [%] of the variables ``names`` as a report says them: ``±10 %`` when
    they are one, else each (``K_v ±5 %, C_v ±15 %``)."""
    if len(set(tolerance.tolist())) == 1:
        return f"±{tolerance[0]:g} %"
    return ", ".join(f"{name} ±{t:g} %" for name, t in zip(names, tolerance))


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


def tolerance_variants(pareto: ParetoSet, tolerance: Tolerances = None) -> list[Variant]:
    """Two variants per design variable: its value in every design times ``1 - t/100`` and
    ``1 + t/100`` (``t`` its tolerance [%]: :func:`variable_tolerances`), the stored
    config."""
    cfg = pareto.config()
    variants = []
    tolerances = variable_tolerances(pareto, tolerance)
    for j, (name, limits) in enumerate(zip(pareto.var_names, variable_limits(pareto))):
        t = float(tolerances[j])
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
        if not np.isfinite(changes).any():  # (NaN where it cannot be computed)
            continue
        i, row = np.unravel_index(np.nanargmax(np.abs(changes)), changes.shape)
        parts.append(
            f"{name} {percent(changes[i, row], '.3g')} ({fronts.variants[i].label}, design "
            f"{front_ids(fronts.pareto)[row]})"
        )
    return "largest change of each objective: " + ("; ".join(parts) or NOT_COMPUTED)


def _held_notes(variants: Sequence[Variant]) -> list[str]:
    """What the report says of the values held at their field's limit."""
    return [
        f"{v.label}: {v.attrs['held_at_limit']} design(s) held at the field's limit"
        for v in variants
        if v.attrs["held_at_limit"]
    ]


def run_tolerances(
    source: Path, tolerance: Tolerances = None, pick: Sequence[str] | None = None
) -> Analysis:
    """``suspopt analyse tolerances PARETO.h5 [--tolerance 10] [--tolerance NAME=T] [--pick
    NAMES]`` (module docstring); nothing written."""
    variants = partial(tolerance_variants, tolerance=tolerance)
    done = run_variants(
        "tolerances",
        Path(source),
        variants,
        "with each design variable off by its tolerance in turn",
        pick,
    )
    fronts, table = done.data, done.tabulate

    def tabulate() -> Report:
        report = table()
        report.notes += [_largest_changes(fronts), *_held_notes(fronts.variants)]
        return report

    done.tabulate = tabulate
    return done


KINDS["tolerances"] = Kind(run_tolerances, options=("tolerance", "pick"))
