"""The isolators' statics and their geometric mechanisms (Sec 2.2, 8.2.2): static deflections,
the exact force laws of NSS1-NSS4 and their Taylor series, and :class:`Mechanism`, the
element a seat's network carries them in. Signs and coordinates: :mod:`suspopt.seat`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..network import widen

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
        return wall_distance * np.sqrt(1.0 / gamma**2 - 1.0)


def nss2_static_deflection(wall_distance, spring_free_length, bar_length):
    """NSS2 static deflection ``X_ST = sqrt(b² - (a_o - L_o)²)`` [m] (Sec 2.2.3, 8.2.2);
    NaN where ``b <= |a_o - L_o|`` (no such geometry)."""
    with np.errstate(invalid="ignore"):
        return np.sqrt(bar_length**2 - (wall_distance - spring_free_length) ** 2)


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

    def law(w, out=None):
        return np.multiply(a + b / np.sqrt(square - w * w), w, out=out)

    law.compiled = ("link", (a, b, square))  # type: ignore[attr-defined]  # (compiled.LAWS)
    return law


def carrella_law(stiffness, wall_distance, spring_free_length):
    """``u -> 2 K_h (L_o / sqrt(u² + a_o²) - 1) u`` (:func:`nss1_force`), constants folded."""
    a, b = -2.0 * stiffness, 2.0 * stiffness * spring_free_length
    square = wall_distance * wall_distance

    def law(u, out=None):
        return np.multiply(b / np.sqrt(u * u + square) + a, u, out=out)

    law.compiled = ("carrella", (a, b, square))  # type: ignore[attr-defined]  # (compiled.LAWS)
    return law


def _link_series(rest, stiffness, offset, length):
    """Coefficients ``(k1, k2, k3)`` of :func:`_link_law` about ``w = rest``:
    ``F(rest + δ) - F(rest) = k1 δ + k2 δ² + k3 δ³ + O(δ⁴)``.

    With ``h(w) = w (ℓ² - w²)^(-1/2)``: ``h' = ℓ² D^(-3/2)``, ``h'' = 3 ℓ² w D^(-5/2)``,
    ``h''' = 3 ℓ² (ℓ² + 4 w²) D^(-7/2)``, ``D = ℓ² - w²``.
    """
    L2 = length * length
    D = L2 - rest * rest
    k1 = 2.0 * stiffness * (1.0 + offset * L2 * D**-1.5)
    k2 = 3.0 * stiffness * offset * L2 * rest * D**-2.5
    k3 = stiffness * offset * L2 * (L2 + 4.0 * rest * rest) * D**-3.5
    return k1, k2, k3


def nss1_force(u, horizontal_stiffness, wall_distance, spring_free_length):
    """NSS1 (Carrella) mechanism force on the seat, ``f_N = 2 K_h (L_o / sqrt(u² + a_o²) - 1) u``
    [N] (Eq 2.41-2.43 in the travel ``u``; slip: docs/thesis-slips.md#eq-243).

    Each inclined spring runs from an anchor at horizontal distance ``a_o`` to the seat; its
    length is ``sqrt(u² + a_o²)``, its compression ``L_o`` minus that, and the vertical share of
    its force ``u / sqrt(u² + a_o²)``. Zero at ``u = 0`` (springs horizontal) and at
    ``u = X_ST`` (springs free).
    """
    return carrella_law(horizontal_stiffness, wall_distance, spring_free_length)(u)


def nss1_taylor(horizontal_stiffness, wall_distance, spring_free_length):
    """Series of :func:`nss1_force` about ``u = 0``: ``(k1, k2, k3)`` with
    ``k1 = 2 K_h (1 - γ)/γ``, ``k2 = 0``, ``k3 = -K_h / (L_o² γ³)``, ``γ = a_o/L_o`` — Eq 2.45
    with ``K_h = α K_v``."""
    k1 = 2.0 * horizontal_stiffness * (spring_free_length / wall_distance - 1.0)
    k3 = -horizontal_stiffness * spring_free_length / wall_distance**3
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
    return nss2_law(horizontal_stiffness, wall_distance, spring_free_length, bar_length)(u)


def nss2_law(horizontal_stiffness, wall_distance, spring_free_length, bar_length):
    """:func:`nss2_force` as a function of the travel (constants folded)."""
    return _link_law(horizontal_stiffness, spring_free_length - wall_distance, bar_length)


def nss2_taylor(horizontal_stiffness, wall_distance, spring_free_length, bar_length):
    """Series of :func:`nss2_force` about ``u = 0``: ``k1 = 2 K_h (1 + γ1 - γ2)/γ1``, ``k2 = 0``,
    ``k3 = K_h (1 - γ2) / (L_o² γ1³)`` — Eq 2.52 with ``K_h = α K_v``."""
    return _link_series(0.0, horizontal_stiffness, spring_free_length - wall_distance, bar_length)


def nss3_force(u, horizontal_stiffness, cam_radius, roller_radius, cam_offset, precompression):
    """NSS3 (Yan) mechanism force on the seat [N] (Eq 2.56 in the travel ``u``):

    ``f_N = 2 K_h (u_2 + sqrt((R + r)² - u²) - d - r) u / sqrt((R + r)² - u²)``.

    The roller's centre stays on a circle of radius ``R + r`` about the cam's centre, at the
    horizontal distance ``sqrt((R + r)² - u²)``; the spring's compression is ``u_2`` plus that
    distance less ``d + r``, and the contact normal gives the vertical share
    ``u / sqrt((R + r)² - u²)``.
    """
    return nss3_law(horizontal_stiffness, cam_radius, roller_radius, cam_offset, precompression)(u)


def nss3_law(horizontal_stiffness, cam_radius, roller_radius, cam_offset, precompression):
    """:func:`nss3_force` as a function of the travel (constants folded)."""
    return _link_law(
        horizontal_stiffness,
        precompression - cam_offset - roller_radius,
        cam_radius + roller_radius,
    )


def nss3_taylor(horizontal_stiffness, cam_radius, roller_radius, cam_offset, precompression):
    """Series of :func:`nss3_force` about ``u = 0`` (the thesis prints none):
    ``k1 = 2 K_h (R + u_2 - d)/(R + r)``, ``k2 = 0``, ``k3 = K_h (u_2 - d - r)/(R + r)³``."""
    return _link_series(
        0.0,
        horizontal_stiffness,
        precompression - cam_offset - roller_radius,
        cam_radius + roller_radius,
    )


def nss3_contact_limit(cam_radius, roller_radius, cam_offset, precompression):
    """Travel ``|u|`` up to which the NSS3 springs still press the rollers on the cam [m]:
    their compression ``u_2 + sqrt((R + r)² - u²) - d - r`` stays positive (Sec 8.2.2: the
    precompression keeps the contact at the extreme positions); at most ``R + r``."""
    gap = np.maximum(cam_offset + roller_radius - precompression, 0.0)
    return np.sqrt((cam_radius + roller_radius) ** 2 - gap**2)


def nss4_force(u, horizontal_stiffness, wall_distance, spring_free_length, bar_length):
    """NSS4 (KDamper) mechanism force on the inner mass, upward + [N]:
    ``2 K_h (1 + c_I / sqrt(1 - u²/b²)) u``, ``c_I = (L_o - a_o)/b`` (Eq 2.65-2.67).

    This is ``-f_N(u)`` of Eq 2.65: Eq 2.60 writes ``+f_ND`` on its left-hand side, so the force
    on ``m_d`` is ``-f_N``; its positive slope ``2 K_h (1 + c_I)`` at ``u = 0`` is the negative
    stiffness ``K_N = -2 K_h`` of Sec 2.2.5 for ``c_I = 0``. The same geometry as NSS2.
    """
    return nss4_law(horizontal_stiffness, wall_distance, spring_free_length, bar_length)(u)


#: :func:`nss4_force` as a function of the travel: the geometry of NSS2.
nss4_law = nss2_law


def nss4_taylor(hinge_offset, horizontal_stiffness, wall_distance, spring_free_length, bar_length):
    """Series of :func:`nss4_force` about the rest position ``u = u_0`` (the thesis prints
    none): ``f_ND(u_0 + δ) = k1 δ + k2 δ² + k3 δ³``; ``k2 ≠ 0`` since ``u_0 ≠ 0``."""
    return _link_series(
        hinge_offset, horizontal_stiffness, spring_free_length - wall_distance, bar_length
    )


# --------------------------------------------------------------------------------------------
# The mechanism as an element

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
    law: Callable[..., Callable[..., np.ndarray]]  # (scale, width) -> law(w, out=None)
    rest: np.ndarray | None
    series: tuple[np.ndarray, np.ndarray, np.ndarray] | None
    limit: np.ndarray | None
    exact: Callable[..., np.ndarray] = field(init=False, repr=False)
    _preload: Any = field(init=False, repr=False)  # (an array where rest is given)

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

    def compiled_law(self) -> tuple[str, tuple[np.ndarray, ...]] | None:
        """:meth:`element_force` as a law of the compiled integrator
        (:data:`suspopt.integrator.compiled.LAWS`), each parameter (1, P, 1): the Taylor form
        as ``("poly3", (-k1, -k2, -k3))``; the exact form as the negated law's own constants
        ``(a, b, ℓ²)`` (``"link"``: ``(a + b / sqrt(ℓ² - w²)) w``; ``"carrella"``: ``(b /
        sqrt(w² + ℓ²) + a) w``) with ``w = rest + δ`` and the static part added back."""

        def rows(x) -> np.ndarray:
            return np.asarray(x, float).reshape(1, -1, 1)

        if self.series is not None:
            return ("poly3", tuple(rows(-np.asarray(k, float)) for k in self.series))
        name, constants = self.law(-1.0).compiled  # type: ignore[attr-defined]
        rest = np.zeros_like(constants[0]) if self.rest is None else self.rest
        preload = np.zeros_like(constants[0]) if self._preload is None else self._preload
        return (name, tuple(rows(c) for c in (*constants, rest, preload)))

    def slope(self) -> np.ndarray:
        """``dF/dδ`` at rest, (P,) [N/m] (a positive slope is a negative stiffness), by
        complex-step differentiation: ``Im F(i h) / h`` is exact to rounding for these
        analytic forces, the same for the exact and the Taylor form."""
        return (
            np.atleast_2d(self.force(np.full((1, 1), 1j * _COMPLEX_STEP))).imag[:, 0]
            / _COMPLEX_STEP
        )

    def coordinate(self, delta: np.ndarray) -> np.ndarray:
        """The mechanism coordinate ``w`` for the travel ``delta`` from rest [m]."""
        return delta if self.rest is None else self.rest + delta
