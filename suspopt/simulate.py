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

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .config import Config
from .params import ParamView
from .road import road_inputs
from .vehicle import VehicleModel, build_vehicle

__all__ = ["simulate", "Result", "SignalMap", "DIVERGENCE_LIMIT", "signal_units"]

#: |state| above this (m, rad, m/s, rad/s) counts as divergence.
DIVERGENCE_LIMIT = 1.0e6
_CHECK_EVERY = 25


class _Dynamics:
    """Right-hand side y' = [q', M^-1 f(q, q', road)] of the first-order system y = [q, q']."""

    def __init__(self, model: VehicleModel):
        self.model = model
        self.n = model.n_dof
        self.inverse_mass = 1.0 / model.mass

    def __call__(self, y: np.ndarray, road: np.ndarray, road_vel: np.ndarray) -> np.ndarray:
        q, v = y[..., :self.n], y[..., self.n:]
        force = self.model.generalised_force(q, v, road, road_vel)
        return np.concatenate([v, force * self.inverse_mass], axis=-1)


def _integrate(f: _Dynamics, P: int, road: np.ndarray, road_vel: np.ndarray, dt: float,
               n_steps: int, every: int):
    """RK4 over ``n_steps``; ``road``/``road_vel`` are (2 n_steps + 1, 1, 1, N) on the
    half-step grid. Returns states (P, T, 2n) at every ``every``-th step, diverged, time."""
    n2 = 2 * f.n
    y = np.zeros((P, 1, n2))
    n_out = n_steps // every + 1
    states = np.empty((n_out, P, n2))      # time-major: each sample is one contiguous write
    states[0] = y[:, 0]
    diverged_at = np.full(P, np.nan)
    half = 0.5 * dt
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(n_steps):
            i = 2 * k
            k1 = f(y, road[i], road_vel[i])
            k2 = f(y + half * k1, road[i + 1], road_vel[i + 1])
            k3 = f(y + half * k2, road[i + 1], road_vel[i + 1])
            k4 = f(y + dt * k3, road[i + 2], road_vel[i + 2])
            y = y + (dt / 6.0) * (k1 + 2.0 * (k2 + k3) + k4)
            if (k + 1) % _CHECK_EVERY == 0 or k + 1 == n_steps:
                bad = ~(np.abs(y) < DIVERGENCE_LIMIT).all(axis=(1, 2))
                new = bad & np.isnan(diverged_at)
                if new.any():
                    diverged_at[new] = (k + 1) * dt
                    y[bad] = np.nan
            if (k + 1) % every == 0:
                states[(k + 1) // every] = y[:, 0]
    return np.ascontiguousarray(states.transpose(1, 0, 2)), diverged_at


def simulate(cfg: Config, params: Mapping[str, Any] | None = None) -> "Result":
    """Simulate ``cfg`` for one design, or for P designs given as dotted-path arrays.

    ``params`` maps dotted config paths (e.g. ``"vehicle.corners.F1.damper.c"``) to arrays of
    shape (P,). Returns a :class:`Result` whose signals are (P, T).
    """
    pv = ParamView(cfg, params)
    model = build_vehicle(cfg, pv)
    sim = cfg.simulation
    n_steps, every = sim.n_steps, sim.output_every
    t_grid = np.arange(2 * n_steps + 1) * (0.5 * sim.dt)
    z, zd = road_inputs(cfg.road, model.offsets, model.sides, t_grid, base_dir=cfg.base_dir)
    road = np.ascontiguousarray(z.T)[:, None, None, :]
    road_vel = np.ascontiguousarray(zd.T)[:, None, None, :]
    f = _Dynamics(model)
    states, diverged_at = _integrate(f, pv.P, road, road_vel, sim.dt, n_steps, every)
    out_idx = np.arange(0, 2 * n_steps + 1, 2 * every)
    return Result(config=cfg, model=model, time=t_grid[out_idx], states=states,
                  road=z[:, out_idx].T[None], road_vel=zd[:, out_idx].T[None],
                  diverged_at=diverged_at, designs=dict(pv.params), _dynamics=f)


_BODY_UNITS = {"heave": "m", "roll": "rad", "pitch": "rad"}


def signal_units(name: str) -> str:
    """SI unit of a signal name."""
    head = name.split(".")[0]
    if head == "body":
        dof, _, deriv = name.split(".")[1].partition("_")
        base = _BODY_UNITS[dof]
        return {"": base, "vel": base + "/s", "acc": base + "/s^2"}[deriv]
    if head == "wheel":
        return {"heave": "m", "heave_vel": "m/s", "heave_acc": "m/s^2"}[name.split(".")[2]]
    return {"travel": "m", "travel_vel": "m/s", "tyre_deflection": "m", "tyre_force": "N",
            "spring_force": "N", "damper_force": "N", "damping": "N s/m", "road": "m",
            "road_vel": "m/s"}[head]


class SignalMap(Mapping):
    """Lazy, cached mapping of signal name -> (P, T) array, computed from the states."""

    def __init__(self, result: "Result"):
        self._r = result
        self._cache: dict[str, np.ndarray] = {}
        m = result.model
        names = []
        for dof in m.body_dofs:
            names += [f"body.{dof}", f"body.{dof}_vel", f"body.{dof}_acc"]
        for c in m.corners:
            names += [f"wheel.{c}.heave", f"wheel.{c}.heave_vel", f"wheel.{c}.heave_acc"]
        for head in ("travel", "travel_vel", "tyre_deflection", "tyre_force", "spring_force",
                     "damper_force", "damping", "road", "road_vel"):
            names += [f"{head}.{c}" for c in m.corners]
        self._names = names

    def __iter__(self) -> Iterator[str]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self._cache:
            if name not in self._names:
                import difflib
                close = difflib.get_close_matches(name, self._names, n=3)
                raise KeyError(f"unknown signal {name!r}" +
                               (f"; did you mean {', '.join(close)}?" if close else ""))
            self._cache[name] = self._compute(name)
        return self._cache[name]

    def _compute(self, name: str) -> np.ndarray:
        r, m = self._r, self._r.model
        parts = name.split(".")
        head = parts[0]
        if head == "body":
            dof, _, deriv = parts[1].partition("_")
            j = m.body_dofs.index(dof)
            return r.channel(deriv, j)
        c = m.corners.index(parts[1])
        if head == "wheel":
            deriv = parts[2].partition("_")[2]
            return r.channel(deriv, m.n_body + c)
        if head in ("road", "road_vel"):
            src = r.road if head == "road" else r.road_vel
            return np.broadcast_to(src[..., c], (m.P, r.time.size)).copy()
        if head in ("travel", "spring_force"):
            st = r.per_corner("travel")
            return (st if head == "travel" else m.spring_force(st))[..., c]
        if head in ("travel_vel", "damper_force"):
            std = r.per_corner("travel_vel")
            return (std if head == "travel_vel" else m.damper * std)[..., c]
        if head == "tyre_deflection":
            return r.q[..., m.n_body + c] - r.road[..., c]
        if head == "tyre_force":
            return m.tyre_force(r.q, r.v, r.road, r.road_vel)[..., c]
        if head == "damping":
            return np.broadcast_to(m.damper[..., c], (m.P, r.time.size)).copy()
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
    metrics: dict[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self):
        self.signals = SignalMap(self)
        self._corner_cache: dict[str, np.ndarray] = {}
        self._derivative: np.ndarray | None = None

    @property
    def P(self) -> int:
        return self.states.shape[0]

    @property
    def diverged(self) -> np.ndarray:
        """(P,) True where the design's simulation diverged."""
        return ~np.isnan(self.diverged_at)

    @property
    def q(self) -> np.ndarray:
        return self.states[..., : self.model.n_dof]

    @property
    def v(self) -> np.ndarray:
        return self.states[..., self.model.n_dof:]

    def channel(self, deriv: str, j: int) -> np.ndarray:
        """DOF ``j`` displacement (''), velocity ('vel') or acceleration ('acc'), (P, T)."""
        n = self.model.n_dof
        if deriv == "":
            return self.states[..., j]
        if deriv == "vel":
            return self.states[..., n + j]
        if self._derivative is None:
            with np.errstate(invalid="ignore", over="ignore"):
                self._derivative = self._dynamics(self.states, self.road, self.road_vel)
        return self._derivative[..., n + j]

    def per_corner(self, kind: str) -> np.ndarray:
        """(P, T, N) suspension travel ('travel') or its rate ('travel_vel')."""
        if kind not in self._corner_cache:
            src = self.q if kind == "travel" else self.v
            self._corner_cache[kind] = self.model.travel(src)
        return self._corner_cache[kind]
