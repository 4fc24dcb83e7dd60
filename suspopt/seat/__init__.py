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

from .design import (
    CONSTRAINT_UNITS,
    passenger_mass_change,
    seat_constraints,
    seat_static_deflection,
)
from .mechanisms import (
    Mechanism,
    nss1_force,
    nss1_static_deflection,
    nss1_taylor,
    nss2_force,
    nss2_static_deflection,
    nss2_taylor,
    nss3_contact_limit,
    nss3_force,
    nss3_static_deflection,
    nss3_taylor,
    nss4_force,
    nss4_static_deflection,
    nss4_taylor,
    ps_static_deflection,
    vertical_stiffness,
)
from .model import (
    PASSENGER_PARTS,
    SIGNAL_HEADS,
    SeatModel,
    base_transmissibility,
    build_attachments,
    build_seat,
    linearise,
    natural_frequencies,
    seat_network,
    signal_units,
)

__all__ = [
    "PASSENGER_PARTS",
    "SIGNAL_HEADS",
    "SeatModel",
    "Mechanism",
    "ps_static_deflection",
    "vertical_stiffness",
    "nss1_static_deflection",
    "nss1_force",
    "nss1_taylor",
    "nss2_static_deflection",
    "nss2_force",
    "nss2_taylor",
    "nss3_static_deflection",
    "nss3_force",
    "nss3_taylor",
    "nss3_contact_limit",
    "nss4_static_deflection",
    "nss4_force",
    "nss4_taylor",
    "build_seat",
    "build_attachments",
    "seat_network",
    "linearise",
    "base_transmissibility",
    "natural_frequencies",
    "seat_static_deflection",
    "seat_constraints",
    "CONSTRAINT_UNITS",
    "passenger_mass_change",
    "signal_units",
]
