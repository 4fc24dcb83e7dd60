"""The pre-run checks: what the config's types alone cannot check of a run, made by every
command that simulates and by ``validate`` (:mod:`suspopt.validation`, which adds the
checks of the optimisation), so that what ``validate`` accepts no other command rejects.

- :func:`check_steps`: the duration is a whole number of integration steps; the controller's
  and the output's sample intervals are whole multiples of ``dt``; the front wheels reach a
  bump within the run; every bump spans at least :data:`MIN_STEPS_PER_BUMP` steps and the
  shortest wave of a random road at least :data:`MIN_STEPS_PER_WAVE`; the output sample rate
  suits the ISO 2631 weightings of the metrics.
- :func:`stability_limit` and :func:`check_stability`: ``dt`` within classical RK4's
  stability limit for every mode of the linearised model (vehicle, seat and passenger).

Each raises :class:`~suspopt.config.ConfigError` naming the key, its line and the limit; one
that checks several things independent of each other (:func:`check_steps`,
:func:`suspopt.validation.check_config`) reports every problem it finds in it (``ConfigError.problems``).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from .config import Config
from .config.road import BumpHalfSine, BumpStep, Iso8608Road
from .errors import Problems
from .network import Network

__all__ = [
    "nonlinear_part",
    "check_exact",
    "stepped_road",
    "MIN_STEPS_PER_BUMP",
    "MIN_STEPS_PER_WAVE",
    "check_steps",
    "stability_limit",
    "check_stability",
    "full_network",
]

#: A bump (the time a wheel takes to cross it) must span this many integration steps: RK4
#: samples the road at half steps, and a half-sine crossed in 10 steps moves the peak body
#: acceleration of the Ch. 5 half car by under 1 % against dt/10.
MIN_STEPS_PER_BUMP = 10
#: The shortest wave of a random road (period ``1/(n_max V)``) must span this many steps,
#: 8 half-step samples of the road per period.
MIN_STEPS_PER_WAVE = 4
#: Relative slack on "a whole number of steps" (durations written in decimal, such as 7.2 s
#: at dt = 1 ms, are not exact binary multiples).
_WHOLE = 1e-9


def _whole(ratio: float) -> bool:
    return abs(ratio - round(ratio)) <= _WHOLE * max(1.0, ratio)


def _resolved(
    cfg: Config, found: Problems, span: float, steps: int, what: str, tail: str = ""
) -> None:
    """A problem on ``simulation.dt`` unless ``span`` [s] (``what``, formatted with it) spans
    at least ``steps`` steps."""
    dt = cfg.simulation.dt
    if span < steps * dt * (1 - _WHOLE):
        found.add(
            ("simulation", "dt"),
            f"{dt:g} s steps over {what.format(span)} must span at least {steps} steps; "
            f"use dt <= {span / steps:.3g} s{tail}",
        )


def check_steps(cfg: Config) -> None:
    """The time grid, the road's features against ``dt`` and the metrics' sample rate (module
    docstring); ConfigError with every problem of them."""
    from .metrics.iso2631 import MIN_SAMPLE_RATE
    from .specs import METRICS

    sim, road = cfg.simulation, cfg.road
    found = cfg.problems()
    if not _whole(sim.duration / sim.dt):
        found.add(
            ("simulation", "duration"),
            f"{sim.duration:g} s is not a whole number "
            f"of steps dt = {sim.dt:g} s ({sim.duration / sim.dt:.6g} steps); "
            f"give a multiple of dt",
        )
    if isinstance(road, (BumpStep, BumpHalfSine)):
        if road.start >= sim.duration:
            found.add(
                ("road", "start"),
                f"the bump starts at {road.start:g} s, after "
                f"the run ends (simulation.duration = {sim.duration:g} s)",
            )
        crossing = road.length / road.speed
        what = "the bump: a wheel crosses it in {:.4g} s (road.length/road.speed), which"
        _resolved(cfg, found, crossing, MIN_STEPS_PER_BUMP, what)
    if isinstance(road, Iso8608Road):
        period = 1.0 / (road.n_max * road.speed)
        what = "the road's shortest wave: 1/(n_max V) = {:.4g} s"
        _resolved(cfg, found, period, MIN_STEPS_PER_WAVE, what, " or a lower road.n_max")
    rate = sim.output_rate
    specs: list[tuple[tuple, Any]] = [(("metrics", i), spec) for i, spec in enumerate(cfg.metrics)]
    if cfg.objectives is not None:
        specs += [(("objectives", "main", i), s) for i, s in enumerate(cfg.objectives.main)]
        specs += [
            (("objectives", "supplementary", i), s)
            for i, s in enumerate(cfg.objectives.supplementary)
        ]
    specs += [(("constraints", i), spec) for i, spec in enumerate(cfg.constraints)]
    for loc, spec in specs:
        if (
            spec.metric is not None
            and METRICS[spec.metric].kind == "iso2631"
            and rate < MIN_SAMPLE_RATE
        ):
            found.add(
                loc + ("metric",),
                f"{spec.metric} needs signals sampled at "
                f"{MIN_SAMPLE_RATE:g} Hz or more; simulation.output_dt gives "
                f"{rate:.4g} Hz",
            )
    found.raise_if_any()


def full_network(model, attachments) -> Network:
    """The vehicle's network with its attachments (seat and passenger) mounted."""
    network = model.network
    for att in attachments:
        network = network.attach(att.network, model.point_map(*att.point), att.coupled)
    return network


#: Directions per pass of :func:`_rk4_radius` (its grid takes 300 complex numbers each).
_RADIUS_CHUNK = 20_000


def nonlinear_part(cfg: Config, model, controller, network) -> tuple[tuple, str] | None:
    """``(config key, why)`` when the run of ``model`` (``network`` its whole network) is not
    linear for the chosen designs (a controller, a tyre that lifts off, a non-linear element),
    else None."""
    if controller is not None:
        return ("control",), "a semi-active controller switches the damping"
    if cfg.vehicle.tyre_lift_off:
        return ("vehicle", "tyre_lift_off"), "a tyre that lifts off is not linear"
    for g in network.groups:
        if g.extra is None:
            continue
        law = g.extra_law
        if law is not None and law[0] == "poly3" and all(not np.any(p) for p in law[1]):
            continue  # a cubic term of zero in every design
        if g.name == "suspension" and law is not None:
            corner = model.corners[int(np.flatnonzero(np.any(law[1][2] != 0, axis=(1, 2)))[0])]
            path = f"vehicle.corners.{corner}.spring.cubic"
            where = [i for i, v in enumerate(cfg.design_variables) if v.path == path]
            key = ("design_variables", where[0]) if where else tuple(path.split("."))
            return key, f"the Duffing spring {path} > 0 is not linear"
        if cfg.seat is not None:
            return ("seat", "kind"), f"the {cfg.seat.kind} seat's mechanism is not linear"
        return ("vehicle",), f"the non-linear part of {g.name!r} is not linear"
    return None


def check_exact(cfg: Config, prepared) -> None:
    """ConfigError at ``simulation.method`` when it is ``exact`` and the run of ``prepared``
    (designs, model, controller, attachments) is not linear (:func:`nonlinear_part`)."""
    if cfg.simulation.method != "exact":
        return
    from .road import road_edges

    _, model, controller, attachments = prepared
    found = nonlinear_part(cfg, model, controller, full_network(model, attachments))
    if found is not None:
        raise cfg.error(
            ("simulation", "method"),
            f"exact needs a linear model without a controller: {found[1]}; use method time",
        )
    if road_edges(cfg.road, model.offsets, model.sides)[0].size:
        raise stepped_road(cfg, cfg.road.kind)


def stepped_road(cfg: Config, kind: str):
    """The error of ``simulation.method: exact`` on a road of ``kind`` with steps."""
    return cfg.error(
        ("simulation", "method"),
        f"exact needs a road without steps between the integration steps; road kind "
        f"{kind!r} has some; use method time",
    )


def _rk4_radius(direction: np.ndarray) -> np.ndarray:
    """For unit complex numbers ``direction`` in the closed left half-plane, the largest
    ``r`` with ``|R(r d)| <= 1`` on the whole segment from 0, ``R(z) = 1 + z + z^2/2 + z^3/6
    + z^4/24`` RK4's amplification factor (2.785 on the negative real axis, 2 sqrt 2 on the
    imaginary one)."""

    def grows(r):
        z = r * direction
        return np.abs(1 + z * (1 + z * (1 / 2 + z * (1 / 6 + z / 24)))) > 1 + 1e-12

    if direction.size > _RADIUS_CHUNK:  # the grid below is (300, size): bounded memory
        return np.concatenate(
            [
                _rk4_radius(direction[i : i + _RADIUS_CHUNK])
                for i in range(0, direction.size, _RADIUS_CHUNK)
            ]
        )
    grid = np.linspace(0.0, 3.0, 301)[1:, None]
    first = np.argmax(grows(grid), axis=0)  # the first radius that grows
    low, high = np.where(first > 0, grid[first - 1, 0], 0.0), grid[first, 0]
    for _ in range(40):
        mid = 0.5 * (low + high)
        up = grows(mid)
        low, high = np.where(up, low, mid), np.where(up, mid, high)
    return low


def stability_limit(
    network: Network, damping_rows: dict[str, np.ndarray] | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The largest RK4 step [s] of each design of ``network`` linearised about rest, with the
    frequency [Hz] and the index of the mode that sets it: ``(dt_max (P,), f (P,), dof (P,))``
    (``dof`` the DOF with most of that mode's kinetic energy).

    The eigenvalues ``λ`` of ``[[0, I], [-M^-1 K, -M^-1 C]]`` must satisfy ``|R(λ dt)| <= 1``
    (Hairer & Wanner, Solving ODEs II, Sec IV.2). Modes that grow by themselves (a real part
    above rounding) are the physics, not the step, and are left out. ``damping_rows`` maps a
    group's name to coefficients (m, P, 1) that replace its damping (a semi-active damper at
    ``c_max``). Non-linear parts enter by their slope at rest only: a hardening Duffing
    spring at large travel, or a tyre in the air, moves the limit.
    """
    if damping_rows:
        network = replace(
            network,
            groups=tuple(
                replace(g, damping=damping_rows[g.name]) if g.name in damping_rows else g
                for g in network.groups
            ),
        )
    lin = network.linear_model()
    P, n = lin.mass.shape
    inverse = 1.0 / lin.mass
    A = np.zeros((P, 2 * n, 2 * n))
    A[:, :n, n:] = np.eye(n)
    A[:, n:, :n] = -inverse[:, :, None] * lin.stiffness
    A[:, n:, n:] = -inverse[:, :, None] * lin.damping
    # a design without a static equilibrium (an infeasible seat geometry: NaN) has no modes;
    # the optimiser's constraints deal with it
    sound = np.isfinite(A).all(axis=(1, 2))
    A[~sound] = 0.0
    with np.errstate(all="ignore"):
        lam, vectors = np.linalg.eig(A)
        lam[~sound] = 0.0
        size = np.abs(lam)
        decaying = (lam.real <= 1e-9 * size) & (size > 0)
        direction = np.where(decaying, lam / np.where(size > 0, size, 1.0), -1.0)
        direction = np.where(direction.real > 0, 1j * np.sign(direction.imag), direction)
        limit = np.where(
            decaying,
            _rk4_radius(direction.reshape(-1)).reshape(lam.shape) / np.where(size > 0, size, 1.0),
            np.inf,
        )
    worst = np.argmin(limit, axis=1)
    rows = np.arange(P)
    energy = lin.mass * np.abs(vectors[rows, :n, worst]) ** 2
    return (
        limit[rows, worst],
        np.abs(lam[rows, worst].imag) / (2 * math.pi),
        np.argmax(energy, axis=1),
    )


def check_stability(
    cfg: Config, pv, model, attachments, loc: tuple = ("simulation", "dt"), what: str = ""
) -> None:
    """ConfigError when ``simulation.dt`` exceeds RK4's stability limit for some design of the
    assembled model (:func:`stability_limit`; semi-active dampers at ``c_min`` and at
    ``c_max``). ``pv`` holds the designs; ``what`` says which designs they are. None under
    ``simulation.method: exact``, whose steps have no stability limit."""
    from .network import parameter_rows

    if cfg.simulation.method == "exact":
        return
    network = full_network(model, attachments)
    cases: list[dict[str, np.ndarray] | None] = [None]  # (None: the dampers as built)
    corners = cfg.vehicle.corners
    if any(corners[c].damper.kind == "semi_active" for c in model.corners):
        stiff = np.stack(
            [
                pv.get(
                    f"vehicle.corners.{c}.damper."
                    f"{'c_max' if corners[c].damper.kind == 'semi_active' else 'c'}"
                )
                for c in model.corners
            ],
            axis=1,
        )
        cases.append({"suspension": parameter_rows(stiff)})
    dt = cfg.simulation.dt
    for case in cases:
        limit, frequency, dof = stability_limit(network, case)
        bad = np.flatnonzero(limit < dt)
        if bad.size:
            p = bad[np.argmin(limit[bad])]
            state = " with the dampers at c_max" if case else ""
            raise cfg.error(
                loc,
                f"{dt:g} s exceeds classical RK4's stability limit "
                f"{limit[p]:.3g} s for the fastest mode of the linearised model"
                f"{state} ({network.dof_names[dof[p]]}, {frequency[p]:.4g} Hz"
                f"{what}); use dt <= {0.9 * limit[p]:.2g} s",
            )
