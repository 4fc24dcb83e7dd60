"""The control laws of a semi-active damper (Sec 2.1.6, Sec 4.4), each one :class:`Law`.

Signs follow the project's travel ``ST = z_s - z_u`` (extension positive, Eq 2.3), so the
travel rate is ``ṠT = ż_s - ż_u`` and the damper force ``F_C = c ṠT`` (Eq 2.32) pushes the
body down and the wheel up while the damper extends. At each corner ``i``, ``ż_s`` and
``z̈_s`` are the body's vertical velocity and acceleration *at the corner*,
``heave + y_i roll - x_i pitch`` (so on HC1, HC2 and FC the roll and pitch enter every law,
Sec 3.2.2), ``ż_u`` is the corner's wheel velocity, and ``ṠT`` comes from the travel map.

Every law compares an *operational condition* ``X`` with a threshold ``T`` (0 for the thesis's
base laws, Eq 2.33; the CDF strategy's ``T_A``/``T_B`` otherwise, Eq 4.2-4.4). When the law
calls for its stiff state the damper takes ``C_max`` (on-off laws) or a coefficient clipped to
``[C_min, C_max]`` (continuous laws); otherwise ``C_min``. At ``X = T`` exactly the damper is
soft, as Eq 2.33, 2.36 and 2.39 write.

==========  =======================================  ==================  =========================
law         condition X                              stiff when          stiff coefficient
==========  =======================================  ==================  =========================
sh_2        ṠT ż_s  (Eq 2.34, 4.3)                   X > T               C_max
sh_l        ṠT ż_s  (Eq 2.35)                        X > T               clip(α C_max +
                                                                         (1 - α) C_max ż_s / ṠT)
add         ṠT z̈_s  (Eq 2.36)                        X > T               C_max
sh_add_1    ṠT ż_s if S <= 0, else ṠT z̈_s / α_c      X > T               C_max
            (Eq 2.37)
sh_add_2    S = z̈_s² - α_c² ż_s²  (Eq 2.39, 4.4)     X < T               C_max
groundhook  -ṠT ż_u                                  X > T               C_max
hybrid      ṠT (β σ_sky + (1 - β) σ_gnd)             X > T               clip(C_max X / ṠT²)
==========  =======================================  ==================  =========================

``S = z̈_s² - α_c² ż_s²`` is the frequency-range selector with the crossover ``α_c`` in rad/s
(``crossover_frequency``; the thesis prints ``ż_s²`` for ``z̈_s²`` in places, slip:
docs/thesis-slips.md#eq-237).

- **SH-L** (Eq 2.35) with ``α`` = ``linear_weight``: the printed coefficient is unbounded as
  ``ṠT -> 0``; a damper cannot exceed its range, so it is clipped to ``[C_min, C_max]`` (as in
  Savaresi et al.'s linear approximation of the skyhook). With ``α = 1`` it is ``C_max``: SH-2.
- **SH-ADD-1** (Eq 2.37): the SH-2 rule in the low-frequency range (``S <= 0``), the ADD rule
  above it. Deviation: Eq 2.38 prints ``ṠT ż_s < 0`` as the soft condition of the high range;
  Eq 2.37 (and the law's source, Savaresi and Spelta) uses ADD's ``ṠT z̈_s``, followed here.
  The high-range product is divided by ``α_c`` so that both ranges' conditions are in m²/s²
  and one threshold applies to both; at ``T = 0`` this is exactly Eq 2.37 (the sign is kept).
- **Groundhook** (the road-holding law named in Sec 4.4; Valášek et al., Koo et al.): the ideal
  damper between the wheel and the ground pushes the wheel with ``-c_g ż_u``; the real damper
  pushes it with ``+c ṠT``, which can match only when ``-ż_u ṠT > 0``: then ``C_max``.
- **Hybrid skyhook-groundhook** (Ahmadian and Koo): ``σ_sky = ż_s`` where ``ṠT ż_s > 0``,
  else 0; ``σ_gnd = -ż_u`` where ``-ṠT ż_u > 0``, else 0; the requested force
  ``C_max (β σ_sky + (1 - β) σ_gnd)`` (``β`` = ``skyhook_weight``, gain ``C_max``) is realised
  by the coefficient ``C_max X / ṠT²`` clipped to ``[C_min, C_max]``. ``β = 1`` is the
  continuous skyhook (SH-L with ``α = 0``), ``β = 0`` the continuous groundhook.

Where ``ṠT = 0`` the damper force is zero whatever the coefficient; the continuous laws then
take the ratio ``ż_s / ṠT`` (or ``X / ṠT²``) as 0.

**Adding a law** is adding one :class:`Law` to :data:`LAWS` (with any new :class:`Parameter`
in :data:`PARAMETERS`): the config (``vehicle...damper.law`` and its parameter fields,
:mod:`suspopt.config.vehicle`) and the controller (:mod:`suspopt.controller`) read
them from here. The compiled engine takes the samples of the laws it lists
(:data:`suspopt.integrator._kernel.CONTROL_LAWS`, with these same rules) and hands any other
law's back to the controller at each sample. This module imports nothing of the config.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

__all__ = ["Parameter", "Motion", "Law", "PARAMETERS", "LAWS", "law_condition", "stiff_coefficient"]


@dataclass(frozen=True)
class Parameter:
    """A law parameter, a field of the semi-active damper in the config: its range
    ``(low, high]`` or ``[low, high]`` (``low_open``), ``unit``, ``default`` (the value the
    controller holds at corners whose law does not take it) and ``description``."""

    name: str
    low: float
    high: float
    low_open: bool
    unit: str
    default: float
    description: str


@dataclass(frozen=True)
class Motion:
    """What a law reads at one sample, (P, 1, N) each: the travel rate ṠT, the body's
    velocity ż_s and acceleration z̈_s at the corner (None for laws that do not need it) and
    the wheel's velocity ż_u [m/s, m/s²], and the law parameters by name (each (P, 1, N))."""

    travel_vel: np.ndarray
    body_vel: np.ndarray
    wheel_vel: np.ndarray
    body_acc: np.ndarray | None
    parameters: Mapping[str, np.ndarray]


@dataclass(frozen=True)
class Law:
    """A control law (module docstring). ``rule(st, zs, zu, za, linear_weight,
    crossover_frequency, skyhook_weight)`` gives X in ``unit`` from the travel rate ṠT, the
    body's velocity ż_s and acceleration z̈_s at the corner and the wheel's velocity ż_u
    (arrays of one shape; ``za`` is None or unused for a law that does not read it) and the
    :data:`PARAMETERS` in their order; ``stiff_below``: stiff when X < T (else X > T);
    ``needs_acceleration``: reads z̈_s; ``parameters``: the names of the parameters it takes;
    ``stiff_rule(c_min, c_max, st, zs, x, linear_weight, crossover_frequency,
    skyhook_weight)`` the coefficient of its stiff state [N s/m], None for ``C_max`` (an on-off
    law); ``equation`` where the thesis states it. The rules use only arithmetic,
    ``np.where`` and ``np.clip`` on arrays, so the compiled engine runs the same functions
    (:mod:`suspopt.integrator.compiled`)."""

    name: str
    rule: Callable[..., np.ndarray]
    unit: str
    equation: str
    stiff_below: bool = False
    needs_acceleration: bool = False
    parameters: tuple[str, ...] = ()
    stiff_rule: Callable[..., np.ndarray] | None = None

    @property
    def continuous(self) -> bool:
        """Whether the stiff coefficient varies inside ``[C_min, C_max]``."""
        return self.stiff_rule is not None

    def condition(self, m: Motion) -> np.ndarray:
        """X at the sample ``m``."""
        values = [m.parameters[name] for name in PARAMETERS]
        return self.rule(m.travel_vel, m.body_vel, m.wheel_vel, m.body_acc, *values)

    def stiff(self, c_min, c_max, m: Motion, condition: np.ndarray) -> np.ndarray:
        """The stiff coefficient at the sample ``m`` with condition X (``C_max`` for an
        on-off law)."""
        if self.stiff_rule is None:
            return c_max
        values = [m.parameters[name] for name in PARAMETERS]
        return self.stiff_rule(c_min, c_max, m.travel_vel, m.body_vel, condition, *values)


PARAMETERS: dict[str, Parameter] = {
    p.name: p
    for p in (
        Parameter(
            "linear_weight",
            0.0,
            1.0,
            False,
            "-",
            1.0,
            "SH-L tuning parameter alpha of Eq 2.35 in [0, 1] [-]; 1 gives SH-2",
        ),
        Parameter(
            "crossover_frequency",
            1e-3,
            1e5,
            False,
            "rad/s",
            1.0,
            "frequency-range selector alpha of Eq 2.37-2.39 [rad/s] (the thesis uses 39 "
            "rad/s, about 6 Hz)",
        ),
        Parameter(
            "skyhook_weight",
            0.0,
            1.0,
            False,
            "-",
            1.0,
            "share beta of the skyhook term in the hybrid law in [0, 1] [-]; 1 is pure "
            "skyhook, 0 pure groundhook",
        ),
    )
}


def _skyhook(st, zs, zu, za, linear_weight, crossover, skyhook_weight):
    return st * zs


def _add(st, zs, zu, za, linear_weight, crossover, skyhook_weight):
    return st * za


def _selector(st, zs, zu, za, linear_weight, crossover, skyhook_weight):
    """``S = z̈_s² - α_c² ż_s²`` (Eq 2.37-2.39; slip: docs/thesis-slips.md#eq-237) [m²/s⁴]."""
    return za * za - crossover * crossover * (zs * zs)


def _sh_add_1(st, zs, zu, za, linear_weight, crossover, skyhook_weight):
    low = za * za - crossover * crossover * (zs * zs) <= 0  # (the selector S)
    return np.where(low, st * zs, st * za / crossover)


def _groundhook(st, zs, zu, za, linear_weight, crossover, skyhook_weight):
    return -(st * zu)


def _hybrid(st, zs, zu, za, linear_weight, crossover, skyhook_weight):
    """``ṠT (β σ_sky + (1 - β) σ_gnd)``."""
    sky = np.where(st * zs > 0, zs, 0.0)
    ground = np.where(st * zu < 0, -zu, 0.0)
    return st * (skyhook_weight * sky + (1.0 - skyhook_weight) * ground)


def _sh_l_coefficient(c_min, c_max, st, zs, x, linear_weight, crossover, skyhook_weight):
    """The clipped SH-L coefficient (Eq 2.35); the ratio ż_s / ṠT taken as 0 where ṠT = 0."""
    moving = st != 0
    ratio = np.where(moving, zs / np.where(moving, st, 1.0), 0.0)
    return np.clip(linear_weight * c_max + (1.0 - linear_weight) * c_max * ratio, c_min, c_max)


def _hybrid_coefficient(c_min, c_max, st, zs, x, linear_weight, crossover, skyhook_weight):
    """``clip(C_max X / ṠT²)``: the coefficient that realises the hybrid force (X / ṠT² taken
    as 0 where ṠT = 0)."""
    square = st * st
    moving = square != 0
    return np.clip(c_max * np.where(moving, x / np.where(moving, square, 1.0), 0.0), c_min, c_max)


LAWS: dict[str, Law] = {
    law.name: law
    for law in (
        Law("sh_2", _skyhook, "m^2/s^2", "Eq 2.34"),
        Law(
            "sh_l",
            _skyhook,
            "m^2/s^2",
            "Eq 2.35",
            parameters=("linear_weight",),
            stiff_rule=_sh_l_coefficient,
        ),
        Law("add", _add, "m^2/s^3", "Eq 2.36", needs_acceleration=True),
        Law(
            "sh_add_1",
            _sh_add_1,
            "m^2/s^2",
            "Eq 2.37",
            needs_acceleration=True,
            parameters=("crossover_frequency",),
        ),
        Law(
            "sh_add_2",
            _selector,
            "m^2/s^4",
            "Eq 2.39",
            stiff_below=True,
            needs_acceleration=True,
            parameters=("crossover_frequency",),
        ),
        Law("groundhook", _groundhook, "m^2/s^2", "Sec 4.4"),
        Law(
            "hybrid",
            _hybrid,
            "m^2/s^2",
            "Sec 4.4",
            parameters=("skyhook_weight",),
            stiff_rule=_hybrid_coefficient,
        ),
    )
}


def _motion(travel_vel, body_vel, wheel_vel, body_acc, **parameters) -> Motion:
    values = {
        name: np.asarray(parameters.get(name, p.default), dtype=float)
        for name, p in PARAMETERS.items()
    }
    return Motion(
        np.asarray(travel_vel),
        np.asarray(body_vel),
        np.asarray(wheel_vel),
        None if body_acc is None else np.asarray(body_acc),
        values,
    )


def law_condition(
    law: str,
    travel_vel: np.ndarray,
    body_vel: np.ndarray,
    wheel_vel: np.ndarray,
    body_acc: np.ndarray | None = None,
    **parameters,
) -> np.ndarray:
    """Operational condition ``X`` of ``law`` (table of the module docstring), in
    ``LAWS[law].unit``.

    ``travel_vel`` ṠT, ``body_vel`` ż_s (body at the corner), ``wheel_vel`` ż_u [m/s],
    ``body_acc`` z̈_s [m/s²] (laws add, sh_add_1, sh_add_2), the law's parameters by name
    (e.g. ``crossover_frequency`` α_c [rad/s], ``skyhook_weight`` β [-]; defaults of
    :data:`PARAMETERS` otherwise); any broadcastable shapes.
    """
    if law not in LAWS:
        raise ValueError(f"unknown control law {law!r}; known: {', '.join(LAWS)}")
    return LAWS[law].condition(_motion(travel_vel, body_vel, wheel_vel, body_acc, **parameters))


def stiff_coefficient(
    law: str, c_min, c_max, travel_vel, body_vel, condition, **parameters
) -> np.ndarray:
    """Coefficient [N s/m] of ``law`` in its stiff state: ``C_max`` for the on-off laws, the
    clipped SH-L (Eq 2.35) or hybrid coefficient for the continuous ones."""
    motion = _motion(travel_vel, body_vel, np.zeros(1), None, **parameters)
    return LAWS[law].stiff(c_min, c_max, motion, condition)
