"""The digital controller of the semi-active dampers (Sec 4.2) and its CDF threshold (Ch. 4).

The laws (:mod:`suspopt.control.laws`) are evaluated every ``ΔT`` (``control.sample_time``, a
whole multiple of the integration step) and the command is held in between (zero-order
hold). With an actuator lag ``τ`` the coefficient follows the command per integration step
as the exact first-order response, ``c <- c_cmd - (c_cmd - c) exp(-dt/τ)`` (i.e.
``c += (c_cmd - c)(1 - exp(-dt/τ))``), the value at the end of the step being used over the
step, so ``τ -> 0`` is the instantaneous damper; the simulator applies it to the damper
coefficients every step (:attr:`SemiActiveController.lag_decay`). The laws that need ``z̈_s``
(add, sh_add_1, sh_add_2) evaluate the equations of motion at sample instants only, with the
coefficient in force just before the sample.

**CDF threshold** (Ch. 4): see :class:`suspopt.config.control.Threshold` and
:func:`suspopt.control.stats.threshold_for_share`. An adaptive threshold keeps every sample of
the condition (``duration / ΔT`` x P x N floats) and refits from all of them (Fig. 4.4): the
normal and empirical fits from the samples themselves, the Student-t fit from a fixed-size
summary that takes in each sample once (:class:`~suspopt.control.stats.StudentTSummary`), so
a refit costs the same however long the history.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from .config import Config, ConfigError
from .config.control import Control
from .control.laws import LAWS, PARAMETERS, Motion
from .control.stats import distribution_quantile, t_quantile
from .control.summary import StudentTSummary
from .params import ParamView
from .vehicle import VehicleModel

__all__ = ["SemiActiveController", "SampleRules", "build_controller"]


def _per_design(
    pv: ParamView, path: str, low: float, high: float | None = None, low_open: bool = False
) -> np.ndarray:
    """``pv.get(path)``, checking every design's value lies in the field's range."""
    value = pv.get(path)
    bad = (value <= low) if low_open else (value < low)
    if high is not None:
        bad |= value > high
    if bad.any():
        rng = f"{'(' if low_open else '['}{low:g}, {'inf)' if high is None else f'{high:g}]'}"
        raise ConfigError(
            f"params: {path}: must be in {rng} (designs {np.flatnonzero(bad)[:5].tolist()})"
        )
    return value


def _rows_map(matrix: np.ndarray) -> np.ndarray:
    """A (1|P, r, n) map of the vehicle's DOFs as (r, n) when every design shares it."""
    return np.ascontiguousarray(matrix[0] if matrix.shape[0] == 1 else matrix)


def _by_rows(matrix: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``matrix @ rows`` for the vehicle's DOF rows ``(n, P)`` [m/s or m/s^2], as the per-corner
    layout (P, 1, r) of the laws (a view)."""
    out = np.dot(matrix, rows) if matrix.ndim == 2 else np.einsum("prc,cp->rp", matrix, rows)
    return out.T[:, None, :]


class SampleRules(NamedTuple):
    """What an engine needs to take a controller's samples itself
    (:meth:`SemiActiveController.sample_rules`), with the controller's arithmetic: the law of
    each corner (None: passive), the map ``rates`` ``(3N, n)`` or ``(P, 3N, n)`` of the
    vehicle's velocities to ``[ṠT; ż_s; ż_u]`` at the corners (its rows ``N .. 2N`` also map
    the accelerations to ``z̈_s``), ``C_min``, ``C_max`` [N s/m] and the threshold ``(P, N)``,
    the law parameters ``(len(PARAMETERS), P, N)`` in the order of
    :data:`~suspopt.control.laws.PARAMETERS`, where a corner is stiff below the threshold
    ``(N,)``, whether a law reads ``z̈_s`` and whether the records carry ``stiff``
    (:meth:`SemiActiveController.record`); ``adaptive``: the threshold is the one in force
    until the next refit (:meth:`SemiActiveController.refit_step`), whose sample the
    controller takes itself."""

    laws: tuple[str | None, ...]
    rates: np.ndarray
    c_min: np.ndarray
    c_max: np.ndarray
    threshold: np.ndarray
    parameters: np.ndarray
    below: np.ndarray
    needs_acceleration: bool
    stiff_records: bool
    adaptive: bool = False


class SemiActiveController:
    """Digital controller of the semi-active dampers (see the module docstring); implements the
    simulator's ``Controller`` protocol. Built by :func:`build_controller`.

    Arrays are (P, 1, N) over designs and corners; passive corners hold ``C_min = C_max = c``
    and their records are NaN. Records (signals ``<name>.<corner>``): ``damper_state`` (the
    command's place in the range, ``(c - C_min)/(C_max - C_min)``: 0 soft, 1 stiff, fractional
    for the continuous laws), ``control_condition`` (X of the latest sample) and
    ``control_threshold`` (T in force). Like ``damping``, a record at an output instant holds
    what was in force over the integration step ending there, i.e. the latest sample before it.
    """

    def __init__(
        self,
        model: VehicleModel,
        laws: list[str | None],
        c_min: np.ndarray,
        c_max: np.ndarray,
        parameters: dict[str, np.ndarray],
        dt: float,
        sample_every: int,
        n_steps: int,
        actuator_lag: np.ndarray,
        threshold: np.ndarray,
        c_max_share: np.ndarray | None = None,
        learn_time: np.ndarray | None = None,
        refit_factor: np.ndarray | None = None,
        distribution: str = "student_t",
    ):
        N = len(model.corners)
        self._laws = tuple(laws)
        self._passive = np.array([law is None for law in laws])
        present = sorted({law for law in laws if law is not None}, key=list(LAWS).index)
        self._groups = [
            (
                law,
                None
                if len(present) == 1 and not self._passive.any()
                else np.array([x == law for x in laws]),
            )
            for law in present
        ]
        self._needs_acc = any(LAWS[law].needs_acceleration for law in present)
        below = np.array([law is not None and LAWS[law].stiff_below for law in laws])
        self._below = below if below.any() and not below.all() else bool(below.all())
        self._c_min, self._c_max = c_min, c_max
        self._switchable = c_max > c_min
        self._fixed = not self._switchable.all()  # some corner has C_min = C_max
        self._range = np.where(self._switchable, c_max - c_min, 1.0)
        self._parameters = parameters  # name -> (P, 1, N)
        # one product gives the travel rates, the body's velocities at the corners and the
        # wheels' velocities: rows [J; J_body; wheels] of the vehicle velocities
        J = model.travel_map
        body = np.zeros_like(J)
        body[:, :, : model.n_body] = J[:, :, : model.n_body]
        wheels = np.zeros((1,) + J.shape[1:])
        wheels[0, np.arange(N), model.wheels.start + np.arange(N)] = 1.0
        self._rates = _rows_map(np.concatenate([J, body, np.broadcast_to(wheels, J.shape)], axis=1))
        self._body = _rows_map(body)
        self.samples = 0  # samples taken: the records change only with them
        self._every = sample_every
        self._decay = np.exp(-dt / np.where(actuator_lag > 0, actuator_lag, 1.0)) * (
            actuator_lag > 0
        )
        self._lagged = bool(np.any(actuator_lag > 0))
        self._threshold = threshold
        self._adaptive = c_max_share is not None
        if c_max_share is not None:  # (adaptive: learn_time and refit_factor given with it)
            assert learn_time is not None and refit_factor is not None
            share = c_max_share[:, None, None]
            self._level = np.where(below[None, None, :], share, 1.0 - share)[:, 0, :]
            self._period = refit_factor * learn_time
            self._next_fit = learn_time.astype(float).copy()
            self._next_due = float(np.min(self._next_fit))  # the earliest of them
            self._history = np.empty((n_steps // sample_every + 1,) + threshold.shape[::2])
            self._n_history = 0
            self._distribution = distribution
            self._t_summary = (
                StudentTSummary(self._history[0].size) if distribution == "student_t" else None
            )
            self._half_step = 0.5 * dt
        units = {LAWS[law].unit for law in present}
        unit = (
            units.pop()
            if len(units) == 1
            else "; ".join(
                f"{c}: {LAWS[law].unit}" for c, law in zip(model.corners, laws) if law is not None
            )
        )
        self.units = {"damper_state": "1", "control_condition": unit, "control_threshold": unit}
        self._N = N

    def start(self, P: int) -> np.ndarray:
        """Command at rest: the soft state (P, 1, N)."""
        self._cmd = np.broadcast_to(self._c_min, (P, 1, self._N)).copy()
        self._condition = np.zeros_like(self._cmd)
        self._stiff = np.zeros(self._cmd.shape, dtype=bool)
        return self._cmd

    @property
    def sample_every(self) -> int:
        """Integration steps per sample (ΔT / dt)."""
        return self._every

    @property
    def lag_decay(self) -> np.ndarray | None:
        """The actuator's factor ``exp(-dt/τ)`` per integration step (P, 1, 1), 0 without a
        lag; None when no design has one."""
        return self._decay if self._lagged else None

    def sample_rules(self) -> SampleRules:
        """The samples' rules for an engine that takes them itself. With an adaptive
        threshold they hold until the next refit (:meth:`refit_step`): the engine hands that
        sample back (:meth:`sample`), tells the controller of the samples it took before
        (:meth:`taken`) and asks for the rules again."""
        below = np.array([law is not None and LAWS[law].stiff_below for law in self._laws])
        values = np.stack([self._parameters[name][:, 0] for name in PARAMETERS])
        return SampleRules(
            self._laws,
            self._rates,
            self._c_min[:, 0],
            self._c_max[:, 0],
            np.broadcast_to(self._threshold[:, 0], self._c_min[:, 0].shape),
            values,
            below,
            self._needs_acc,
            self._fixed,
            self._adaptive,
        )

    def refit_step(self, k: int) -> int | None:
        """The first sample step from step ``k`` on at which some design's threshold is
        refitted (:meth:`_refit`'s test on ``t = k dt``), None with a fixed threshold."""
        if not self._adaptive:
            return None
        every, dt = self._every, 2.0 * self._half_step
        first = -(-k // every)

        def due(j: int) -> bool:
            return not (j * every * dt + self._half_step < self._next_due)

        j = max(first, int((self._next_due - self._half_step) / (dt * every)))
        while j > first and due(j - 1):
            j -= 1
        while not due(j):
            j += 1
        return j * every

    def taken(self, conditions: np.ndarray) -> None:
        """Samples an engine took itself with :meth:`sample_rules` (none of them a refit):
        their conditions ``(S, P, N)``, in time order, join the history the refits fit."""
        if self._adaptive:
            end = self._n_history + len(conditions)
            self._history[self._n_history : end] = conditions
            self._n_history = end
        self.samples += len(conditions)

    def sample(self, k: int, t: float, state) -> np.ndarray:
        """The command (P, 1, N) [N s/m] from the sample at step ``k`` (``t = k dt``), held
        until the next sample (see the protocol in simulate.py)."""
        self._sample(t, state)
        return self._cmd

    def _sample(self, t: float, state) -> None:
        N = self._N
        rates = _by_rows(self._rates, state.velocity())
        travel_vel, body_vel, wheel_vel = (
            rates[..., :N],
            rates[..., N : 2 * N],
            rates[..., 2 * N :],
        )
        body_acc = _by_rows(self._body, state.acceleration()) if self._needs_acc else None
        motion = Motion(travel_vel, body_vel, wheel_vel, body_acc, self._parameters)
        condition = None
        for law, mask in self._groups:
            x = LAWS[law].condition(motion)
            condition = (
                x if mask is None else np.where(mask, x, 0.0 if condition is None else condition)
            )
        assert condition is not None  # (a controller has at least one law)
        if self._adaptive:
            self._refit(t, condition)
        if self._below is True:
            stiff = condition < self._threshold
        elif self._below is False:
            stiff = condition > self._threshold
        else:
            stiff = np.where(self._below, condition < self._threshold, condition > self._threshold)
        c_stiff = self._c_max
        for law, mask in self._groups:
            if LAWS[law].continuous:
                c = LAWS[law].stiff(self._c_min, self._c_max, motion, condition)
                c_stiff = c if mask is None else np.where(mask, c, c_stiff)
        self._cmd = np.where(stiff, c_stiff, self._c_min)
        self._condition, self._stiff = condition, stiff
        self.samples += 1

    def _refit(self, t: float, condition: np.ndarray) -> None:
        """Store the sample; at each design's refit instants set its threshold to the
        quantile of the history (Fig. 4.4: first at t >= T_learn, then every κ T_learn)."""
        self._history[self._n_history] = condition[:, 0]
        self._n_history += 1
        if t + self._half_step < self._next_due:
            return
        due = t + self._half_step >= self._next_fit
        idx = np.flatnonzero(due)
        history = self._history[: self._n_history]
        if self._t_summary is not None:  # bounded: from the summary, see its class
            n, corners = history.shape[0], history.shape[-1]
            columns = (
                slice(None)
                if idx.size == due.size
                else (idx[:, None] * corners + np.arange(corners)).ravel()
            )
            fit = self._t_summary.fit(history.reshape(n, -1), columns)
            first, second, third = (a.reshape(idx.size, corners) for a in fit)
            threshold = t_quantile((first, second, third), self._level[idx])
        else:
            if idx.size < due.size:
                history = history[:, idx]
            threshold = distribution_quantile(history, self._level[idx], self._distribution)
        self._threshold = self._threshold.copy()
        self._threshold[idx, 0] = threshold
        late, period = t + self._half_step - self._next_fit[idx], self._period[idx]
        with np.errstate(over="ignore"):  # a period far below a sample's (5e-324 s) ...
            following = self._next_fit[idx] + period * (np.floor(late / period) + 1.0)
        # ... refits at every sample: its next fit is due at the next one
        self._next_fit[idx] = np.where(np.isfinite(following), following, t + self._half_step)
        self._next_due = float(np.min(self._next_fit))

    def record(self) -> dict[str, np.ndarray]:
        """What the latest sample decided, (P, N) each, as :meth:`published` turns it into
        the records: the command [N s/m], the condition and the threshold in force, and where
        some corner has ``C_min = C_max``, whether the law asked for the stiff state. Arrays
        the controller never writes again."""
        out = {
            "command": self._cmd[:, 0],
            "condition": self._condition[:, 0],
            "threshold": self._threshold[:, 0],
        }
        if self._fixed:  # only where C_min = C_max does it tell more
            out["stiff"] = self._stiff[:, 0]
        return out

    def published(self, raw: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """The records (S, P, N) from :meth:`record`'s values of S samples stacked: damper
        state (the command's place in the range, ``(c - C_min)/(C_max - C_min)``: 0 soft,
        1 stiff, fractional for the continuous laws; where ``C_min = C_max``, whether the law
        asked for the stiff state), condition and threshold; NaN at passive corners.
        Computed once for the whole run, when a record is first read."""
        switchable, c_min, span = (a[:, 0] for a in (self._switchable, self._c_min, self._range))
        state = raw["command"] - c_min
        state /= span
        if self._fixed:
            state = np.where(switchable, state, raw["stiff"])
        records = {
            "damper_state": state,
            "control_condition": raw["condition"],
            "control_threshold": raw["threshold"],
        }
        if self._passive.any():
            records = {
                name: np.where(self._passive, np.nan, value) for name, value in records.items()
            }
        return records


def _sample_ratio(cfg: Config, pv: ParamView, control: Control) -> float:
    """Integration steps per controller sample ``ΔT / dt``: a whole number, one per run."""
    sim = cfg.simulation
    ratio = control.sample_time / sim.dt
    if ratio < 1 - 1e-9 or abs(ratio - round(ratio)) > 1e-6:
        raise cfg.error(
            ("control", "sample_time"),
            f"the controller's sample time "
            f"{control.sample_time:g} s must be a whole multiple of simulation.dt "
            f"({sim.dt:g} s)",
        )
    if pv.varies("control.sample_time"):
        raise ConfigError(
            "params: control.sample_time cannot vary between designs: the "
            "controller samples once per run"
        )

    return ratio


def _threshold(cfg: Config, pv: ParamView, control: Control, laws: list, n_corners: int):
    """The fixed CDF threshold ``(P, 1, N)`` (zero when there is none or it adapts) and the
    adaptive threshold's settings by keyword (empty unless ``mode: adaptive``)."""
    threshold = np.zeros((pv.P, 1, n_corners))
    settings: dict[str, Any] = {}
    spec = control.threshold
    if spec is not None and spec.mode == "fixed":
        units = {LAWS[law].unit for law in laws if law is not None}
        if len(units) > 1:
            raise cfg.error(
                ("control", "threshold", "value"),
                "one fixed threshold cannot serve "
                f"conditions of different units ({', '.join(sorted(units))}); "
                "give the corners laws of one unit or use mode adaptive",
            )
        threshold = threshold + pv.get("control.threshold.value")[:, None, None]
    elif spec is not None:
        base = "control.threshold."
        settings = dict(
            c_max_share=_per_design(pv, base + "c_max_share", 0.0, None, True),
            learn_time=_per_design(pv, base + "learn_time", 0.0, low_open=True),
            refit_factor=_per_design(pv, base + "refit_factor", 0.0, low_open=True),
            distribution=spec.distribution,
        )
        if np.any(settings["c_max_share"] >= 1):
            raise ConfigError(f"params: {base}c_max_share: must be in (0, 1)")
    return threshold, settings


def build_controller(
    cfg: Config, pv: ParamView, model: VehicleModel
) -> SemiActiveController | None:
    """The controller of ``cfg``'s semi-active dampers for the designs of ``pv``; None when
    every damper is passive. Law parameters, lag and threshold settings may vary per design
    (dotted paths in ``pv``); the sample time is one per run."""
    dampers = [cfg.vehicle.corners[c].damper for c in model.corners]
    if all(d.kind == "passive" for d in dampers):
        return None
    control = cfg.control or Control()
    sim = cfg.simulation
    ratio = _sample_ratio(cfg, pv, control)

    def setting(
        path: str, default: float, low: float, high: float | None = None, low_open: bool = False
    ) -> np.ndarray:
        if cfg.control is None:
            return np.full(pv.P, default)
        return _per_design(pv, path, low, high, low_open)

    def corner(name: str, damper, parameter) -> np.ndarray:
        if damper.kind == "passive" or parameter.name not in LAWS[damper.law].parameters:
            return np.full(pv.P, parameter.default)
        return _per_design(
            pv,
            f"vehicle.corners.{name}.damper.{parameter.name}",
            parameter.low,
            parameter.high,
            parameter.low_open,
        )

    laws: list[str | None] = []
    c_min: list[np.ndarray] = []
    c_max: list[np.ndarray] = []
    parameters: dict[str, list[np.ndarray]] = {name: [] for name in PARAMETERS}
    for name, damper in zip(model.corners, dampers):
        if damper.kind == "passive":
            c = _per_design(pv, f"vehicle.corners.{name}.damper.c", 0.0)
            laws.append(None)
            c_min.append(c)
            c_max.append(c)
        else:
            laws.append(damper.law)
            lo = _per_design(pv, f"vehicle.corners.{name}.damper.c_min", 0.0)
            hi = _per_design(pv, f"vehicle.corners.{name}.damper.c_max", 0.0)
            if np.any(hi < lo):
                raise ConfigError(
                    f"params: vehicle.corners.{name}.damper.c_max: must be at "
                    f"least c_min (designs {np.flatnonzero(hi < lo)[:5].tolist()})"
                )
            c_min.append(lo)
            c_max.append(hi)
        for parameter in PARAMETERS.values():
            parameters[parameter.name].append(corner(name, damper, parameter))

    def stack(values: list[np.ndarray]) -> np.ndarray:
        return np.stack(values, axis=1)[:, None, :]

    lag = setting("control.actuator_lag", 0.0, 0.0)[:, None, None]
    threshold, settings = _threshold(cfg, pv, control, laws, len(model.corners))
    return SemiActiveController(
        model,
        laws,
        stack(c_min),
        stack(c_max),
        {name: stack(values) for name, values in parameters.items()},
        sim.dt,
        int(round(ratio)),
        sim.n_steps,
        lag,
        threshold,
        **settings,
    )
