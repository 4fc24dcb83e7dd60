"""Robust design: the scenarios of a config resolved into batches, and the aggregates.

:meth:`ScenarioSet.from_config` expands the ``scenarios:`` section
(:mod:`suspopt.config.scenarios`) and sorts each scenario's changes into two kinds:

- numbers the simulator reads per design (any numeric field outside ``road``,
  ``simulation`` and ``vehicle.gravity``: masses, stiffnesses, ``c_max``, the passenger) and
  ``load_mass`` (the seat's mass-change rule of Sec 8.4.3,
  :func:`suspopt.seat.passenger_mass_change`) become extra design columns: P designs under
  the S_g scenarios of a group are ONE batch of P x S_g columns, scenario after scenario
  (:meth:`ScenarioSet.columns`);
- a road of its own (another class, speed, seed, profile or bump height) drives its
  scenario's columns of the same batch (the integrators take a road per block of columns,
  :func:`suspopt.streaming.reduce`);
- a change of the ``simulation`` or ``control`` section (duration, time step, the
  controller's sample time) or ``vehicle.gravity``, of a bump's instants (its start, length,
  speed), or of any road under ``simulation.method: spectral`` makes a :class:`Group` of its
  own: a batch shares one time grid, the instants where a bump's edges split its steps, and
  the spectral method integrates one road's spectrum per batch.

An evaluation therefore makes one simulation call per group (for configs/robust/ps.yaml and
nss4.yaml one per road class, each driven 1000 m at its own speed, so for its own duration;
for hc2_bumps.yaml one), never one per scenario.

:func:`aggregate` combines the values of every scenario, ``(P, S, k)``, into ``(P, k)``
by each column's ``over_scenarios`` (:data:`suspopt.config.scenarios.AGGREGATES`). A
constraint is combined on its margin ``g`` (``g <= 0`` holds), so its default ``max``
makes it hold in every scenario.
"""

from __future__ import annotations

import difflib
import itertools
import json
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..config import Config, ConfigError
from ..config.loader import edit_config, set_path
from ..config.road import BumpHalfSine, BumpStep
from ..config.scenarios import Quantile
from ..params import field_range, numeric_paths

__all__ = ["Scenario", "Group", "ScenarioSet", "aggregate", "GROUP_SECTIONS"]

#: The config parts one batch shares: a scenario that changes them is simulated apart.
GROUP_SECTIONS = ("road", "simulation", "vehicle.gravity", "control")
#: Sections a scenario cannot change.
_FIXED = (
    "output",
    "optimiser",
    "execution",
    "scenarios",
    "design_variables",
    "objectives",
    "constraints",
    "metrics",
    "vehicle.corner_defaults",
)


@dataclass(frozen=True)
class Scenario:
    """One expanded scenario: ``sets`` maps dotted paths to values, ``locs`` each path to its
    key in the config (for messages)."""

    name: str
    weight: float
    sets: dict[str, Any]
    locs: dict[str, tuple]
    load_mass: float | None = None
    load_loc: tuple | None = None
    loc: tuple = ("scenarios",)


@dataclass
class Group:
    """Scenarios simulated as one batch: ``cfg`` is the first one's config (the nominal one
    when it changes no section), ``members`` their indices in :attr:`ScenarioSet.names`,
    ``values`` per member the per-design paths it sets [SI], ``scales`` the factors it applies
    to a design variable's own value (``seat.stiffness_ratio`` under ``load_mass``) and
    ``configs`` each member's whole config (they differ from ``cfg`` in their road at most)."""

    cfg: Config
    members: list[int] = field(default_factory=list)
    values: list[dict[str, float]] = field(default_factory=list)
    scales: list[dict[str, float]] = field(default_factory=list)
    configs: list[Config] = field(default_factory=list)

    @property
    def roads(self) -> list[Any] | None:
        """Each member's road, one per block of P columns, or None when they share
        ``cfg``'s."""
        roads = [c.road for c in self.configs]
        return None if all(r == self.cfg.road for r in roads) else roads

    @property
    def sim_cfg(self) -> Config:
        """The group's config without ``metrics:`` (what the evaluation simulates)."""
        return self.cfg.model_copy(update={"metrics": []})


def _one(case, loc: tuple) -> Scenario:
    return Scenario(
        case.name,
        float(case.weight),
        dict(case.set),
        {path: loc + ("set", path) for path in case.set},
        case.load_mass,
        loc + ("load_mass",) if case.load_mass is not None else None,
        loc,
    )


def _combined(cfg: Config, parts: list[Scenario]) -> Scenario:
    """The scenario of one combination of ``product``: names joined, sets merged (a path set
    by two factors is an error), weights multiplied."""
    sets: dict[str, Any] = {}
    locs: dict[str, tuple] = {}
    load, load_loc = None, None
    for part in parts:
        for path, value in part.sets.items():
            if path in sets:
                raise cfg.error(part.locs[path], f"{path} is set by another product list too")
            sets[path], locs[path] = value, part.locs[path]
        if part.load_mass is not None:
            if load is not None:
                raise cfg.error(part.load_loc or part.loc, "load_mass is given by two lists")
            load, load_loc = part.load_mass, part.load_loc
    weight = float(np.prod([p.weight for p in parts]))
    return Scenario(
        "/".join(p.name for p in parts), weight, sets, locs, load, load_loc, parts[0].loc
    )


def expand(cfg: Config) -> list[Scenario]:
    """The scenarios of ``cfg.scenarios`` in order: nominal, the cases, the product."""
    section = cfg.scenarios
    assert section is not None
    out = (
        [Scenario("nominal", 1.0, {}, {}, loc=("scenarios", "nominal"))] if section.nominal else []
    )
    out += [_one(c, ("scenarios", "cases", i)) for i, c in enumerate(section.cases)]
    factors = [
        [_one(c, ("scenarios", "product", i, j)) for j, c in enumerate(factor)]
        for i, factor in enumerate(section.product)
    ]
    if factors:
        out += [_combined(cfg, list(combo)) for combo in itertools.product(*factors)]
    seen: dict[str, Scenario] = {}
    for scenario in out:
        if scenario.name in seen:
            raise cfg.error(scenario.loc, f"two scenarios are named {scenario.name!r}")
        seen[scenario.name] = scenario
    return out


def _in(path: str, prefixes) -> str | None:
    for prefix in prefixes:
        if path == prefix or path.startswith(prefix + "."):
            return prefix
    return None


def _per_design(cfg: Config, scenario: Scenario, designed: set[str]) -> dict[str, float]:
    """The numeric per-design changes of ``scenario``, checked against ``cfg``."""
    numeric = numeric_paths(cfg)
    values: dict[str, float] = {}
    for path, value in scenario.sets.items():
        loc = scenario.locs[path]
        fixed = _in(path, _FIXED)
        if fixed is not None:
            raise cfg.error(loc, f"a scenario cannot change {fixed}")
        if _in(path, GROUP_SECTIONS) is not None:
            continue
        if path not in numeric:
            close = difflib.get_close_matches(path, list(numeric), n=3)
            raise cfg.error(
                loc,
                f"{path} is not a numeric field of this config"
                + (f"; did you mean {', '.join(close)}?" if close else "")
                + " (outside road and simulation a scenario changes numbers only)",
            )
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise cfg.error(loc, f"{path} takes a number, got {value!r}")
        if path in designed:
            raise cfg.error(loc, f"{path} is a design variable; a scenario cannot fix it")
        low, low_closed, high, high_closed = field_range(cfg, path)
        if not (
            low < value < high or (value == low and low_closed) or (value == high and high_closed)
        ):
            raise cfg.error(loc, f"{path} must be in [{low:g}, {high:g}], got {value:g}")
        values[path] = float(value)
    return values


def _load_changes(
    cfg: Config, scenario: Scenario, designed: set[str], values: dict
) -> tuple[dict, dict]:
    """``values`` with the passenger of ``load_mass`` seated (Sec 8.4.3), and the factors on
    design variables that the rule scales; ``({path: value}, {path: factor})``."""
    from ..seat import passenger_mass_change

    loc = scenario.load_loc or scenario.loc
    if cfg.seat is None:
        raise cfg.error(loc, "load_mass needs a seat: section")
    for path in designed:
        if path == "seat.mass" or path.startswith("seat.passenger."):
            raise cfg.error(
                loc, f"load_mass changes the passenger, and {path} is a design variable"
            )
    lowest = cfg.seat.mass if cfg.seat.passenger is not None else 0.0
    new = float(scenario.load_mass)  # type: ignore[arg-type]
    if not new > lowest:
        raise cfg.error(loc, f"the load must be above the seat's own {lowest:g} kg, got {new:g} kg")
    changed = {path: float(v[0]) for path, v in passenger_mass_change(cfg, new).items()}
    nominal, scales = numeric_paths(cfg), {}
    for path in list(changed):
        if path in values:
            raise cfg.error(scenario.locs[path], f"{path} is set by load_mass too")
        if path in designed:  # seat.stiffness_ratio: each design's own takes the rule's factor
            scales[path] = changed.pop(path) / nominal[path]
    return {**values, **changed}, scales


def _group_config(cfg: Config, scenario: Scenario) -> tuple[str, Config]:
    """The key of the batch ``scenario`` can join and its config: the time grid, controller
    and gravity, and the road where it cannot have a road of its own (module docstring)."""
    shared = {p: v for p, v in scenario.sets.items() if _in(p, GROUP_SECTIONS) is not None}
    edited = _edited(cfg, scenario, shared) if shared else cfg
    parts: list[Any] = [edited.simulation, edited.control, edited.vehicle.gravity]
    if cfg.simulation.method == "spectral":  # a batch of the spectral method has one road
        parts.append(edited.road)
    elif isinstance(edited.road, (BumpStep, BumpHalfSine)):  # bumps of one batch share edges
        parts.append(edited.road.model_dump(mode="json", exclude={"height"}))
    key = json.dumps(
        [p.model_dump(mode="json") if hasattr(p, "model_dump") else p for p in parts],
        sort_keys=True,
    )
    return key, edited


def _edited(cfg: Config, scenario: Scenario, shared: dict) -> Config:
    """``cfg`` with the scenario's ``shared`` (road, simulation, ...) values written in."""

    def put(data: dict) -> None:
        for path, value in shared.items():
            set_path(data, path, value)

    try:
        return edit_config(cfg.text, put, cfg.source, f"scenario {scenario.name}")
    except ConfigError as exc:
        message = str(exc).split(": ", 1)[-1]
        raise cfg.error(scenario.locs[next(iter(shared))], message) from None


class ScenarioSet:
    """The scenarios of a config (module docstring): ``names``, ``weights (S,)`` and the
    :class:`Group` s that are simulated as one batch each."""

    def __init__(self, scenarios: list[Scenario], groups: list[Group]):
        self.scenarios = scenarios
        self.names = [s.name for s in scenarios]
        self.weights = np.array([s.weight for s in scenarios])
        self.groups = groups

    @classmethod
    def from_config(cls, cfg: Config) -> ScenarioSet | None:
        """The scenarios of ``cfg`` (None without a ``scenarios:`` section); ConfigError at
        the scenario's key for a path that does not exist or cannot vary, a value out of
        its field's range, or a road or simulation the config rejects."""
        if cfg.scenarios is None:
            return None
        scenarios = expand(cfg)
        designed = {v.path for v in cfg.design_variables}
        groups: dict[str, Group] = {}
        for i, scenario in enumerate(scenarios):
            key, group_cfg = _group_config(cfg, scenario)
            values = _per_design(cfg, scenario, designed)
            scales: dict[str, float] = {}
            if scenario.load_mass is not None:
                values, scales = _load_changes(cfg, scenario, designed, values)
            group = groups.setdefault(key, Group(group_cfg))
            group.members.append(i)
            group.values.append(values)
            group.scales.append(scales)
            group.configs.append(group_cfg)
        return cls(scenarios, list(groups.values()))

    def columns(self, group: Group, params: dict[str, np.ndarray], P: int) -> dict[str, np.ndarray]:
        """``params`` of P designs under every scenario of ``group``: each path ``(P S_g,)``,
        the designs of the group's first scenario, then of its second, ..."""
        changed = set(params).union(*group.values, *group.scales)
        nominal = numeric_paths(group.cfg)
        out = {}
        for path in changed:
            base = params[path] if path in params else np.full(P, nominal[path])
            parts = []
            for values, scales in zip(group.values, group.scales):
                if path in values:
                    parts.append(np.full(P, values[path]))
                elif path in scales:
                    parts.append(base * scales[path])
                else:
                    parts.append(base)
            out[path] = np.concatenate(parts)
        return out


def aggregate(values: np.ndarray, how: list, weights: np.ndarray) -> np.ndarray:
    """``(P, k)``: each column of ``values (P, S, k)`` combined over the scenarios by its
    ``how`` (``mean``, ``max``, ``min``, ``std``, ``weighted`` or a
    :class:`~suspopt.config.scenarios.Quantile`)."""
    P, _, k = values.shape
    out = np.empty((P, k))
    for j, rule in enumerate(how):  # one rule per objective or constraint column
        v = values[:, :, j]
        if isinstance(rule, Quantile):
            out[:, j] = np.quantile(v, rule.quantile, axis=1)
        elif rule == "weighted":
            out[:, j] = (v * weights).sum(axis=1) / weights.sum()
        elif rule == "mean":
            out[:, j] = v.mean(axis=1)
        elif rule == "max":
            out[:, j] = v.max(axis=1)
        elif rule == "min":
            out[:, j] = v.min(axis=1)
        else:
            out[:, j] = v.std(axis=1)
    return out
