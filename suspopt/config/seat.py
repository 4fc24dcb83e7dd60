"""The ``seat:`` section: a seat isolator on the body and, optionally, the seated passenger.

One model per isolator ``kind`` (Sec 2.2, Ch. 8), joined in the discriminated union
:data:`SeatConfig`:

- ``ps``: passive spring and damper (Eq 2.40);
- ``nss1``: Carrella et al., inclined springs (Eq 2.41-2.45);
- ``nss2``: Le et al., bars and horizontal springs (Eq 2.46-2.52);
- ``nss3``: Yan et al., cam-roller-spring (Eq 2.53-2.58);
- ``nss4``: Antoniadis et al., KDamper with an inner mass (Eq 2.59-2.69).

The passenger (Sec 2.3, Table 2.3) is the optional ``passenger`` sub-key of the seat: it sits on
the seat mass and needs no other anchor. ``passenger: {}`` gives the Table 2.3 passenger; any
value of it can be overridden. Without it, ``mass`` is the seat and the passenger lumped (the
thesis's Ch. 8 optimisation: 13.6 + 81.4 = 95 kg).

Inputs and derived quantities. The thesis's design variables are the inputs (Tables 8.2, 8.4,
8.6, 8.8, 8.10); what the statics fix is derived (Sec 8.2.2) and never written in the config:

- PS: ``K_v`` given; ``X_ST = m g / K_v``.
- NSS1-NSS3: the geometry gives ``X_ST``; ``K_v = m g / X_ST`` and ``K_h = α K_v``.
- NSS4: ``K_S, K_v, K_h`` given; ``X_ST`` from Eq 2.64.

Here ``m`` is the whole load on the isolator: ``mass`` plus the passenger's segments. All
quantities SI: lengths in m, stiffnesses in N/m, dampings in N s/m, masses in kg.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Field, model_validator

from .base import Damping, Mass, Ratio, SeatLength, Section, Stiffness, bounds

__all__ = [
    "Position",
    "Segment",
    "Link",
    "Passenger",
    "PassiveSeat",
    "CarrellaSeat",
    "LeSeat",
    "YanSeat",
    "KDamperSeat",
    "SeatConfig",
    "TABLE_2_3",
]

#: [m] a point of the body relative to its centre of gravity
_BodyPoint = Annotated[float, bounds(-100.0, 100.0)]


class Position(Section):
    """Where the seat stands on the body (x + forward, y + right of the CG:
    docs/architecture.md#conventions)."""

    x: _BodyPoint = Field(
        0.0,
        description="longitudinal distance ahead of the body's centre of "
        "gravity [m] (Ch. 7: e = 0.4)",
    )
    y: _BodyPoint = Field(
        0.0, description="lateral distance to the right of the centre of gravity [m]"
    )


class Segment(Section):
    """One body part of the passenger and the spring-damper joining it to the part below."""

    mass: Mass = Field(description="mass of the body part m_i [kg]")
    stiffness: Stiffness = Field(description="stiffness k_i to the part below [N/m]")
    damping: Damping = Field(description="damping c_i to the part below [N s/m]")


class Link(Section):
    """A spring-damper between two body parts."""

    stiffness: Stiffness = Field(description="stiffness [N/m]")
    damping: Damping = Field(description="damping [N s/m]")


#: Table 2.3: mass [kg], stiffness [N/m] and damping [N s/m] of each part, and what its k, c
#: join it to; ``torso_back`` is the torso-back link (k_4, c_4, the "Torso (3-4)" row).
TABLE_2_3 = {
    "pelvis": (27.70, 25500.0, 378.0, "seat (k_8, c_8)"),
    "abdomen": (6.20, 8941.0, 298.0, "pelvis (k_7, c_7)"),
    "diaphragm": (0.46, 8941.0, 298.0, "abdomen (k_6, c_6)"),
    "thorax": (1.38, 8941.0, 298.0, "diaphragm (k_5, c_5)"),
    "torso": (33.33, 8941.0, 298.0, "thorax (k_3, c_3)"),
    "back": (6.94, 53460.0, 3651.0, "pelvis (k_2, c_2)"),
    "head": (6.20, 53460.0, 3651.0, "back (k_1, c_1)"),
}
_TORSO_BACK = (8941.0, 298.0)


def _segment(part: str):
    m, k, c, below = TABLE_2_3[part]
    return Field(
        default_factory=lambda: Segment(mass=m, stiffness=k, damping=c),
        description=f"m, k, c (Table 2.3: {m}, {k:g}, {c:g}); k and c join it to the "
        f"{below}; keys not given keep the table's values",
    )


class Passenger(Section):
    """The seated passenger of Sec 2.3 (Fig. 2.14, Table 2.3), Eq 2.70-2.77 as mended (slip:
    docs/thesis-slips.md#eq-270).

    Chain: seat - pelvis - abdomen - diaphragm - thorax - torso; the back is tied to the pelvis
    and to the torso; the head sits on the back. Each part's ``stiffness`` and ``damping`` join
    it to the part below it; ``torso_back`` is the torso-back link (k_4, c_4, the "Torso (3-4)"
    row of Table 2.3). A part given with some keys keeps the table's values for the others
    (``head: {mass: 7}``). The Table 2.3 masses sum to 82.21 kg, not the printed 81.4 kg; the
    table's masses are kept (slip: docs/thesis-slips.md#table-23).
    """

    pelvis: Segment = _segment("pelvis")
    abdomen: Segment = _segment("abdomen")
    diaphragm: Segment = _segment("diaphragm")
    thorax: Segment = _segment("thorax")
    torso: Segment = _segment("torso")
    back: Segment = _segment("back")
    head: Segment = _segment("head")
    torso_back: Link = Field(
        default_factory=lambda: Link(stiffness=_TORSO_BACK[0], damping=_TORSO_BACK[1]),
        description="torso-back link k_4, c_4 (Table 2.3, 'Torso (3-4)': 8941, 298)",
    )

    @model_validator(mode="before")
    @classmethod
    def _table_values_for_keys_not_given(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        data = dict(data)
        for part, (m, k, c, _) in TABLE_2_3.items():
            if isinstance(data.get(part), dict):
                data[part] = {"mass": m, "stiffness": k, "damping": c, **data[part]}
        if isinstance(data.get("torso_back"), dict):
            data["torso_back"] = {
                "stiffness": _TORSO_BACK[0],
                "damping": _TORSO_BACK[1],
                **data["torso_back"],
            }
        return data


class _Seat(Section):
    """Fields every isolator has."""

    mass: Mass = Field(
        description="mass moving on the isolator m_se [kg]: the seat alone (13.6) with a "
        "passenger model, the seat and the lumped passenger (Ch. 8: 95) without one"
    )
    damping: Damping = Field(
        description="damper C_v [N s/m]: floor to seat (PS, NSS1-NSS3), seat to inner mass (NSS4)"
    )
    position: Position = Field(
        default_factory=Position, description="where the seat stands on the body"
    )
    coupling: Literal["one_way", "two_way"] = Field(
        "one_way",
        description="one_way: the body motion drives the seat and the seat does not "
        "act back (the thesis's way); two_way: the seat's dynamic force also acts on the body "
        "(its weight is not added to the vehicle's statics: the body mass is as written)",
    )
    passenger: Passenger | None = Field(
        None, description="seated passenger of Sec 2.3 on the seat mass ({} for Table 2.3)"
    )


class _NegativeStiffnessSeat(_Seat):
    """An isolator with a geometric (negative-stiffness) mechanism."""

    form: Literal["exact", "taylor"] = Field(
        "exact",
        description="mechanism force: exact geometry (default) or its 3rd-order "
        "Taylor series about the static equilibrium (Eq 2.45, 2.52)",
    )


class PassiveSeat(_Seat):
    """PS: linear spring and damper, Eq 2.40 with the seat mass accelerating, x'' (slip:
    docs/thesis-slips.md#eq-240)."""

    kind: Literal["ps"] = Field(description="passive seat, Eq 2.40")
    stiffness: Stiffness = Field(description="spring K_v [N/m] (Table 8.2: 1e4-1.5e5)")


class CarrellaSeat(_NegativeStiffnessSeat):
    """NSS1 (Carrella et al.): two inclined springs, horizontal at equilibrium, Eq 2.41-2.45.

    Inputs as Table 8.4: ``gamma``, ``stiffness_ratio``, ``wall_distance``, ``damping``;
    ``L_o = a_o/γ``, ``X_ST = sqrt(L_o² - a_o²)``, ``K_v = m g/X_ST``, ``K_h = α K_v``.
    """

    kind: Literal["nss1"] = Field(description="Carrella et al. isolator, Eq 2.41-2.45")
    stiffness_ratio: Ratio = Field(description="α = K_h/K_v [-] (Table 8.4: 0-5)")
    gamma: float = Field(gt=0, lt=1, description="γ = a_o/L_o = cos θ_o [-] (Table 8.4: 0.01-0.99)")
    wall_distance: SeatLength = Field(
        description="a_o, horizontal distance from the seat "
        "axis to the springs' anchors [m] (Table 8.4: 0.1-0.3)"
    )


class LeSeat(_NegativeStiffnessSeat):
    """NSS2 (Le et al.): two bars of length b pushed by horizontal springs, Eq 2.46-2.52.

    Inputs as Table 8.6; ``X_ST = sqrt(b² - (a_o - L_o)²)``, ``K_v = m g/X_ST``, ``K_h = α K_v``;
    ``γ1 = b/L_o``, ``γ2 = a_o/L_o``.
    """

    kind: Literal["nss2"] = Field(description="Le et al. isolator, Eq 2.46-2.52")
    stiffness_ratio: Ratio = Field(description="α = K_h/K_v [-] (Table 8.6: 0-1)")
    spring_free_length: SeatLength = Field(
        description="L_o, free length of a horizontal spring [m] (Table 8.6: 0.1-0.3)"
    )
    wall_distance: SeatLength = Field(
        description="a_o, distance from the seat axis to a spring's anchor [m] (Table 8.6: 0.1-0.3)"
    )
    bar_length: SeatLength = Field(description="b, length of a bar [m] (Table 8.6: 0.05-0.3)")

    @model_validator(mode="after")
    def _static_deflection_exists(self) -> LeSeat:
        gap = abs(self.wall_distance - self.spring_free_length)
        if self.bar_length <= gap:
            raise ValueError(
                f"NSS2 has no static deflection: bar_length b = {self.bar_length} must exceed "
                f"|wall_distance - spring_free_length| = {gap:.6g} so that X_ST = "
                f"sqrt(b^2 - (a_o - L_o)^2) > 0 (Table 8.7, constraint 4)"
            )
        return self


class YanSeat(_NegativeStiffnessSeat):
    """NSS3 (Yan et al.): cam-roller-spring mechanism, Eq 2.53-2.58.

    Inputs as Table 8.8 plus the precompression ``u_2``; ``X_ST = sqrt((R + r)² - (d + r)²)``,
    ``K_v = m g/X_ST``, ``K_h = α K_v``.
    """

    kind: Literal["nss3"] = Field(description="Yan et al. isolator, Eq 2.53-2.58")
    stiffness_ratio: Ratio = Field(description="α = K_h/K_v [-] (Table 8.8: 0-5)")
    cam_radius: SeatLength = Field(description="R, cam radius [m] (Table 8.8: 0.01-0.25)")
    roller_radius: SeatLength = Field(description="r, roller radius [m] (Table 8.8: 0.01-0.25)")
    cam_offset: Annotated[float, bounds(0.0, 10.0)] = Field(
        description="d, distance from the cam centre [m] (Table 8.8: 0-0.25)"
    )
    precompression: SeatLength = Field(
        description="u_2, precompression of the horizontal springs [m]; no default on purpose: "
        "Sec 2.2.4 uses 0.01, Ch. 8 (Sec 8.2.2) 0.001 (slip: docs/thesis-slips.md#sec-224)"
    )

    @model_validator(mode="after")
    def _static_deflection_exists(self) -> YanSeat:
        if self.cam_offset >= self.cam_radius:
            raise ValueError(
                f"NSS3 has no static deflection: cam_offset d = {self.cam_offset} must be less "
                f"than cam_radius R = {self.cam_radius} (Eq 2.54) so that X_ST = "
                f"sqrt((R + r)^2 - (d + r)^2) > 0"
            )
        return self


class KDamperSeat(_NegativeStiffnessSeat):
    """NSS4 (Antoniadis et al.): KDamper with an inner mass m_d, Eq 2.59-2.69.

    ``K_S`` joins floor and seat; ``K_v`` and ``C_v`` join seat and inner mass; the negative
    stiffness mechanism (two horizontal springs K_h on bars of length b) joins floor and inner
    mass, its hinge ``u_0`` above the horizontal at rest. Inputs as Table 8.10; ``X_ST`` from
    Eq 2.64.
    """

    kind: Literal["nss4"] = Field(description="KDamper, Eq 2.59-2.69")
    support_stiffness: Stiffness = Field(
        description="K_S, floor to seat [N/m] (Table 8.10: 1e4-1.5e5)"
    )
    inner_stiffness: Stiffness = Field(
        description="K_v, seat to inner mass [N/m] (Table 8.10: 2e3-7e4)"
    )
    horizontal_stiffness: Annotated[float, bounds(0.0, 1e10)] = Field(
        description="K_h, each horizontal spring [N/m] (Table 8.10: 2e3-7e4)"
    )
    spring_free_length: SeatLength = Field(
        description="L_o, free length of a horizontal spring [m] (Table 8.10: 0.1-0.3)"
    )
    wall_distance: SeatLength = Field(description="a_o [m] (Table 8.10: 0.1-0.3)")
    bar_length: SeatLength = Field(description="b, bar length [m] (Table 8.10: 0.1-0.3)")
    hinge_offset: Annotated[float, bounds(-10.0, 10.0)] = Field(
        0.001,
        description="u_0, the hinge's height above the horizontal at rest [m] (Sec 2.2.5: 1 mm)",
    )
    inner_mass: Mass = Field(1.0, description="m_d, inner mass [kg] (Sec 2.2.5: 1)")

    @model_validator(mode="after")
    def _hinge_within_bar(self) -> KDamperSeat:
        if abs(self.hinge_offset) >= self.bar_length:
            raise ValueError(
                f"NSS4: |hinge_offset| u_0 = {abs(self.hinge_offset)} must be "
                f"less than bar_length b = {self.bar_length} (Eq 2.65 needs "
                f"|u| < b)"
            )
        return self


SeatConfig = Annotated[
    PassiveSeat | CarrellaSeat | LeSeat | YanSeat | KDamperSeat, Field(discriminator="kind")
]
