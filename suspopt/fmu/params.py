"""The FMU's parameters: every numeric field of the model's config sections, and which of the
description's entries each one moves.

A parameter is the config field itself (``vehicle.corners.F1.spring.linear``), with its unit,
its description and the design's value as its start. Which entries of the description
(:mod:`suspopt.fmu.model`) follow it is not written down here but measured: the field is
changed a little in a copy of the config, the model built again by the simulator's own
builders, and each entry compared with the design's. An entry that moves as a power of the
field (``k`` with the spring rate, a mass with a mass, a law constant with a stiffness ratio,
a bump's heights with its height: ``e = e0 (p/p0)^d``, d = ±1 or ±2, or ``e = α p`` for a field
at 0) is bound to it, and the C runtime recomputes it when the parameter is set; the other
entries stay as built. A field that moves some entry any other way (a seat's geometry through
its static deflection, a road speed through the wheelbase delay), or changes the network's
structure (a cubic spring rate at 0 adds a Duffing law), cannot be tuned in the FMU: it is
exported as a constant with its value, said so in its description. All bindings are checked
together once more, every tunable field changed at once, before the FMU is written.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..config import Config, ConfigError
from .description import Description
from .model import describe

__all__ = ["Parameter", "Binding", "bind_parameters", "flat_entries"]

#: The config sections whose numeric fields are the model's parameters (the road only when it
#: is built into the FMU).
_SECTIONS = ("vehicle.", "seat.", "control.")
_SKIP = ("vehicle.corner_defaults.",)
#: Relative changes of a probe (two, so that no non-linear dependence passes by chance).
_STEPS = (1e-3, -2e-3)
#: Absolute changes of a field at 0.
_ZERO_STEPS = (1e-3, 2e-3)
_TOLERANCE = 1e-10


@dataclass
class Parameter:
    """One numeric config field: its dotted ``path``, the design's ``value``, ``unit``,
    ``description``, whether the FMU can tune it (``tunable``; else why not: ``reason``)."""

    path: str
    value: float
    unit: str
    description: str
    tunable: bool = True
    reason: str = ""


@dataclass
class Binding:
    """The entries (flat indices ``index``) a parameter moves and how: ``degree`` per entry
    (``e = e0 (p/p0)^d``), or for a parameter at 0 ``alpha`` (``e = α p``)."""

    index: np.ndarray
    degree: np.ndarray
    alpha: np.ndarray | None = None


@dataclass
class Bound:
    """The parameters and their bindings (by parameter index)."""

    parameters: list[Parameter]
    bindings: dict[int, Binding] = field(default_factory=dict)


def flat_entries(d: Description) -> tuple[np.ndarray, dict[str, tuple[int, int]]]:
    """Every entry of ``d`` in one array, and where each named entry starts and its size."""
    offsets, at = {}, 0
    for name, values in d.entries.items():
        offsets[name] = (at, values.size)
        at += values.size
    flat = np.concatenate(list(d.entries.values())) if d.entries else np.zeros(0)
    return flat, offsets


def _int_paths(node, prefix: str, out: set[str]) -> None:
    if isinstance(node, dict):
        for key, value in node.items():
            _int_paths(value, f"{prefix}.{key}" if prefix else str(key), out)
    elif isinstance(node, int) and not isinstance(node, bool):
        out.add(prefix)


def _field(cfg: Config, path: str):
    """The config section holding ``path`` and the field's name."""
    node = cfg
    parts = path.split(".")
    for part in parts[:-1]:
        node = node[part] if isinstance(node, dict) else getattr(node, part)
    return node, parts[-1]


def _description(cfg: Config, path: str) -> str:
    node, name = _field(cfg, path)
    info = getattr(type(node), "model_fields", {}).get(name)
    return " ".join((info.description or "").split()) if info is not None else ""


def model_parameters(cfg: Config, road: str) -> list[Parameter]:
    """The model's numeric config fields (module docstring), a design variable's described
    as one: integers (a seed, a count of waves) are settings, not parameters, and are left
    out."""
    from ..params import field_unit, numeric_paths

    ints: set[str] = set()
    _int_paths(cfg.model_dump(), "", ints)
    sections = _SECTIONS + (("road.",) if road == "embedded" else ())
    labels = {v.path: v.label for v in cfg.design_variables}
    found = []
    for path, value in numeric_paths(cfg).items():
        if not path.startswith(sections) or path.startswith(_SKIP) or path in ints:
            continue
        text = _description(cfg, path)
        if path in labels:
            text = f"design variable {labels[path]}: {text}"
        found.append(Parameter(path, value, field_unit(cfg, path), text))
    return found


def _changed(cfg: Config, changes: dict[str, float]) -> Config | None:
    """A copy of ``cfg`` with ``changes`` made (None when a field refuses a value)."""
    copy = cfg.model_copy(deep=True)
    try:
        for path, value in changes.items():
            node, name = _field(copy, path)
            if isinstance(node, dict):
                node[name] = value
            else:
                setattr(node, name, float(value))
            parts = path.split(".")
            for depth in range(len(parts) - 1, 0, -1):  # the sections' own checks, up to the root
                parent, key = _field(copy, ".".join(parts[:depth]))
                if not isinstance(parent, dict):
                    setattr(parent, key, getattr(parent, key))
    except (ValueError, TypeError, KeyError, AttributeError):
        return None
    return copy


def _probe(cfg: Config, road: str, changes: dict[str, float], d0: Description):
    """The flat entries of the model with ``changes``, or None when it cannot be built or
    its structure differs from ``d0``'s."""
    changed = _changed(cfg, changes)
    if changed is None:
        return None
    try:
        with np.errstate(all="ignore"):
            d = describe(changed, road)
    except (ConfigError, ValueError, ZeroDivisionError, np.linalg.LinAlgError):
        return None
    return flat_entries(d)[0] if d.same_structure(d0) else None


def _degrees(e0: np.ndarray, probes: list[np.ndarray], steps, zero: bool):
    """The moved entries and their degrees, or a reason the dependence is not a power."""
    same = [(p == e0) | (np.isnan(p) & np.isnan(e0)) for p in probes]  # (NaN: no limit)
    moved = np.flatnonzero(~np.all(same, axis=0))
    if not moved.size:
        return moved, np.zeros(0, int), None
    if zero:
        a, b = probes[0][moved], probes[1][moved]
        ok = (e0[moved] == 0) & np.isclose(b, 2 * a, rtol=_TOLERANCE, atol=0)
        return moved, np.ones(moved.size, int), (None if ok.all() else "not proportional")
    if np.any(e0[moved] == 0):
        return moved, np.zeros(0, int), "moves an entry from 0"
    ratio = probes[0][moved] / e0[moved]
    with np.errstate(all="ignore"):
        degree = np.rint(np.log(np.abs(ratio)) / math.log1p(steps[0])).astype(int)
    ok = np.isin(degree, (-2, -1, 1, 2))
    for probe, step in zip(probes, steps):
        expected = (1.0 + step) ** degree.astype(float)
        ok &= np.isclose(probe[moved] / e0[moved], expected, rtol=_TOLERANCE, atol=0)
    return moved, degree, (None if ok.all() else "not a power of it")


def _classify(cfg: Config, road: str, d0: Description, e0, p: Parameter):
    """The binding of ``p`` (None: not tunable, with ``p.reason`` set)."""
    zero = p.value == 0.0
    steps = _ZERO_STEPS if zero else _STEPS
    values = [s if zero else p.value * (1.0 + s) for s in steps]
    probes = [_probe(cfg, road, {p.path: v}, d0) for v in values]
    if any(pr is None for pr in probes):
        p.tunable, p.reason = False, "changing it changes the model's structure"
        return None
    moved, degree, why = _degrees(e0, probes, steps, zero)
    if why is not None:
        p.tunable, p.reason = (
            False,
            f"the model depends on it in a way the FMU cannot recompute ({why})",
        )
        return None
    alpha = probes[0][moved] / values[0] if zero else None
    return Binding(moved, degree, alpha)


def bind_parameters(cfg: Config, road: str, d0: Description) -> Bound:
    """The parameters of ``cfg``'s model and their bindings (module docstring)."""
    e0 = flat_entries(d0)[0]
    bound = Bound(model_parameters(cfg, road))
    for i, p in enumerate(bound.parameters):
        binding = _classify(cfg, road, d0, e0, p)
        if binding is not None and binding.index.size:
            bound.bindings[i] = binding
    _one_zero_each(bound)
    for _ in range(4):
        if _verified(cfg, road, d0, e0, bound):
            return bound
    raise ConfigError("the FMU's parameters could not be checked against the model")


def _one_zero_each(bound: Bound) -> None:
    """An entry may follow at most one parameter that is 0 (its α is measured alone)."""
    owners: dict[int, list[int]] = {}
    for i, b in bound.bindings.items():
        if b.alpha is not None:
            for e in b.index:
                owners.setdefault(int(e), []).append(i)
    for who in owners.values():
        if len(who) > 1:
            for i in who:
                _demote(bound, i, "it multiplies another parameter that is 0")


def _demote(bound: Bound, i: int, reason: str) -> None:
    p = bound.parameters[i]
    p.tunable, p.reason = False, reason
    bound.bindings.pop(i, None)


def predicted(e0: np.ndarray, bound: Bound, values: dict[int, float]) -> np.ndarray:
    """The entries the runtime computes with the parameters ``values`` (by index; the others
    at the design's): the numpy twin of the runtime's ``su_entries``."""
    e = e0.copy()
    zero_alpha = {}
    for i, b in bound.bindings.items():
        p0 = bound.parameters[i].value
        p = values.get(i, p0)
        if b.alpha is not None:
            for k, a in zip(b.index, b.alpha):
                zero_alpha[int(k)] = a * p
            continue
        e[b.index] *= (p / p0) ** b.degree.astype(float)
    for k, v in zero_alpha.items():  # (e0 is 0 there: the factors of the others follow)
        factor = 1.0
        for i, b in bound.bindings.items():
            if b.alpha is None and k in set(b.index.tolist()):
                j = int(np.flatnonzero(b.index == k)[0])
                p0 = bound.parameters[i].value
                factor *= (values.get(i, p0) / p0) ** float(b.degree[j])
        e[k] = v * factor
    return e


def _verified(cfg: Config, road: str, d0: Description, e0, bound: Bound) -> bool:
    """Every tunable parameter changed at once: the runtime's entries against the model's;
    the parameters of an entry that disagrees are demoted (False: check again)."""
    tunable = [i for i, p in enumerate(bound.parameters) if p.tunable]
    if not tunable:
        return True
    values = {}
    for n, i in enumerate(tunable):
        p = bound.parameters[i]
        step = 1e-3 * (1 + n % 7)
        values[i] = step if p.value == 0.0 else p.value * (1.0 + step)
    actual = _probe(cfg, road, {bound.parameters[i].path: v for i, v in values.items()}, d0)
    if actual is None:
        for i in tunable:
            _demote(bound, i, "changing it with the others changes the model's structure")
        return False
    wrong = ~np.isclose(predicted(e0, bound, values), actual, rtol=1e-9, atol=0, equal_nan=True)
    if not wrong.any():
        return True
    for i in list(bound.bindings):
        if np.isin(bound.bindings[i].index, np.flatnonzero(wrong)).any():
            _demote(bound, i, "the model depends on it together with others")
    return False
