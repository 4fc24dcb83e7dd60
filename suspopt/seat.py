"""Seat isolators PS and NSS1-NSS4 (Sec 2.2, Ch. 8) and the seated passenger (Sec 2.3).

Coordinates and signs. Displacements are vertical, upward +, and measured from static
equilibrium: ``z_s`` is the floor (the body at the seat's point), ``x`` the seat mass, ``y`` the
inner mass of NSS4. The mechanisms stand on the floor, so their forces act on the isolator
travel ``u = x - z_s`` (NSS4: ``u_0 + y - z_s``), as Eq 2.45, 2.52 and 2.58 do (Eq 2.43/2.44
and 2.49/2.51 print ``x``; slip: docs/thesis-slips.md#eq-243). The ``*_force`` functions return
the force of a
mechanism on the mass it carries, upward +: a positive slope is a negative stiffness.

Static equilibrium. Each isolator carries its load ``m g`` at ``u = 0`` (NSS4: ``u = u_0``):
``K_v X_ST = m g`` with the mechanism's force zero there (NSS1-NSS3, Sec 8.2.2) and
``K_S X_ST + F_0 = (m + m_d) g`` for NSS4 (Eq 2.64). The dynamic equations therefore hold the
springs' changes from that state only: every force is zero at ``q = 0`` with the floor at rest,
and ``m`` here is the whole load on the isolator, seat plus passenger.

Equations of motion (``u = x - z_s``; the passenger's pelvis link acts on the seat too):

- PS: ``m ẍ + C_v u̇ + K_v u = 0`` (Eq 2.40 with the seat's ``ẍ``; slip:
  docs/thesis-slips.md#eq-240);
- NSS1-NSS3: ``m ẍ + C_v u̇ + K_v u - f_N(u) = 0`` (Eq 2.44, 2.51, 2.57), ``f_N`` exact
  (Eq 2.43, 2.49, 2.56) or its 3rd-order series (Eq 2.45, 2.52; NSS3 derived here);
- NSS4: ``m ẍ + C_v (ẋ - ẏ) + K_S u + K_v (x - y) = 0`` and
  ``m_d ÿ - C_v (ẋ - ẏ) - K_v (x - y) - [F(u_0 + y - z_s) - F(u_0)] = 0`` (Eq 2.59-2.69,
  ``F = -f_N`` the mechanism's upward force, :func:`nss4_force`);
- passenger: Eq 2.70-2.77 rebuilt from the topology (slip: docs/thesis-slips.md#eq-270):
  seat - pelvis - abdomen -
  diaphragm - thorax - torso, back tied to pelvis and torso, head on back. Besides the index
  slips, Eq 2.75 prints the torso-back term with the wrong sign (``-k_4 (z_3 - z_2)`` would be
  a negative stiffness) and Eq 2.76 lacks the head's reaction ``-c_1 (ż_1 - ż_2) -
  k_1 (z_1 - z_2)`` on the back; the links here are equal and opposite on both parts.

The seat and its passenger form one :class:`SeatModel`, mounted on the vehicle by the
simulator: a :class:`suspopt.network.Network` (:func:`seat_network`) whose linear springs and
dampers are links over the nodes [floor, seat, (inner mass), passenger parts] and whose
mechanism (NSS1-NSS4) is one non-linear element between the floor and the mass it carries.
The linearised model (for transmissibility and modes) comes from that same network, with the
mechanism's slope at rest by complex-step differentiation, never from a second copy of the
equations.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .config import Config, ConfigError
from .network import Elements, Network, parameter_rows, shared_rows, widen
from .params import ParamView

__all__ = [
    "PASSENGER_PARTS", "SIGNAL_HEADS", "SeatModel", "Mechanism", "LinearSeat",
    "ps_static_deflection", "vertical_stiffness",
    "nss1_static_deflection", "nss1_force", "nss1_taylor",
    "nss2_static_deflection", "nss2_force", "nss2_taylor",
    "nss3_static_deflection", "nss3_force", "nss3_taylor", "nss3_contact_limit",
    "nss4_static_deflection", "nss4_force", "nss4_taylor",
    "build_seat", "build_attachments", "linearise", "base_transmissibility",
    "natural_frequencies", "seat_static_deflection", "seat_constraints", "CONSTRAINT_UNITS",
    "passenger_mass_change", "signal_units",
]

#: Body parts of the passenger, bottom to top (Fig. 2.14, Table 2.3).
PASSENGER_PARTS = ("pelvis", "abdomen", "diaphragm", "thorax", "torso", "back", "head")
#: The part (or the seat) each part's own k_i, c_i join it to (slip: docs/thesis-slips.md#eq-270).
_BELOW = {"pelvis": "seat", "abdomen": "pelvis", "diaphragm": "abdomen", "thorax": "diaphragm",
          "torso": "thorax", "back": "pelvis", "head": "back"}
#: First part of the names of seat and passenger signals.
SIGNAL_HEADS = ("seat",) + PASSENGER_PARTS
_UNITS = {"x": "m", "vel": "m/s", "acc": "m/s^2", "base": "m", "base_vel": "m/s",
          "base_acc": "m/s^2", "travel": "m", "travel_vel": "m/s", "travel_margin": "m",
          "inner_x": "m", "inner_acc": "m/s^2"}


def signal_units(name: str) -> str:
    """SI unit of a seat or passenger signal (``seat.acc``, ``head.x``, ...)."""
    return _UNITS[name.split(".", 1)[1]]


# --------------------------------------------------------------------------------------------
# Statics (Sec 8.2.2)

def vertical_stiffness(load_mass, static_deflection, gravity):
    """``K_v = m g / X_ST`` [N/m]: the vertical spring that carries the load at the static
    deflection (Hooke's law at equilibrium, Sec 2.2.2-2.2.4, 8.2.2)."""
    return load_mass * gravity / static_deflection


def ps_static_deflection(load_mass, stiffness, gravity):
    """PS static deflection ``X_ST = m g / K_v`` [m] (Eq 2.40 at rest)."""
    return load_mass * gravity / stiffness


def nss1_static_deflection(wall_distance, gamma):
    """NSS1 static deflection ``X_ST = sqrt(L_o² - a_o²)`` with ``L_o = a_o/γ`` [m]
    (Eq 2.42 at the unloaded position, Sec 8.2.2): the inclined springs are free there. NaN
    unless ``0 < γ < 1``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return wall_distance * np.sqrt(1.0 / gamma ** 2 - 1.0)


def nss2_static_deflection(wall_distance, spring_free_length, bar_length):
    """NSS2 static deflection ``X_ST = sqrt(b² - (a_o - L_o)²)`` [m] (Sec 2.2.3, 8.2.2);
    NaN where ``b <= |a_o - L_o|`` (no such geometry)."""
    with np.errstate(invalid="ignore"):
        return np.sqrt(bar_length ** 2 - (wall_distance - spring_free_length) ** 2)


def nss3_static_deflection(cam_radius, roller_radius, cam_offset):
    """NSS3 static deflection ``X_ST = sqrt((R + r)² - (d + r)²)`` [m] (Sec 2.2.4, 8.2.2);
    NaN where ``d > R``."""
    with np.errstate(invalid="ignore"):
        return np.sqrt((cam_radius + roller_radius) ** 2 - (cam_offset + roller_radius) ** 2)


def nss4_static_deflection(load_mass, inner_mass, support_stiffness, preload, gravity):
    """NSS4 static deflection of ``K_S``: ``X_ST = ((m + m_d) g - F_0) / K_S`` [m] (Eq 2.64).

    ``F_0`` is the mechanism's upward force on the inner mass at rest, ``nss4_force(u_0)``
    (Eq 2.61-2.65). Deviation: Eq 2.64 prints ``- f_N0`` with ``f_N0 = f_N(u_0)`` of Eq 2.65,
    whose sign is the opposite (Eq 2.60 puts ``+f_N`` on the left-hand side, so the force on
    ``m_d`` is ``-f_N``). Statics of ``m + m_d``: ``K_S X_ST + F_0 = (m + m_d) g``, so with
    ``u_0 > 0`` (hinge above the horizontal) the mechanism carries ``F_0 > 0`` of the load and
    ``K_S`` the rest. This is Eq 2.64 with ``f_N0`` read as the upward force.
    """
    return ((load_mass + inner_mass) * gravity - preload) / support_stiffness


# --------------------------------------------------------------------------------------------
# Mechanism forces (exact geometry) and their Taylor series

def _link_law(stiffness, offset, length) -> Callable[[np.ndarray], np.ndarray]:
    """``w -> 2 k (1 + c / sqrt(ℓ² - w²)) w``: two symmetric horizontal springs acting through
    a link whose vertical position is ``w`` and horizontal reach ``sqrt(ℓ² - w²)``, with
    ``c`` the spring's free length offset (NSS2, NSS3, NSS4 share this form). The constants are
    folded once, so the simulator evaluates it in six array operations."""
    a = 2.0 * stiffness
    b, square = a * offset, length * length
    return lambda w, out=None: np.multiply(a + b / np.sqrt(square - w * w), w, out=out)


def _carrella_law(stiffness, wall_distance, spring_free_length):
    """``u -> 2 K_h (L_o / sqrt(u² + a_o²) - 1) u`` (:func:`nss1_force`), constants folded."""
    a, b = -2.0 * stiffness, 2.0 * stiffness * spring_free_length
    square = wall_distance * wall_distance
    return lambda u, out=None: np.multiply(b / np.sqrt(u * u + square) + a, u, out=out)


def _link_series(rest, stiffness, offset, length):
    """Coefficients ``(k1, k2, k3)`` of :func:`_link_law` about ``w = rest``:
    ``F(rest + δ) - F(rest) = k1 δ + k2 δ² + k3 δ³ + O(δ⁴)``.

    With ``h(w) = w (ℓ² - w²)^(-1/2)``: ``h' = ℓ² D^(-3/2)``, ``h'' = 3 ℓ² w D^(-5/2)``,
    ``h''' = 3 ℓ² (ℓ² + 4 w²) D^(-7/2)``, ``D = ℓ² - w²``.
    """
    L2 = length * length
    D = L2 - rest * rest
    k1 = 2.0 * stiffness * (1.0 + offset * L2 * D ** -1.5)
    k2 = 3.0 * stiffness * offset * L2 * rest * D ** -2.5
    k3 = stiffness * offset * L2 * (L2 + 4.0 * rest * rest) * D ** -3.5
    return k1, k2, k3


def nss1_force(u, horizontal_stiffness, wall_distance, spring_free_length):
    """NSS1 (Carrella) mechanism force on the seat, ``f_N = 2 K_h (L_o / sqrt(u² + a_o²) - 1) u``
    [N] (Eq 2.41-2.43 in the travel ``u``; slip: docs/thesis-slips.md#eq-243).

    Each inclined spring runs from an anchor at horizontal distance ``a_o`` to the seat; its
    length is ``sqrt(u² + a_o²)``, its compression ``L_o`` minus that, and the vertical share of
    its force ``u / sqrt(u² + a_o²)``. Zero at ``u = 0`` (springs horizontal) and at
    ``u = X_ST`` (springs free).
    """
    return _carrella_law(horizontal_stiffness, wall_distance, spring_free_length)(u)


def nss1_taylor(horizontal_stiffness, wall_distance, spring_free_length):
    """Series of :func:`nss1_force` about ``u = 0``: ``(k1, k2, k3)`` with
    ``k1 = 2 K_h (1 - γ)/γ``, ``k2 = 0``, ``k3 = -K_h / (L_o² γ³)``, ``γ = a_o/L_o`` — Eq 2.45
    with ``K_h = α K_v``."""
    k1 = 2.0 * horizontal_stiffness * (spring_free_length / wall_distance - 1.0)
    k3 = -horizontal_stiffness * spring_free_length / wall_distance ** 3
    return k1, np.zeros_like(k1), k3


def nss2_force(u, horizontal_stiffness, wall_distance, spring_free_length, bar_length):
    """NSS2 (Le) mechanism force on the seat, ``f_N = 2 K_h (1 + (L_o - a_o)/sqrt(b² - u²)) u``
    [N] (Eq 2.49 in the travel ``u``; slip: docs/thesis-slips.md#eq-243).

    A bar of length ``b`` from the seat reaches a slider at ``sqrt(b² - u²)`` from the seat's
    axis; the horizontal spring between slider and its anchor at ``a_o`` has length
    ``a_o - sqrt(b² - u²)`` and potential ``½ K_h (L_o - a_o + sqrt(b² - u²))²``; the force is
    minus its derivative, times two springs. It is zero at ``u = 0`` and at ``u = X_ST``.

    Eq 2.50 (slip: docs/thesis-slips.md#eq-250) in the ratios ``γ1 = b/L_o``, ``γ2 = a_o/L_o``:
    dividing Eq 2.49's
    fraction by ``L_o`` gives ``f_N = 2 K_h (1 + (1 - γ2) / sqrt(γ1² - (u/L_o)²)) u`` — the
    printed ``sqrt(γ1² - x²)`` lacks the ``1/L_o`` on ``x``.
    """
    return _nss2_law(horizontal_stiffness, wall_distance, spring_free_length, bar_length)(u)


def _nss2_law(horizontal_stiffness, wall_distance, spring_free_length, bar_length):
    """:func:`nss2_force` as a function of the travel (constants folded)."""
    return _link_law(horizontal_stiffness, spring_free_length - wall_distance, bar_length)


def nss2_taylor(horizontal_stiffness, wall_distance, spring_free_length, bar_length):
    """Series of :func:`nss2_force` about ``u = 0``: ``k1 = 2 K_h (1 + γ1 - γ2)/γ1``, ``k2 = 0``,
    ``k3 = K_h (1 - γ2) / (L_o² γ1³)`` — Eq 2.52 with ``K_h = α K_v``."""
    return _link_series(0.0, horizontal_stiffness, spring_free_length - wall_distance,
                        bar_length)


def nss3_force(u, horizontal_stiffness, cam_radius, roller_radius, cam_offset, precompression):
    """NSS3 (Yan) mechanism force on the seat [N] (Eq 2.56 in the travel ``u``):

    ``f_N = 2 K_h (u_2 + sqrt((R + r)² - u²) - d - r) u / sqrt((R + r)² - u²)``.

    The roller's centre stays on a circle of radius ``R + r`` about the cam's centre, at the
    horizontal distance ``sqrt((R + r)² - u²)``; the spring's compression is ``u_2`` plus that
    distance less ``d + r``, and the contact normal gives the vertical share
    ``u / sqrt((R + r)² - u²)``.
    """
    return _nss3_law(horizontal_stiffness, cam_radius, roller_radius, cam_offset,
                     precompression)(u)


def _nss3_law(horizontal_stiffness, cam_radius, roller_radius, cam_offset, precompression):
    """:func:`nss3_force` as a function of the travel (constants folded)."""
    return _link_law(horizontal_stiffness, precompression - cam_offset - roller_radius,
                     cam_radius + roller_radius)


def nss3_taylor(horizontal_stiffness, cam_radius, roller_radius, cam_offset, precompression):
    """Series of :func:`nss3_force` about ``u = 0`` (the thesis prints none):
    ``k1 = 2 K_h (R + u_2 - d)/(R + r)``, ``k2 = 0``, ``k3 = K_h (u_2 - d - r)/(R + r)³``."""
    return _link_series(0.0, horizontal_stiffness, precompression - cam_offset - roller_radius,
                        cam_radius + roller_radius)


def nss3_contact_limit(cam_radius, roller_radius, cam_offset, precompression):
    """Travel ``|u|`` up to which the NSS3 springs still press the rollers on the cam [m]:
    their compression ``u_2 + sqrt((R + r)² - u²) - d - r`` stays positive (Sec 8.2.2: the
    precompression keeps the contact at the extreme positions); at most ``R + r``."""
    gap = np.maximum(cam_offset + roller_radius - precompression, 0.0)
    return np.sqrt((cam_radius + roller_radius) ** 2 - gap ** 2)


def nss4_force(u, horizontal_stiffness, wall_distance, spring_free_length, bar_length):
    """NSS4 (KDamper) mechanism force on the inner mass, upward + [N]:
    ``2 K_h (1 + c_I / sqrt(1 - u²/b²)) u``, ``c_I = (L_o - a_o)/b`` (Eq 2.65-2.67).

    This is ``-f_N(u)`` of Eq 2.65: Eq 2.60 writes ``+f_ND`` on its left-hand side, so the force
    on ``m_d`` is ``-f_N``; its positive slope ``2 K_h (1 + c_I)`` at ``u = 0`` is the negative
    stiffness ``K_N = -2 K_h`` of Sec 2.2.5 for ``c_I = 0``. The same geometry as NSS2.
    """
    return _nss4_law(horizontal_stiffness, wall_distance, spring_free_length, bar_length)(u)


#: :func:`nss4_force` as a function of the travel: the geometry of NSS2.
_nss4_law = _nss2_law


def nss4_taylor(hinge_offset, horizontal_stiffness, wall_distance, spring_free_length,
                bar_length):
    """Series of :func:`nss4_force` about the rest position ``u = u_0`` (the thesis prints
    none): ``f_ND(u_0 + δ) = k1 δ + k2 δ² + k3 δ³``; ``k2 ≠ 0`` since ``u_0 ≠ 0``."""
    return _link_series(hinge_offset, horizontal_stiffness, spring_free_length - wall_distance,
                        bar_length)


# --------------------------------------------------------------------------------------------
# The attachment

_COMPLEX_STEP = 1.0e-20

@dataclass
class Mechanism:
    """The geometric element of NSS1-NSS4 between the floor and the mass it carries.

    ``node``: index of that mass among the seat's DOFs; ``law(s, width=None)``: the function
    ``w -> s F(w)``, F the force on that mass [N] at the mechanism coordinate ``w`` (the travel
    from where the geometry is symmetric, the springs horizontal), its constants folded for
    the scale ``s`` (and widened to ``width`` design columns); ``rest``: ``w`` at static
    equilibrium, (P, 1), or None for 0 (NSS1-NSS3; NSS4 rests at ``u_0``); ``series``:
    ``(k1, k2, k3)`` about ``rest`` when the Taylor form is used, else None; ``limit``: the
    largest ``|w|`` the geometry allows [m], (P, 1), or None.
    """

    node: int
    law: Callable[..., Callable[[np.ndarray], np.ndarray]]
    rest: np.ndarray | None
    series: tuple[np.ndarray, np.ndarray, np.ndarray] | None
    limit: np.ndarray | None
    exact: Callable[[np.ndarray], np.ndarray] = field(init=False, repr=False)
    _preload: np.ndarray | None = field(init=False, repr=False)

    def __post_init__(self):
        self.exact = self.law(1.0)
        self._preload = None if self.rest is None else self.exact(self.rest)

    def force(self, delta: np.ndarray) -> np.ndarray:
        """Dynamic force for the travel ``delta`` from rest, zero at ``delta = 0``: the exact
        force less its static part, or the Taylor series."""
        if self.series is not None:
            k1, k2, k3 = self.series
            return ((k3 * delta + k2) * delta + k1) * delta
        if self.rest is None:
            return self.exact(delta)
        return self.exact(self.rest + delta) - self._preload

    def element_force(self, width: int) -> Callable[..., object]:
        """``(δ, δ̇, F, out) -> out = -force(δ)``: the mechanism as the non-linear part of a
        network element along ``δ`` (the element force resists the deformation;
        :mod:`suspopt.network`) for ``width`` design columns, with the sign folded into the
        constants: the same arithmetic as :meth:`force`, negated exactly."""
        if self.series is not None:
            c1, c2, c3 = (widen(-k[None], width) for k in self.series)
            return lambda d, r, f, out: np.multiply((c3 * d + c2) * d + c1, d, out=out)
        negated = self.law(-1.0, width)
        if self.rest is None:
            return lambda d, r, f, out: negated(d, out)
        rest, preload = widen(self.rest[None], width), widen(self._preload[None], width)
        return lambda d, r, f, out: np.add(negated(rest + d), preload, out=out)

    def slope(self) -> np.ndarray:
        """``dF/dδ`` at rest, (P,) [N/m] (a positive slope is a negative stiffness), by
        complex-step differentiation: ``Im F(i h) / h`` is exact to rounding for these
        analytic forces, the same for the exact and the Taylor form."""
        return np.atleast_2d(self.force(np.full((1, 1), 1j * _COMPLEX_STEP))).imag[:, 0] \
            / _COMPLEX_STEP

    def coordinate(self, delta: np.ndarray) -> np.ndarray:
        """The mechanism coordinate ``w`` for the travel ``delta`` from rest [m]."""
        return delta if self.rest is None else self.rest + delta


@dataclass
class SeatModel:
    """A seat isolator and its optional passenger, mounted at ``point`` on the body.

    ``dof_names``: ``seat``, ``seat.inner`` (NSS4), then the passenger's parts; ``mass (1|P, 1,
    m)`` [kg]; ``network`` its :class:`~suspopt.network.Network` over those DOFs with the floor
    under the seat as the one input (groups ``links``: the linear springs and dampers; and, for
    NSS1-NSS4, ``mechanism``: the geometric element between the floor and the mass it carries,
    whose force is the group's non-linear part); ``point = (x, y)`` [m] the mount on the body
    (x + forward, y + right), ``coupled`` whether the seat pushes back on the body (two-way) or
    is driven one way (the thesis's way); ``mechanism`` the geometric element (None for PS);
    ``isolator`` the derived and given isolator quantities by name, (P,) each
    (``static_deflection`` [m], ``vertical_stiffness`` [N/m], ...).
    """

    kind: str
    dof_names: tuple[str, ...]
    mass: np.ndarray
    point: tuple[float, float]
    coupled: bool
    network: Network
    mechanism: Mechanism | None
    isolator: dict[str, np.ndarray]

    def __post_init__(self):
        self._signals = self._signal_table()

    @property
    def P(self) -> int:
        return self.isolator["static_deflection"].shape[0]

    @property
    def static_deflection(self) -> np.ndarray:
        """``X_ST`` (P,) [m] (Eq 8.2, the thesis's f_2)."""
        return self.isolator["static_deflection"]

    def force(self, q: np.ndarray, v: np.ndarray, base: np.ndarray,
              base_vel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Forces on the seat's DOFs (m, P, S) and on the floor (P, S), upward +, from the
        states ``q, v (m, P, S)`` and the floor's motion ``base, base_vel (P, S)``."""
        own, floor = self.network.generalised_forces(q, v, base[None], base_vel[None])
        return own, floor[0]

    def signals(self) -> dict[str, tuple[str, Callable[..., np.ndarray]]]:
        """The seat's and the passenger's entries of the signal table
        (:class:`suspopt.result.Attachment`): name -> (SI unit, ``compute(q, v, acc, base,
        base_vel, base_acc)``), a signal (P, T) from the seat's states (m, P, T) and the
        floor's (P, T)."""
        return {name: (signal_units(name), compute) for name, compute in self._signals.items()}

    def _signal_table(self) -> dict[str, Callable[..., np.ndarray]]:
        table: dict[str, Callable[..., np.ndarray]] = {
            "seat.base": lambda q, v, a, b, bv, ba: b,
            "seat.base_vel": lambda q, v, a, b, bv, ba: bv,
            "seat.base_acc": lambda q, v, a, b, bv, ba: ba,
            "seat.x": lambda q, v, a, b, bv, ba: q[0],
            "seat.vel": lambda q, v, a, b, bv, ba: v[0],
            "seat.acc": lambda q, v, a, b, bv, ba: a[0],
            "seat.travel": lambda q, v, a, b, bv, ba: q[0] - b,
            "seat.travel_vel": lambda q, v, a, b, bv, ba: v[0] - bv,
        }
        if "seat.inner" in self.dof_names:
            table["seat.inner_x"] = lambda q, v, a, b, bv, ba: q[1]
            table["seat.inner_acc"] = lambda q, v, a, b, bv, ba: a[1]
        mech = self.mechanism
        if mech is not None and mech.limit is not None:
            table["seat.travel_margin"] = lambda q, v, a, b, bv, ba: \
                mech.limit - np.abs(mech.coordinate(q[mech.node] - b))
        for j, name in enumerate(self.dof_names):
            if name in PASSENGER_PARTS:
                table[f"{name}.x"] = lambda q, v, a, b, bv, ba, j=j: q[j]
                table[f"{name}.vel"] = lambda q, v, a, b, bv, ba, j=j: v[j]
                table[f"{name}.acc"] = lambda q, v, a, b, bv, ba, j=j: a[j]
        return table


def _passive(get: Callable[[str], np.ndarray], load: np.ndarray, g: float, form: str):
    """PS, Eq 2.40 as ``m ẍ + C_v (ẋ - ż_s) + K_v (x - z_s) = 0`` (slip:
    docs/thesis-slips.md#eq-240)."""
    k_v = get("stiffness")
    return [(0, 1, k_v, get("damping"))], None, {
        "static_deflection": ps_static_deflection(load, k_v, g), "vertical_stiffness": k_v}


def _scaled(law: Callable, params: tuple[np.ndarray, ...]):
    """``(s, width) -> law(s K_h, *geometry)`` for a mechanism's ``params = (K_h, *geometry)``,
    (P, 1) each, widened to ``width`` design columns when given."""
    def make(scale: float, width: int | None = None):
        # shaped like the mechanism's row (1, width, 1): numpy is slow to broadcast
        p = params if width is None else tuple(widen(a[None], width) for a in params)
        return law(scale * p[0], *p[1:])
    return make


def _negative_stiffness(kind: str):
    """Builder of NSS1-NSS3: ``m ẍ + C_v u̇ + K_v u - f_N(u) = 0`` (Eq 2.44, 2.51, 2.57) with
    ``K_v = m g / X_ST`` and ``K_h = α K_v`` (Sec 8.2.2)."""
    def build(get: Callable[[str], np.ndarray], load: np.ndarray, g: float, form: str):
        if kind == "nss1":
            a_o, gamma = get("wall_distance"), get("gamma")
            geometry, limit = (a_o, a_o / gamma), None
            x_st = nss1_static_deflection(a_o, gamma)
        elif kind == "nss2":
            a_o, l_o, b = get("wall_distance"), get("spring_free_length"), get("bar_length")
            geometry, limit = (a_o, l_o, b), b
            x_st = nss2_static_deflection(a_o, l_o, b)
        else:
            geometry = (get("cam_radius"), get("roller_radius"), get("cam_offset"),
                        get("precompression"))
            limit = nss3_contact_limit(*geometry)
            x_st = nss3_static_deflection(*geometry[:3])
        k_v = vertical_stiffness(load, x_st, g)
        k_h = get("stiffness_ratio") * k_v
        params = tuple(p[:, None] for p in (k_h,) + geometry)
        law, series = _FORMS[kind]
        mech = Mechanism(node=0, law=_scaled(law, params), rest=None,
                         series=series(*params) if form == "taylor" else None,
                         limit=None if limit is None else limit[:, None])
        return [(0, 1, k_v, get("damping"))], mech, {
            "static_deflection": x_st, "vertical_stiffness": k_v, "horizontal_stiffness": k_h}
    return build


def _kdamper(get: Callable[[str], np.ndarray], load: np.ndarray, g: float, form: str):
    """NSS4, Eq 2.59-2.69: ``K_S`` floor-seat, ``K_v`` and ``C_v`` seat-inner mass, the
    mechanism floor-inner mass at rest at ``u_0``; ``X_ST`` from Eq 2.64."""
    k_s, k_v, k_h = (get("support_stiffness"), get("inner_stiffness"),
                     get("horizontal_stiffness"))
    a_o, l_o, b = get("wall_distance"), get("spring_free_length"), get("bar_length")
    u_0 = get("hinge_offset")
    params = tuple(p[:, None] for p in (k_h, a_o, l_o, b))
    preload = nss4_force(u_0, k_h, a_o, l_o, b)
    mech = Mechanism(node=1, law=_scaled(_nss4_law, params), rest=u_0[:, None],
                     series=nss4_taylor(u_0[:, None], *params) if form == "taylor" else None,
                     limit=b[:, None])
    return [(0, 1, k_s, 0.0), (1, 2, k_v, get("damping"))], mech, {
        "static_deflection": nss4_static_deflection(load, get("inner_mass"), k_s, preload, g),
        "vertical_stiffness": k_v, "horizontal_stiffness": k_h, "support_stiffness": k_s,
        "mechanism_preload": preload, "c_I": (l_o - a_o) / b}


#: Exact force law (the parameters of the ``*_force`` function after the travel, giving the
#: function of the travel) and Taylor coefficients of NSS1-NSS3.
_FORMS = {"nss1": (_carrella_law, nss1_taylor), "nss2": (_nss2_law, nss2_taylor),
          "nss3": (_nss3_law, nss3_taylor)}
#: Isolator builders: (get, load [kg], g, form) -> (links, mechanism, quantities). Links are
#: (node_a, node_b, stiffness, damping) over the nodes 0 floor, 1 seat, 2 inner mass.
_ISOLATORS = {"ps": _passive, "nss1": _negative_stiffness("nss1"),
              "nss2": _negative_stiffness("nss2"), "nss3": _negative_stiffness("nss3"),
              "nss4": _kdamper}


def build_seat(cfg: Config, pv: ParamView | None = None) -> SeatModel:
    """Assemble the batched :class:`SeatModel` of ``cfg.seat`` for the designs in ``pv``."""
    pv = pv or ParamView(cfg)
    seat = cfg.seat
    if seat is None:
        raise ConfigError("seat: the config has no seat section")
    if pv.varies("seat.position"):
        raise ConfigError("params: seat.position cannot be a design parameter: the seat's "
                          "point on the body is one per run")

    def get(key: str) -> np.ndarray:
        return pv.get(f"seat.{key}")

    inner = seat.kind == "nss4"
    parts = PASSENGER_PARTS if seat.passenger is not None else ()
    names = ("seat",) + (("seat.inner",) if inner else ()) + parts
    node = {name: i for i, name in enumerate(("floor",) + names)}     # 0 floor, 1 seat, ...
    masses = [pv.require_positive("seat.mass")] + \
        ([pv.require_positive("seat.inner_mass")] if inner else [])
    load = masses[0]                  # the isolator carries the seat and the passenger
    links = []
    for part in parts:
        m = pv.require_positive(f"seat.passenger.{part}.mass")
        masses.append(m)
        load = load + m
        links.append((node[part], node[_BELOW[part]], get(f"passenger.{part}.stiffness"),
                      get(f"passenger.{part}.damping")))
    if parts:
        links.append((node["torso"], node["back"], get("passenger.torso_back.stiffness"),
                      get("passenger.torso_back.damping")))
    form = getattr(seat, "form", "exact")
    with np.errstate(divide="ignore", invalid="ignore"):     # undefined geometry -> NaN
        iso_links, mechanism, isolator = _ISOLATORS[seat.kind](get, load, cfg.vehicle.gravity,
                                                               form)
        mass = np.stack(masses, axis=1)[:, None, :]
        network = seat_network(names, mass[:, 0, :], iso_links + links, mechanism)
    return SeatModel(kind=seat.kind, dof_names=names, mass=shared_rows(mass),
                     point=(seat.position.x, seat.position.y),
                     coupled=seat.coupling == "two_way", network=network,
                     mechanism=mechanism, isolator={**isolator, "load_mass": load})


def seat_network(dof_names: tuple[str, ...], mass: np.ndarray, links: list,
                 mechanism: Mechanism | None) -> Network:
    """The seat's :class:`~suspopt.network.Network`: DOFs ``dof_names`` with ``mass (P, m)``
    [kg], the floor as input; ``links`` ``(node_a, node_b, k, c)`` over the nodes 0 floor,
    1.. the DOFs, each a spring and damper along ``x_a - x_b`` (group ``links``); the
    ``mechanism`` between the floor and its node (group ``mechanism``, linear part zero: its
    element force is minus the mechanism's upward force on the node, so the node feels that
    force and the floor its reaction)."""
    P, m = mass.shape
    dof_map, floor = np.zeros((len(links), m)), np.zeros((len(links), 1))
    for i, (a, b, _, _) in enumerate(links):
        for node, sign in ((a, 1.0), (b, -1.0)):
            if node == 0:
                floor[i, 0] += sign
            else:
                dof_map[i, node - 1] += sign
    k = np.stack([np.broadcast_to(link[2], (P,)) for link in links])[:, :, None]
    c = np.stack([np.broadcast_to(link[3], (P,)) for link in links])[:, :, None]
    groups = [Elements("links", dof_map, floor, k, c)]
    if mechanism is not None:
        carried = np.zeros((1, m))
        carried[0, mechanism.node] = 1.0
        zero = np.zeros((1, P, 1))
        groups.append(Elements("mechanism", carried, -np.ones((1, 1)), zero, zero,
                               extra=mechanism.element_force,
                               extra_slope=-mechanism.slope()[None, :, None]))
    return Network(dof_names, ("floor",), parameter_rows(mass),
                   tuple(groups))


def build_attachments(cfg: Config, pv: ParamView) -> list[SeatModel]:
    """The body attachments of ``cfg``: its seat (and passenger), or none."""
    return [] if cfg.seat is None else [build_seat(cfg, pv)]


# --------------------------------------------------------------------------------------------
# Linearised model, transmissibility, modes

@dataclass
class LinearSeat:
    """The seat linearised about static equilibrium, the floor motion ``z_s`` as input:
    ``M q'' + C q' + K q = b_k z_s + b_c z_s'``.

    ``mass (P, m)`` the diagonal of M [kg]; ``stiffness``, ``damping (P, m, m)`` [N/m, N s/m];
    ``input_stiffness``, ``input_damping (P, m)`` [N/m, N s/m]; DOFs as ``dof_names``.
    """

    dof_names: tuple[str, ...]
    mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    input_stiffness: np.ndarray
    input_damping: np.ndarray


def linearise(seat: SeatModel) -> LinearSeat:
    """The seat linearised about static equilibrium (:meth:`Network.linear_model` of its
    network): the links as they are, the mechanism with its slope at rest
    (:meth:`Mechanism.slope`), the floor motion as the input."""
    lin = seat.network.linear_model()
    return LinearSeat(dof_names=seat.dof_names, mass=lin.mass, stiffness=lin.stiffness,
                      damping=lin.damping, input_stiffness=lin.input_stiffness[..., 0],
                      input_damping=lin.input_damping[..., 0])


def base_transmissibility(lin: LinearSeat, f: np.ndarray) -> np.ndarray:
    """Acceleration transmissibility ``z̈_i / z̈_s`` of every DOF from the floor, Eq 2.86,
    complex, (P, F, m).

    ``(K - ω² M + jω C) Q = b_k + jω b_c`` for a unit floor displacement; the acceleration
    ratio equals the displacement ratio ``Q``. Seat-to-head transmissibility (STHT, Eq 2.86 with
    i = head, Fig. 8.26: ``z̈_head / z̈_s``) is the ``head`` column.
    """
    omega = 2.0 * np.pi * np.atleast_1d(np.asarray(f, dtype=float))
    w = omega[None, :, None, None]
    dyn = lin.stiffness[:, None] - w ** 2 * (lin.mass[:, None, :, None]
                                            * np.eye(lin.mass.shape[-1])) \
        + 1j * w * lin.damping[:, None]
    rhs = lin.input_stiffness[:, None, :] + 1j * omega[None, :, None] * lin.input_damping[:, None]
    return np.linalg.solve(dyn, rhs[..., None])[..., 0]


def natural_frequencies(lin: LinearSeat) -> np.ndarray:
    """Undamped natural frequencies with the floor held still, (P, m) [Hz], ascending
    (``K φ = ω² M φ``, solved as the symmetric ``M^-1/2 K M^-1/2``)."""
    s = 1.0 / np.sqrt(lin.mass)
    lam = np.linalg.eigvalsh(s[:, :, None] * lin.stiffness * s[:, None, :])
    return np.sqrt(np.clip(lam, 0.0, None)) / (2.0 * np.pi)


# --------------------------------------------------------------------------------------------
# Design quantities without simulation: X_ST, geometric constraints, passenger mass change

#: Unit of each constraint value of :func:`seat_constraints`.
CONSTRAINT_UNITS = {
    "stability": "N/m", "gamma2_above_one": "-", "gamma2_within_gamma1": "-",
    "stiffness_ratio_limit": "-", "static_deflection_exists": "-",
    "roller_radius_positive": "m", "cam_offset_positive": "m", "cam_offset_within_radius": "m",
    "precompression_positive": "m", "roller_within_cam": "m", "cam_offset_ratio": "m",
    "c_I_upper": "-", "c_I_lower": "-", "hinge_within_bar": "m",
}


def seat_static_deflection(cfg: Config, params: Mapping[str, Any] | None = None) -> np.ndarray:
    """``X_ST`` of every design (P,) [m] (the thesis's objective f_2, Eq 8.2)."""
    return build_seat(cfg, ParamView(cfg, params)).static_deflection


def seat_constraints(cfg: Config, params: Mapping[str, Any] | None = None,
                     mu: float = 0.8) -> dict[str, np.ndarray]:
    """Geometric and static feasibility of every design as constraint values, ``g <= 0``
    feasible, (P,) each (units in :data:`CONSTRAINT_UNITS`). Never raises for an infeasible
    design: an undefined geometry gives NaN or a positive value.

    - all kinds: ``stability`` = minus the smallest eigenvalue of the linearised stiffness
      with the floor held (a statically unstable isolator has ``g > 0``; NaN where the
      geometry has no static deflection);
    - NSS2, ``γ1 = b/L_o``, ``γ2 = a_o/L_o``: ``gamma2_above_one`` ``1 - γ2`` (Eq 2.46,
      Table 8.7 #5), ``gamma2_within_gamma1`` ``γ2 - γ1`` (Eq 2.47; Table 8.7 drops it),
      ``stiffness_ratio_limit`` ``α - γ1/(2(1 + γ1 - γ2))`` (Eq 2.48, Table 8.7 #3),
      ``static_deflection_exists`` ``γ2 - 1 - γ1`` (Table 8.7 #4);
    - NSS3: ``roller_radius_positive`` ``-r`` and ``cam_offset_positive`` ``-d`` (Eq 2.53),
      ``cam_offset_within_radius`` ``d - R`` (Eq 2.54), ``precompression_positive`` ``-u_2``
      (Eq 2.55), ``roller_within_cam`` ``r - R`` (Table 8.9 #3), ``cam_offset_ratio``
      ``d - μ R`` (Table 8.9 #4, Sec 8.3.4 picks μ = 0.8);
    - NSS4: ``c_I_upper`` ``c_I - 0.1`` and ``c_I_lower`` ``-0.1 - c_I`` (Table 8.11 #3),
      ``hinge_within_bar`` ``|u_0| - b`` (Eq 2.65 needs ``|u| < b``).

    The travel limits the motion must respect are the signal ``seat.travel_margin`` (m, >= 0
    feasible): NSS2 and NSS4 ``b - |u|``, NSS3 the roller's contact limit less ``|u|``.
    """
    pv = ParamView(cfg, params)
    seat = build_seat(cfg, pv)

    def get(key: str) -> np.ndarray:
        return pv.get(f"seat.{key}")

    with np.errstate(invalid="ignore", divide="ignore"):
        stiffness = linearise(seat).stiffness
    defined = np.isfinite(stiffness).all(axis=(1, 2)) & np.isfinite(seat.static_deflection)
    stability = np.full(pv.P, np.nan)
    if defined.any():
        stability[defined] = -np.linalg.eigvalsh(stiffness[defined])[:, 0]
    out = {"stability": stability}
    if seat.kind == "nss2":
        l_o = get("spring_free_length")
        g1, g2 = get("bar_length") / l_o, get("wall_distance") / l_o
        out.update(gamma2_above_one=1.0 - g2, gamma2_within_gamma1=g2 - g1,
                   stiffness_ratio_limit=get("stiffness_ratio") - g1 / (2.0 * (1.0 + g1 - g2)),
                   static_deflection_exists=g2 - 1.0 - g1)
    elif seat.kind == "nss3":
        R, r, d = get("cam_radius"), get("roller_radius"), get("cam_offset")
        out.update(roller_radius_positive=-r, cam_offset_positive=-d,
                   cam_offset_within_radius=d - R, precompression_positive=-get("precompression"),
                   roller_within_cam=r - R, cam_offset_ratio=d - mu * R)
    elif seat.kind == "nss4":
        c_i = seat.isolator["c_I"]
        out.update(c_I_upper=c_i - 0.1, c_I_lower=-0.1 - c_i,
                   hinge_within_bar=np.abs(get("hinge_offset")) - get("bar_length"))
    return out


def passenger_mass_change(cfg: Config, load_mass) -> dict[str, np.ndarray]:
    """Design parameters (dotted path -> (P,)) that seat a different passenger, Sec 8.4.3.

    ``load_mass (P,)`` [kg] is the new whole load on the isolator (seat plus passenger; the
    thesis: 95 ± 20 kg). Without a passenger model ``seat.mass`` (the lumped load) takes it;
    with one, the passenger's segment masses are scaled in proportion (stiffnesses and dampings
    kept). As in Sec 8.4.3:

    - NSS1-NSS3 keep ``X_ST``: their ``K_v = m g / X_ST`` is re-set by the new load, and
      ``stiffness_ratio`` is scaled by ``m_old / m_new`` so that the horizontal springs ``K_h``
      stay as built (the thesis modifies ``K_v`` only);
    - PS and NSS4 keep every stiffness; their ``X_ST`` follows the load.

    Pass the result to :func:`suspopt.simulate` as ``params``.
    """
    load_mass = np.atleast_1d(np.asarray(load_mass, dtype=float))
    seat = cfg.seat
    if seat is None:
        raise ConfigError("seat: the config has no seat section")
    old = float(build_seat(cfg).isolator["load_mass"][0])
    if seat.passenger is None:
        params = {"seat.mass": load_mass}
    else:
        scale = (load_mass - seat.mass) / (old - seat.mass)
        params = {f"seat.passenger.{part}.mass": getattr(seat.passenger, part).mass * scale
                  for part in PASSENGER_PARTS}
    if seat.kind in ("nss1", "nss2", "nss3"):
        params["seat.stiffness_ratio"] = seat.stiffness_ratio * old / load_mass
    return params
