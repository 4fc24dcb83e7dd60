"""Batched fixed-step simulation of P designs at once and the ``Result`` it returns.

The integrator is the classical 4th-order Runge-Kutta method with a fixed step ``dt``; the road
is sampled on the half-step grid the stages need, so a bump edge that falls on a step boundary
is seen exactly. All P designs advance together: each stage is a handful of array operations on
states of shape (P, 1, 2n) - there is no Python loop over designs.

A design whose state becomes non-finite or exceeds ``DIVERGENCE_LIMIT`` is marked in
``Result.diverged`` (with the time in ``Result.diverged_at``); its samples from then on are NaN,
so a diverged design can never pass for a valid one.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import difflib

import numpy as np

from .config import Config
from .control import build_controller
from .params import ParamView
from .specs import evaluate_spec, spec_signals
from .road import road_inputs
from .seat import SIGNAL_HEADS as _SEAT_HEADS, build_attachments
from .seat import signal_units as _seat_signal_units
from .vehicle import VehicleModel, build_vehicle

__all__ = ["simulate", "check", "signal_names", "signal_units", "Result", "SignalMap",
           "Controller", "Attachment", "DIVERGENCE_LIMIT"]

#: |state| above this (m, rad, m/s, rad/s) counts as divergence.
DIVERGENCE_LIMIT = 1.0e6
_CHECK_EVERY = 25


class Controller(Protocol):
    """A semi-active damper controller (built by :mod:`suspopt.control`).

    The integrator calls ``start`` once, then ``step`` at the start of every integration step
    with the vehicle states ``q, v (P, 1, n)``; ``step`` returns the damping coefficients
    ``(P, 1, N)`` [N s/m] held over that step, so a digital controller changes them only at
    its own sample instants (zero-order hold). ``acceleration()`` gives the vehicle
    accelerations ``(P, 1, n)`` at the current instant, computed only when called.
    ``record`` returns the controller's quantities ``{name: (P, N)}`` at output instants;
    they become the signals ``<name>.<corner>`` with units ``units[name]``.
    """

    units: dict[str, str]

    def start(self, P: int) -> np.ndarray: ...

    def step(self, k: int, t: float, q: np.ndarray, v: np.ndarray,
             acceleration: Callable[[], np.ndarray]) -> np.ndarray: ...

    def record(self) -> dict[str, np.ndarray]: ...


class Attachment(Protocol):
    """Extra bodies mounted at a point of the vehicle body (a seat, a seated passenger).

    ``dof_names`` name its vertical DOFs (appended after the vehicle's), ``mass (1|P, 1, m)``
    their masses. ``point = (x, y)`` is where it sits on the body [m] (x + forward, y + right);
    the base motion is the body's vertical motion there. ``force`` returns the forces on its
    own DOFs ``(P, S, m)`` and the vertical force it exerts on the body at the point
    ``(P, S)`` (upward +), which acts on the body only when ``coupled`` (two-way); the thesis
    drives seats one way. ``signal(name, ...)`` computes its named signals ``(P, S)``.
    """

    dof_names: tuple[str, ...]
    mass: np.ndarray
    point: tuple[float, float]
    coupled: bool

    def force(self, q: np.ndarray, v: np.ndarray, base: np.ndarray,
              base_vel: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...

    def signal_names(self) -> list[str]: ...

    def signal(self, name: str, q: np.ndarray, v: np.ndarray, acc: np.ndarray,
               base: np.ndarray, base_vel: np.ndarray, base_acc: np.ndarray) -> np.ndarray: ...


class _Dynamics:
    """Right-hand side y' = [q', M^-1 f(q, q', road)] of the first-order system y = [q, q'],
    q = [vehicle DOFs, attachment DOFs]."""

    def __init__(self, model: VehicleModel, attachments: Sequence[Attachment] = ()):
        self.model = model
        self.attachments = tuple(attachments)
        self.n_vehicle = model.n_dof
        self.slices, start = [], model.n_dof
        for att in self.attachments:
            self.slices.append(slice(start, start + len(att.dof_names)))
            start += len(att.dof_names)
        self.n = start
        self.point_rows = [model.point_map(*att.point) for att in self.attachments]
        masses = [model.mass] + [att.mass for att in self.attachments]
        P = max(m.shape[0] for m in masses)
        self.inverse_mass = 1.0 / np.concatenate(
            [np.broadcast_to(m, (P, 1, m.shape[-1])) for m in masses], axis=-1)

    def base(self, j: int, x: np.ndarray) -> np.ndarray:
        """Body displacement (or velocity, acceleration) at attachment j's point, (P, S)."""
        return x[..., :self.n_vehicle] @ self.point_rows[j]

    def __call__(self, y: np.ndarray, road: np.ndarray, road_vel: np.ndarray,
                 damping: np.ndarray | None = None) -> np.ndarray:
        n, nv = self.n, self.n_vehicle
        q, v = y[..., :n], y[..., n:]
        force = self.model.generalised_force(q[..., :nv], v[..., :nv], road, road_vel, damping)
        parts = [force]
        for j, att in enumerate(self.attachments):
            sl = self.slices[j]
            own, reaction = att.force(q[..., sl], v[..., sl], self.base(j, q), self.base(j, v))
            if att.coupled:
                force = force + reaction[..., None] * self.point_rows[j]
                parts[0] = force
            parts.append(own)
        acc = (np.concatenate(parts, axis=-1) if len(parts) > 1 else parts[0]) \
            * self.inverse_mass
        return np.concatenate([v, acc], axis=-1)


@dataclass
class _Held:
    """A controller quantity held between changes: the distinct values ``(S, P, N)`` and, for
    each output sample, which of them held ``(T,)``. Expanded to ``(P, T, N)`` on demand, so a
    coefficient that changes only every ΔT is stored once per change, not per sample."""

    values: np.ndarray
    index: np.ndarray

    def corner(self, c: int) -> np.ndarray:
        """(P, T) series of corner ``c``."""
        return self.values[self.index, :, c].T

    def full(self) -> np.ndarray:
        """(P, T, N) series of every corner."""
        return np.moveaxis(self.values[self.index], 0, 1)


@dataclass
class _Trajectory:
    """What one integration produced: states (P, T, 2n), the held damping coefficients and
    controller records (or None / empty without a controller) and the divergence times (P,)."""

    states: np.ndarray
    damping: _Held | None
    records: dict[str, _Held]
    diverged_at: np.ndarray


def _integrate(f: _Dynamics, P: int, road: np.ndarray, road_vel: np.ndarray, dt: float,
               n_steps: int, every: int, controller: Controller | None = None) -> _Trajectory:
    """RK4 over ``n_steps``; ``road``/``road_vel`` are (2 n_steps + 1, 1, 1, N) on the
    half-step grid. Samples are kept at every ``every``-th step."""
    n, n2 = f.n, 2 * f.n
    y = np.zeros((P, 1, n2))
    n_out = n_steps // every + 1
    states = np.empty((n_out, P, n2))      # time-major: each sample is one contiguous write
    damping = None
    held: list[tuple[np.ndarray, dict[str, np.ndarray]]] = []
    held_index = np.empty(n_out, dtype=np.intp)
    last: list = [None, None]
    if controller is not None:
        damping = controller.start(P)
    diverged_at = np.full(P, np.nan)
    half = 0.5 * dt
    nv = f.n_vehicle

    def keep(j: int) -> None:
        states[j] = y[:, 0]
        if controller is not None:
            records = controller.record()
            # controllers hand out new arrays when a value changes: store only the changes
            if damping is not last[0] or records is not last[1]:
                held.append((damping[:, 0].copy(),
                             {name: np.array(value) for name, value in records.items()}))
                last[:] = [damping, records]
            held_index[j] = len(held) - 1

    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(n_steps):
            i = 2 * k
            if controller is not None:
                def acceleration(y=y, i=i, damping=damping):
                    return f(y, road[i], road_vel[i], damping)[..., n:n + nv]
                damping = controller.step(k, k * dt, y[..., :nv], y[..., n:n + nv], acceleration)
            if k == 0:
                keep(0)
            k1 = f(y, road[i], road_vel[i], damping)
            k2 = f(y + half * k1, road[i + 1], road_vel[i + 1], damping)
            k3 = f(y + half * k2, road[i + 1], road_vel[i + 1], damping)
            k4 = f(y + dt * k3, road[i + 2], road_vel[i + 2], damping)
            y = y + (dt / 6.0) * (k1 + 2.0 * (k2 + k3) + k4)
            if (k + 1) % _CHECK_EVERY == 0 or k + 1 == n_steps:
                bad = ~(np.abs(y) < DIVERGENCE_LIMIT).all(axis=(1, 2))
                new = bad & np.isnan(diverged_at)
                if new.any():
                    diverged_at[new] = (k + 1) * dt
                    y[bad] = np.nan
            if (k + 1) % every == 0:
                keep((k + 1) // every)

    damping_held, records_held = None, {}
    if controller is not None:
        damping_held = _Held(np.stack([h[0] for h in held]), held_index)
        records_held = {name: _Held(np.stack([h[1][name] for h in held]), held_index)
                        for name in held[0][1]}
    return _Trajectory(states=np.ascontiguousarray(np.moveaxis(states, 0, 1)),
                       damping=damping_held, records=records_held, diverged_at=diverged_at)


def _prepare(cfg: Config, params: Mapping[str, Any] | None):
    """Designs, model, controller and attachments of a run; metric specs checked against the
    signals the run will have (so bad specs fail before any integration)."""
    pv = ParamView(cfg, params)
    model = build_vehicle(cfg, pv)
    controller: Controller | None = build_controller(cfg, pv, model)
    attachments: list[Attachment] = build_attachments(cfg, pv)
    available = signal_names(model, getattr(controller, "units", {}), attachments)
    for i, spec in enumerate(cfg.metrics):
        try:
            spec_signals(spec, available, model.corners)
        except ValueError as exc:
            raise cfg.error(("metrics", i, "signal"), str(exc)) from None
    return pv, model, controller, attachments


def check(cfg: Config) -> None:
    """Raise ConfigError for problems only the assembled model reveals (metric signals)."""
    _prepare(cfg, None)


def simulate(cfg: Config, params: Mapping[str, Any] | None = None) -> "Result":
    """Simulate ``cfg`` for one design, or for P designs given as dotted-path arrays.

    ``params`` maps dotted config paths (e.g. ``"vehicle.corners.F1.damper.c"``) to arrays of
    shape (P,). Returns a :class:`Result` whose signals are (P, T) and whose ``metrics`` hold
    the config's ``metrics:`` specs as (P,) arrays.
    """
    pv, model, controller, attachments = _prepare(cfg, params)
    result = _run(cfg, pv, model, controller, attachments)
    for spec in cfg.metrics:
        for name, values, unit in evaluate_spec(spec, result, result.signal_unit):
            result.metrics[name] = values
            result.metric_units[name] = unit
    return result


def _run(cfg: Config, pv: ParamView, model: VehicleModel, controller: Controller | None,
         attachments: Sequence[Attachment]) -> "Result":
    sim = cfg.simulation
    n_steps, every = sim.n_steps, sim.output_every
    t_grid = np.arange(2 * n_steps + 1) * (0.5 * sim.dt)
    z, zd = road_inputs(cfg.road, model.offsets, model.sides, t_grid, base_dir=cfg.base_dir)
    road = np.ascontiguousarray(z.T)[:, None, None, :]
    road_vel = np.ascontiguousarray(zd.T)[:, None, None, :]
    f = _Dynamics(model, attachments)
    traj = _integrate(f, pv.P, road, road_vel, sim.dt, n_steps, every, controller)
    out_idx = np.arange(0, 2 * n_steps + 1, 2 * every)
    return Result(config=cfg, model=model, time=t_grid[out_idx], states=traj.states,
                  road=z[:, out_idx].T[None], road_vel=zd[:, out_idx].T[None],
                  diverged_at=traj.diverged_at, designs=dict(pv.params), _dynamics=f,
                  held_damping=traj.damping, controller_records=traj.records,
                  controller_units=dict(getattr(controller, "units", {})))


_BODY_UNITS = {"heave": "m", "roll": "rad", "pitch": "rad"}


def signal_units(name: str) -> str:
    """SI unit of a signal name."""
    head = name.split(".")[0]
    if head in _SEAT_HEADS:
        return _seat_signal_units(name)
    if head == "body":
        dof, _, deriv = name.split(".")[1].partition("_")
        base = _BODY_UNITS[dof]
        return {"": base, "vel": base + "/s", "acc": base + "/s^2"}[deriv]
    if head == "wheel":
        return {"heave": "m", "heave_vel": "m/s", "heave_acc": "m/s^2"}[name.split(".")[2]]
    return {"travel": "m", "travel_vel": "m/s", "tyre_deflection": "m", "tyre_force": "N",
            "spring_force": "N", "damper_force": "N", "damping": "N s/m", "road": "m",
            "road_vel": "m/s"}[head]


def signal_names(model: VehicleModel, controller_units: Mapping[str, str] = {},
                 attachments: Sequence[Attachment] = ()) -> list[str]:
    """Every signal a simulation of this model (controller, attachments) provides."""
    names = []
    for dof in model.body_dofs:
        names += [f"body.{dof}", f"body.{dof}_vel", f"body.{dof}_acc"]
    for c in model.corners:
        names += [f"wheel.{c}.heave", f"wheel.{c}.heave_vel", f"wheel.{c}.heave_acc"]
    for head in ("travel", "travel_vel", "tyre_deflection", "tyre_force", "spring_force",
                 "damper_force", "damping", "road", "road_vel", *controller_units):
        names += [f"{head}.{c}" for c in model.corners]
    for att in attachments:
        names += att.signal_names()
    return names


class SignalMap(Mapping):
    """Lazy, cached mapping of signal name -> (P, T) array, computed from the states."""

    def __init__(self, result: "Result"):
        self._r = result
        self._cache: dict[str, np.ndarray] = {}
        self._names = signal_names(result.model, result.controller_units,
                                   result._dynamics.attachments)
        self._attachment_of = {name: j for j, att in enumerate(result._dynamics.attachments)
                               for name in att.signal_names()}

    def __iter__(self) -> Iterator[str]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)

    def __contains__(self, name: object) -> bool:
        return name in self._names

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self._cache:
            if name not in self._names:
                close = difflib.get_close_matches(name, self._names, n=3)
                raise KeyError(f"unknown signal {name!r}" +
                               (f"; did you mean {', '.join(close)}?" if close else ""))
            self._cache[name] = self._compute(name)
        return self._cache[name]

    def _compute(self, name: str) -> np.ndarray:
        r, m = self._r, self._r.model
        if name in self._attachment_of:
            return r.attachment_signal(self._attachment_of[name], name)
        parts = name.split(".")
        head = parts[0]
        if head == "body":
            dof, _, deriv = parts[1].partition("_")
            return r.channel(deriv, m.body_dofs.index(dof))
        c = m.corners.index(parts[1])
        if head in r.controller_records:
            return r.controller_records[head].corner(c)
        if head == "wheel":
            return r.channel(parts[2].partition("_")[2], m.n_body + c)
        if head in ("road", "road_vel"):
            src = r.road if head == "road" else r.road_vel
            return np.broadcast_to(src[..., c], (m.P, r.time.size)).copy()
        if head in ("travel", "spring_force"):
            st = r.per_corner("travel")
            return (st if head == "travel" else m.spring_force(st))[..., c]
        if head == "travel_vel":
            return r.per_corner("travel_vel")[..., c]
        if head == "damper_force":
            return (r.damping_coefficient() * r.per_corner("travel_vel"))[..., c]
        if head == "damping":
            return np.broadcast_to(r.damping_coefficient()[..., c], (m.P, r.time.size)).copy()
        if head == "tyre_deflection":
            return r.q[..., m.n_body + c] - r.road[..., c]
        if head == "tyre_force":
            return m.tyre_force(r.vehicle_q, r.vehicle_v, r.road, r.road_vel)[..., c]
        raise KeyError(name)


@dataclass
class Result:
    """Output of :func:`simulate`.

    ``time (T,)`` [s]; ``signals[name] (P, T)`` (lazy); ``metrics[name] (P,)``;
    ``diverged (P,)`` and ``diverged_at (P,)`` [s, NaN when fine]; ``designs`` the (P,) arrays of
    the design parameters by dotted path; ``states (P, T, 2n)`` the raw [q, q'] samples.
    """

    config: Config
    model: VehicleModel
    time: np.ndarray
    states: np.ndarray
    road: np.ndarray
    road_vel: np.ndarray
    diverged_at: np.ndarray
    designs: dict[str, np.ndarray]
    _dynamics: _Dynamics
    held_damping: _Held | None = None
    controller_records: dict[str, _Held] = field(default_factory=dict)
    controller_units: dict[str, str] = field(default_factory=dict)
    metrics: dict[str, np.ndarray] = field(default_factory=dict)
    metric_units: dict[str, str] = field(default_factory=dict)

    def __post_init__(self):
        self.signals = SignalMap(self)
        self._corner_cache: dict[str, np.ndarray] = {}
        self._derivative: np.ndarray | None = None
        self._damping_full: np.ndarray | None = None

    def signal_unit(self, name: str) -> str:
        """SI unit of a signal of this result."""
        head = name.split(".")[0]
        if head in self.controller_units:
            return self.controller_units[head]
        return signal_units(name)

    @property
    def P(self) -> int:
        return self.states.shape[0]

    @property
    def diverged(self) -> np.ndarray:
        """(P,) True where the design's simulation diverged."""
        return ~np.isnan(self.diverged_at)

    @property
    def q(self) -> np.ndarray:
        """Displacements of every DOF (vehicle, then attachments), (P, T, n)."""
        return self.states[..., : self._dynamics.n]

    @property
    def v(self) -> np.ndarray:
        """Velocities of every DOF, (P, T, n)."""
        return self.states[..., self._dynamics.n:]

    @property
    def vehicle_q(self) -> np.ndarray:
        return self.q[..., : self.model.n_dof]

    @property
    def vehicle_v(self) -> np.ndarray:
        return self.v[..., : self.model.n_dof]

    def damping_coefficient(self) -> np.ndarray:
        """Damper coefficient of every corner, (P, T, N) or (P, 1, N) when passive [N s/m]."""
        return self.model.damper if self.damping_history is None else self.damping_history

    @property
    def damping_history(self) -> np.ndarray | None:
        """(P, T, N) damping coefficients of a controlled run [N s/m], None when passive."""
        if self.held_damping is None:
            return None
        if self._damping_full is None:
            self._damping_full = self.held_damping.full()
        return self._damping_full

    def acceleration(self) -> np.ndarray:
        """Accelerations of every DOF, (P, T, n), from the equations of motion."""
        if self._derivative is None:
            with np.errstate(invalid="ignore", over="ignore"):
                damping = self.damping_history
                self._derivative = self._dynamics(self.states, self.road, self.road_vel,
                                                  damping)
        return self._derivative[..., self._dynamics.n:]

    def attachment_signal(self, j: int, name: str) -> np.ndarray:
        f = self._dynamics
        sl = f.slices[j]
        acc = self.acceleration()
        return f.attachments[j].signal(name, self.q[..., sl], self.v[..., sl], acc[..., sl],
                                       f.base(j, self.q), f.base(j, self.v), f.base(j, acc))

    def channel(self, deriv: str, j: int) -> np.ndarray:
        """DOF ``j`` displacement (''), velocity ('vel') or acceleration ('acc'), (P, T)."""
        if deriv == "":
            return self.q[..., j]
        if deriv == "vel":
            return self.v[..., j]
        return self.acceleration()[..., j]

    def per_corner(self, kind: str) -> np.ndarray:
        """(P, T, N) suspension travel ('travel') or its rate ('travel_vel')."""
        if kind not in self._corner_cache:
            src = self.vehicle_q if kind == "travel" else self.vehicle_v
            self._corner_cache[kind] = self.model.travel(src)
        return self._corner_cache[kind]
