"""Stationary statistics of linear designs on ISO 8608 roads: ``simulation.method: spectral``.

For a model that is linear (no Duffing term, no tyre lift-off, no semi-active controller, a
linear seat such as PS) on an ISO 8608 road, each response is a linear filter of the road,
and its stationary variance is the integral of the road's spectrum through the frequency
response (the Wiener-Khinchin relation):

    σ_y² = Σ_tracks ∫ G_z(f) |Σ_i H_y,i(f) e^{-j2πf τ_i}|² df,    G_z(f) = G_d(f / V) / V,

with ``G_d(n) = G_d(n0) (n / n0)^-w`` (Eq 2.93) at the level the road's ``convention`` gives
(:func:`suspopt.road.iso8608_level`), over the road's band ``V n_min .. V n_max`` [Hz] (the
time-domain road's band), ``H_y,i`` the response of signal ``y`` to wheel ``i``'s road
height, ``τ_i = d_i / V`` its wheelbase delay (an exact phase here, where a Lyapunov form
would need an approximation), and one track (``identical``) or two (``independent``: the
right and the left wheels each on their own realisation; a ``*_only`` flat side contributes
nothing). The ISO 2631 weighted r.m.s. multiplies the integrand by ``|W(f)|²``, the
weighting's exact analogue response (:func:`suspopt.metrics.iso2631.weighting_response`).

The frequency responses of the DOFs come from the element network's linear matrices
(:meth:`suspopt.network.LinearModel.modal_response`: one eigen-decomposition per design,
then a few products per frequency), batched over designs and frequencies; each signal's response is the one signal table's computation
(:class:`suspopt.result.Result`) applied to the complex amplitudes (the signal of the
response minus the signal of rest, so that a static part such as the tyre's static load
drops out). The integral is Simpson's rule over ``ln f`` on a grid of frequencies equally spaced in
``ln f``, refined by adding the midpoints until no value of a design changes by more than
:data:`TOLERANCE` relative (from :data:`FIRST_POINTS` to at most :data:`MAX_POINTS` points;
each finer grid is computed for the designs not yet converged alone); each design keeps the
values of the grid where it converged, and one that has not converged
at the most points is a failed design (NaN), as a diverged one is in time.

Metrics with a stationary closed form: ``var``, ``std``, ``rms`` (the response has zero
mean: ``rms = std``, ``mean = 0``), ``rms_weighted``, ``dissipated_power`` (the mean of
``F_C ṠT``: the real part of the cross-spectrum of the damper force and the travel rate,
integrated; Eq 2.92 for a stationary run) and ``dynamic_tyre_load`` (the tyre force's
standard deviation over the static load); every other metric (maxima, VDV, MTVV, crest
factor, switch counts, transient and derived metrics) needs a time history and is bad input
under this method. ``simulate`` integrates in time whatever the method: the method applies
to objectives and constraints (``optimise``, ``kesort``, ``analyse``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .config import Config
from .config.road import Iso8608Road

__all__ = ["METRICS", "reduce", "check", "TOLERANCE", "FIRST_POINTS", "MAX_POINTS"]

#: The metrics this method gives.
METRICS = ("var", "std", "rms", "mean", "rms_weighted", "dissipated_power", "dynamic_tyre_load")
#: Largest relative change of any value when the frequency grid is doubled.
TOLERANCE = 1e-6
#: Frequencies of the first grid, and the most of the last (each grid adds the midpoints).
FIRST_POINTS = 129
MAX_POINTS = 65537
#: Frequencies whose responses are computed at a time (bounds the memory of a batch).
BLOCK = 256
#: Most memory [bytes] a refinement's arrays take at a time: beyond it the designs not yet
#: converged are refined in parts (the values are the same bits).
REFINE_BYTES = 1 << 30
#: ISO 8608's reference spatial frequency n0 [cycles/m].
_N0 = 0.1


def _nonlinear(cfg: Config, model, controller, network) -> tuple[tuple, str] | None:
    """``(config key, why)`` when the run is not linear on a random road, else None."""
    from .checks import nonlinear_part

    if cfg.road.kind != "iso8608" and controller is None:
        return ("road", "kind"), f"road kind {cfg.road.kind!r} is not a random ISO 8608 road"
    return nonlinear_part(cfg, model, controller, network)


def check(cfg: Config, specs: Sequence[tuple[Any, tuple]]) -> None:
    """ConfigError (with the YAML line) when ``cfg`` cannot be evaluated by this method:
    a non-linear model or road (naming the key that makes it so) or a metric of
    ``specs`` (``(spec, its location in the config)``) without a stationary closed form."""
    from .checks import full_network
    from .simulation import prepare

    for spec, loc in specs:
        if spec.metric is not None and spec.metric not in METRICS:
            raise cfg.error(
                loc + ("metric",),
                f"{spec.metric} needs a time history and has no stationary closed form under "
                f"simulation.method spectral (it gives {', '.join(METRICS)}); use method time",
            )
    bounds = {v.path: np.array([v.lower, v.upper]) for v in cfg.design_variables}
    _, model, controller, attachments = prepare(cfg, bounds or None)
    found = _nonlinear(cfg, model, controller, full_network(model, attachments))
    if found is not None:
        key, why = found
        raise cfg.error(
            key, f"simulation.method spectral needs a linear model on a random road: {why}"
        )


def _tracks(cfg: Config, model) -> list[np.ndarray]:
    """Per track, which wheels ride on it (N,) as 0/1."""
    on_road = np.array(
        [(cfg.road.tracks, side) not in {("right_only", "left"), ("left_only", "right")}
         for side in model.sides], dtype=float
    )  # fmt: skip
    if cfg.road.tracks != "independent":
        return [on_road]
    sides = np.array(model.sides)
    return [on_road * (sides == "right"), on_road * (sides == "left")]


class _Linear:
    """What the responses of a batch need once: the designs, the model and its attachments,
    the network's linear matrices and its assembly."""

    def __init__(self, cfg: Config, pv, model, attachments):
        from .checks import full_network
        from .network import Assembled

        self.cfg, self.pv, self.model, self.attachments = cfg, pv, model, attachments
        network = full_network(model, attachments)
        self.n, self.linear, self.asm = network.n, network.linear_model(), Assembled(network, pv.P)
        self.form = self.linear.modal_form()
        self.rest: dict[str, np.ndarray] = {}  # each signal at rest (P, 1)

    def subset(self, keep: np.ndarray) -> _Linear:
        """The same for the designs ``keep`` (a mask over the batch) alone."""
        from .simulation import prepare

        pv, model, _, attachments = prepare(
            self.cfg, {k: v[keep] for k, v in self.pv.params.items()}
        )
        part = _Linear(self.cfg, pv, model, attachments)
        part.rest = {name: value[keep] for name, value in self.rest.items()}
        return part


def _phasors(system: _Linear, f, q, road):
    """The :class:`~suspopt.result.Result` whose "samples" are the complex amplitudes at
    frequencies ``f``: DOF amplitudes ``q (n, P, F)`` and the wheels' road ``(N, F)``."""
    from .result import Result

    jw = 2j * math.pi * f
    return Result(
        config=system.cfg, model=system.model, time=f,
        states=np.concatenate([q, jw * q]), accelerations=jw**2 * q,
        road=road[:, None, :], road_vel=jw * road[:, None, :],
        diverged_at=np.full(system.pv.P, np.nan), designs=dict(system.pv.params),
        _assembled=system.asm, attachments=tuple(system.attachments),
    )  # fmt: skip


def _responses(system: _Linear, f, names) -> dict[str, list[np.ndarray]]:
    """Each signal's complex response to each track's road (P, F) at frequencies ``f``: the
    signal of the motion less the signal of rest (its static part, the same at every
    frequency: computed once, at one frequency)."""
    cfg, model = system.cfg, system.model
    delay = np.exp(-2j * math.pi * f[:, None] * model.offsets[None, :] / cfg.road.speed)
    missing = [name for name in names if name not in system.rest]
    if missing:
        zero = np.zeros((system.n, system.pv.P, 1), complex)
        rest = _phasors(system, f[:1], zero, np.zeros((model.offsets.size, 1)))
        system.rest.update({name: rest.signals[name] for name in missing})
    out: dict[str, list[np.ndarray]] = {name: [] for name in names}
    for wheels in _tracks(cfg, model):
        inputs = delay * wheels[None, :]  # (F, N)
        q = np.moveaxis(system.linear.modal_response(f, inputs, system.form), -1, 0)
        moving = _phasors(system, f, q, inputs.T)
        for name in names:
            out[name].append(moving.signals[name] - system.rest[name])
    return out


def _integrands(system: _Linear, requests, f: np.ndarray) -> dict:
    """Each requested variance's integrand over ``ln f``, ``f G_z(f) |W|² Σ_tracks |H|²``,
    (P, F), at frequencies ``f`` (in blocks of :data:`BLOCK` frequencies)."""
    from .metrics.iso2631 import weighting_response
    from .road import iso8608_level

    road = system.cfg.road
    assert isinstance(road, Iso8608Road)  # (check() said so)
    names = sorted({k for spec, ns in requests for n in ns for k in _reads(spec, n)})
    out: dict = {(id(spec), n): [] for spec, ns in requests for n in ns}
    for start in range(0, f.size, BLOCK):
        fb = f[start : start + BLOCK]
        psd = iso8608_level(road) * (fb / road.speed / _N0) ** (-road.waviness) / road.speed
        responses = _responses(system, fb, names)
        for spec, ns in requests:
            weight = psd * fb
            if spec.metric == "rms_weighted":
                weight = weight * np.abs(weighting_response(fb, spec.weighting)) ** 2
            for name in ns:
                first, second = _reads(spec, name)[0], _reads(spec, name)[-1]
                cross = sum(
                    (a * np.conj(b)).real for a, b in zip(responses[first], responses[second])
                )
                out[(id(spec), name)].append(cross * weight)
    return {key: np.concatenate(parts, axis=-1) for key, parts in out.items()}


def _bytes(P: int, points: int, values: int) -> float:
    """The most memory [bytes] the integrands of ``values`` values over ``points``
    frequencies for P designs take while refined (the coarser grid's, the midpoints' and
    the finer grid's at once) with one block's responses."""
    return 8.0 * P * (2.5 * points * values + 40 * BLOCK)


def _check_memory(cfg: Config, P: int, points: int, values: int) -> None:
    """ConfigError (at ``simulation.method``) when the integrands of ``values`` values over
    ``points`` frequencies for P designs (:func:`_bytes`) exceed the memory limit
    (:func:`suspopt.memory.check`)."""
    from . import memory

    memory.check(
        _bytes(P, points, values),
        f"the spectral integral over {points} frequencies for {P} designs",
        "narrow the road's band (n_min, n_max), evaluate fewer designs at once or use method time",
        cfg,
        ("simulation", "method"),
    )


def _reads(spec, name: str) -> list[str]:
    """The signals whose cross-spectrum gives ``spec`` on ``name``: the signal itself (its
    variance), or for the dissipated power the travel rate and the damper force of the
    corner (the mean of their product)."""
    if spec.metric == "dissipated_power":
        return [name, f"damper_force.{name.rsplit('.', 1)[1]}"]
    return [name]


def _simpson(y: np.ndarray, step: float) -> np.ndarray:
    """Simpson's rule over the last axis (an odd number of equally spaced points)."""
    return step / 3.0 * (y[..., 0] + y[..., -1] + 4.0 * y[..., 1:-1:2].sum(-1)
                         + 2.0 * y[..., 2:-1:2].sum(-1))  # fmt: skip


def _converged(P: int, integrands: dict, system, requests, band, points: int):
    """Each value's variance (P,) from its integrands on ``points`` frequencies over ``band``
    (``ln f`` from, to), the grid refined by its midpoints until, design by design, no value
    changes by more than :data:`TOLERANCE` relative: a design's variances are those of the
    grid where it converged, whatever its batch needs, and NaN (a failed design, as a
    diverged one) where it has not converged at :data:`MAX_POINTS` frequencies (a mode
    damped so lightly that its resonance is narrower than the grid: 1e-300 N s/m at a
    damper gave an error for the whole batch before). Each finer grid is computed for the
    designs not yet converged alone (the whole batch was refined until its last design
    converged: one such design made a batch up to 500 times dearer), and for as many of
    them at a time as fit in :data:`REFINE_BYTES` (:func:`_refine`)."""
    low, high = band
    variances = {k: _simpson(y, (high - low) / (points - 1)) for k, y in integrands.items()}
    final = {k: np.full(P, np.nan) for k in integrands}
    _refine(final, (np.arange(P), system, integrands, variances), requests, band, points)
    return final


def _refine(final: dict, part: tuple, requests, band, points: int) -> None:
    """Refine the designs of ``part``: ``(left, system, integrands, variances)``, their
    indices in the batch and their model, integrands and variances alone, whose grid has
    ``points`` frequencies; write each design's variances into ``final`` where it converges.
    When the next grid's arrays for them would take more than :data:`REFINE_BYTES` (or half
    of ``--max-memory``), they are refined in parts, each as many designs as fit in that at
    the finest grid: a design's values do not depend on its batch mates, so the bits are
    the same, and the memory stays bounded (2000 designs that never converge took 12 GB
    at the finest grid before)."""
    from . import memory

    low, high = band
    left, system, integrands, variances = part
    cap = memory.explicit_limit()
    budget = REFINE_BYTES if cap is None else min(REFINE_BYTES, cap // 2)
    while left.size and points < MAX_POINTS:
        if left.size > 1 and _bytes(left.size, 2 * points - 1, len(integrands)) > budget:
            width = max(1, int(budget // _bytes(1, MAX_POINTS, len(integrands))))
            which = np.arange(left.size) // width
            parts = [_part(which == i, *part) for i in range(which[-1] + 1)]
            integrands.clear()  # (the parts hold copies: freed here)
            variances.clear()
            while parts:  # each part fits at the finest grid, and is freed once refined
                _refine(final, parts.pop(), requests, band, points)
            return
        points = 2 * points - 1  # the midpoints added
        _check_memory(system.cfg, left.size, points, len(integrands))
        added = _integrands(system, requests, np.exp(np.linspace(low, high, points)[1::2]))
        change = np.zeros(left.size)
        for key, y in integrands.items():
            both = np.empty(y.shape[:-1] + (points,))
            both[..., 0::2], both[..., 1::2] = y, added[key]
            integrands[key] = both
            finer = _simpson(both, (high - low) / (points - 1))
            scale = np.maximum(np.abs(finer), 1e-300)
            with np.errstate(invalid="ignore"):
                step = np.abs(finer - variances[key]) / scale
            change = np.maximum(change, np.where(np.isnan(step), np.inf, step))
            variances[key] = finer
        now = change <= TOLERANCE
        for key in integrands:
            final[key][left[now]] = variances[key][now]
        if now.all():
            return
        if now.any():  # (the arrays of ``part`` are those just refined)
            part = _part(~now, *part)
            left, system, integrands, variances = part


def _part(keep: np.ndarray, left, system, integrands: dict, variances: dict) -> tuple:
    """The designs ``keep`` (a mask) of a refinement's ``left, system, integrands,
    variances`` alone."""
    return (
        left[keep],
        system.subset(keep),
        {k: y[keep] for k, y in integrands.items()},
        {k: v[keep] for k, v in variances.items()},
    )


def reduce(
    cfg: Config, params: Mapping[str, Any] | None, requests: Sequence[tuple[Any, Sequence[str]]]
):
    """The metric specs of ``requests`` (``(spec, its signal names)``) of the designs
    ``params``, stationary, by the frequency integral (module docstring): a
    :class:`suspopt.streaming.Reduced` (engine ``spectral``)."""
    from .simulation import prepare
    from .streaming import Reduced

    pv, model, controller, attachments = prepare(cfg, params)
    road = cfg.road
    assert isinstance(road, Iso8608Road)  # (check() said so)
    low, high = math.log(road.speed * road.n_min), math.log(road.speed * road.n_max)
    points = FIRST_POINTS
    grid = np.exp(np.linspace(low, high, points))
    _check_memory(cfg, pv.P, points, sum(len(ns) for _, ns in requests))
    system = _Linear(cfg, pv, model, attachments)
    integrands = _integrands(system, requests, grid)
    variances = _converged(pv.P, integrands, system, requests, (low, high), points)
    from .metrics.stats import moment_value

    values = {}
    for spec, ns in requests:
        for name in ns:
            var = variances[(id(spec), name)]
            # the moments' state of a zero-mean response of variance var (a linear response
            # to a zero-mean road), made a statistic by the metrics' own arithmetic
            state = (1, np.zeros_like(var), var, np.nan, np.nan)
            if spec.metric == "dissipated_power":
                value = var
            elif spec.metric == "dynamic_tyre_load":
                corner = model.corners.index(name.rsplit(".", 1)[1])
                value = moment_value("std", state) / model.static_tyre_load[:, 0, corner]
            else:
                value = moment_value("std" if spec.metric == "rms_weighted" else spec.metric, state)
            values[(id(spec), name)] = value
    from .result import signal_table

    return Reduced(
        model, signal_table(model, {}, attachments), values, np.full(pv.P, np.nan), "spectral"
    )
