"""The ``vehicle:`` section: body, corners (spring, damper, tyre), anti-roll bars.

All quantities SI. The body mass and inertias are those *of the model* (the thesis's QC uses
``m_s/4``, HC1/HC2 ``m_s/2`` and ``I_x/2`` or ``I_y/2``; Sec 2.1.1-2.1.3), so a preset never
rescales what the user wrote.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, PositiveFloat, NonNegativeFloat, model_validator

from .base import Section

__all__ = [
    "PRESET_CORNERS", "PRESET_BODY_DOFS", "Spring", "Tyre", "Damper", "Corner", "Body",
    "AntiRollBars", "Vehicle",
]

#: Corners of each preset (thesis names: F1 front right, F2 front left, R1 rear right, R2 rear left).
PRESET_CORNERS: dict[str, tuple[str, ...]] = {
    "quarter": ("F1",),
    "half_roll": ("F1", "F2"),
    "half_pitch": ("F1", "R1"),
    "full": ("F1", "F2", "R1", "R2"),
}
#: Body degrees of freedom of each preset (Eq 2.1, 2.5-2.6, 2.13-2.14, 2.19-2.21).
PRESET_BODY_DOFS: dict[str, tuple[str, ...]] = {
    "quarter": ("heave",),
    "half_roll": ("heave", "roll"),
    "half_pitch": ("heave", "pitch"),
    "full": ("heave", "roll", "pitch"),
}
#: Body fields each preset needs.
_REQUIRED_BODY = {
    "quarter": (),
    "half_roll": ("roll_inertia", "b_right", "b_left"),
    "half_pitch": ("pitch_inertia", "a_front", "a_rear"),
    "full": ("roll_inertia", "pitch_inertia", "a_front", "a_rear", "b_right", "b_left"),
}


class Spring(Section):
    """Suspension spring, Eq 2.30 (linear) or Eq 2.31 (Duffing): F_K = k_l ST + k_nl ST^3."""

    linear: PositiveFloat = Field(description="linear stiffness k_l [N/m]")
    cubic: float = Field(0.0, description="cubic (Duffing) coefficient k_nl [N/m^3]; "
                         "positive hardens (the thesis's case), negative softens")


class Tyre(Section):
    """Tyre spring and optional damper, Eq 2.28-2.29."""

    stiffness: PositiveFloat = Field(description="tyre vertical stiffness k_T [N/m]")
    damping: NonNegativeFloat = Field(0.0, description="tyre damping c_T [N s/m] (Eq 2.29; "
                                      "the thesis mostly takes 0)")


class Damper(Section):
    """Suspension damper, Eq 2.32: F_C = c dST/dt."""

    kind: Literal["passive"] = Field("passive", description="damper type")
    c: NonNegativeFloat = Field(description="viscous damping coefficient [N s/m]")


class Corner(Section):
    """One corner: an unsprung mass on a tyre, joined to the body by a spring and a damper."""

    unsprung_mass: PositiveFloat = Field(description="unsprung mass m_u [kg]")
    tyre: Tyre
    spring: Spring
    damper: Damper


class Body(Section):
    """Sprung mass of the model and the corner geometry.

    Corner positions follow DESIGN.md: ``x = +a_front`` (front) / ``-a_rear`` (rear),
    ``y = +b_right`` (right, F1/R1) / ``-b_left`` (left, F2/R2).
    """

    mass: PositiveFloat = Field(description="sprung mass of the model [kg] (QC: m_s/4, HC: m_s/2)")
    roll_inertia: PositiveFloat | None = Field(None, description="roll inertia about x [kg m^2]")
    pitch_inertia: PositiveFloat | None = Field(None, description="pitch inertia about y [kg m^2]")
    a_front: PositiveFloat | None = Field(None, description="CG to front axle a_F [m]")
    a_rear: PositiveFloat | None = Field(None, description="CG to rear axle a_R [m]")
    b_right: PositiveFloat | None = Field(None, description="CG to right wheels b_1 [m]")
    b_left: PositiveFloat | None = Field(None, description="CG to left wheels b_2 [m]")


class AntiRollBars(Section):
    """Torsional anti-roll bar stiffness per axle [N m/rad].

    Modelled as a torsional spring between the body roll angle and the axle's wheel-pair roll
    angle ``(z_right - z_left)/(b_right + b_left)`` (ERRATA for Eq 2.11-2.12, 2.25).
    """

    front: NonNegativeFloat = Field(0.0, description="front bar k_AR,F [N m/rad]")
    rear: NonNegativeFloat = Field(0.0, description="rear bar k_AR,R [N m/rad]")


def _deep_merge(base: dict, over: dict) -> dict:
    out = dict(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _deep_merge(out[key], value)
        else:
            out[key] = value
    return out


class Vehicle(Section):
    """A rigid body on corners; the four thesis models are presets (DESIGN.md)."""

    preset: Literal["quarter", "half_roll", "half_pitch", "full"] = Field(
        description="quarter (QC) | half_roll (HC1) | half_pitch (HC2) | full (FC)")
    body: Body
    corner_defaults: dict[str, Any] | None = Field(
        None, description="values shared by every corner; a corner's own keys override them")
    corners: dict[str, Corner] = Field(default_factory=dict,
                                       description="corners by thesis name: F1, F2, R1, R2")
    anti_roll_bars: AntiRollBars = Field(default_factory=AntiRollBars)
    tyre_lift_off: bool = Field(False, description="tyres cannot pull (no tensile force); the "
                                "thesis assumes permanent contact, so off by default")
    gravity: PositiveFloat = Field(9.81, description="gravitational acceleration [m/s^2]")

    @model_validator(mode="before")
    @classmethod
    def _apply_corner_defaults(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        defaults = data.get("corner_defaults") or {}
        preset = data.get("preset")
        corners = dict(data.get("corners") or {})
        if defaults and preset in PRESET_CORNERS and isinstance(defaults, dict):
            for name in PRESET_CORNERS[preset]:
                own = corners.get(name) or {}
                corners[name] = _deep_merge(defaults, own) if isinstance(own, dict) else own
        data = dict(data)
        data["corners"] = corners
        return data

    @model_validator(mode="after")
    def _check_preset(self) -> "Vehicle":
        wanted = PRESET_CORNERS[self.preset]
        extra = sorted(set(self.corners) - set(wanted))
        if extra:
            raise ValueError(f"preset {self.preset!r} has corners {list(wanted)}; "
                             f"unexpected corner(s) {extra}")
        missing = [c for c in wanted if c not in self.corners]
        if missing:
            raise ValueError(f"preset {self.preset!r} needs corners {list(wanted)}; "
                             f"missing {missing} (give them or corner_defaults)")
        need = [f for f in _REQUIRED_BODY[self.preset] if getattr(self.body, f) is None]
        if need:
            raise ValueError(f"preset {self.preset!r} needs body.{', body.'.join(need)}")
        if (self.anti_roll_bars.front or self.anti_roll_bars.rear) and \
                self.preset not in ("half_roll", "full"):
            raise ValueError("anti_roll_bars need a model with roll (half_roll or full)")
        return self
