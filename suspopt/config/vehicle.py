"""The ``vehicle:`` section: body, corners (spring, damper, tyre), anti-roll bars.

All quantities SI. The body mass and inertias are those *of the model* (the thesis's QC uses
``m_s/4``, HC1/HC2 ``m_s/2`` and ``I_x/2`` or ``I_y/2``; Sec 2.1.1-2.1.3), so a preset never
rescales what the user wrote.

A corner's damper is passive (``c``) or semi-active (``kind: semi_active``: ``c_min``, ``c_max``
and a control ``law``, Sec 2.1.6); the controller's sampling and the CDF threshold are set in
the ``control:`` section (:mod:`suspopt.config.control`).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Annotated, Any, ClassVar, Literal

from pydantic import Discriminator, Field, Tag, create_model, model_validator

from ..control.laws import LAWS, PARAMETERS
from .base import (
    CubicStiffness,
    Damping,
    Inertia,
    Mass,
    Section,
    Stiffness,
    TorsionalStiffness,
    VehicleLength,
    bounds,
    quantity,
)

__all__ = [
    "Preset",
    "PRESETS",
    "DOF_FIELDS",
    "CORNER_NAMES",
    "PRESET_CORNERS",
    "PRESET_BODY_DOFS",
    "DAMPER_LAWS",
    "LAW_PARAMETERS",
    "Spring",
    "Tyre",
    "PassiveDamper",
    "SemiActiveDamper",
    "Damper",
    "Corner",
    "Body",
    "AntiRollBars",
    "Vehicle",
    "corner_defaults_schema",
]


@dataclass(frozen=True)
class Preset:
    """A vehicle model: the rigid body's degrees of freedom (a subset of heave, roll and
    pitch) and its corners (thesis names: F1 front right, F2 front left, R1 rear right, R2
    rear left). What the body needs follows from its DOFs (:data:`DOF_FIELDS`), and where a
    corner sits from its name and the DOFs (a front corner ``a_front`` ahead of the centre of
    gravity when the body pitches, a right one ``b_right`` to the right when it rolls)."""

    name: str
    label: str
    body_dofs: tuple[str, ...]
    corners: tuple[str, ...]

    @property
    def required_body(self) -> tuple[str, ...]:
        """The body fields this preset needs besides the mass: each DOF's inertia and lever
        arms."""
        return tuple(f for dof in self.body_dofs for f in DOF_FIELDS[dof] if f != "mass")


#: What each body DOF needs of the body: its inertia (or the mass) and the corners' lever arms.
DOF_FIELDS = {
    "heave": ("mass",),
    "roll": ("roll_inertia", "b_right", "b_left"),
    "pitch": ("pitch_inertia", "a_front", "a_rear"),
}
#: The vehicle models, all presets of one corner-based model (Eq 2.1, 2.5-2.6, 2.13-2.14,
#: 2.19-2.21). Adding a preset is adding one entry here.
PRESETS: dict[str, Preset] = {
    p.name: p
    for p in (
        Preset("quarter", "QC", ("heave",), ("F1",)),
        Preset("half_roll", "HC1", ("heave", "roll"), ("F1", "F2")),
        Preset("half_pitch", "HC2", ("heave", "pitch"), ("F1", "R1")),
        Preset("full", "FC", ("heave", "roll", "pitch"), ("F1", "F2", "R1", "R2")),
    )
}
#: Corners of each preset.
PRESET_CORNERS: dict[str, tuple[str, ...]] = {k: p.corners for k, p in PRESETS.items()}
#: Body degrees of freedom of each preset.
PRESET_BODY_DOFS: dict[str, tuple[str, ...]] = {k: p.body_dofs for k, p in PRESETS.items()}
#: Every corner name of the presets, in order.
CORNER_NAMES = tuple(dict.fromkeys(c for p in PRESETS.values() for c in p.corners))


class Spring(Section):
    """Suspension spring, Eq 2.30 (linear) or Eq 2.31 (Duffing): F_K = k_l ST + k_nl ST^3."""

    linear: Stiffness = Field(description="linear stiffness k_l [N/m]")
    cubic: CubicStiffness = Field(
        0.0,
        description="cubic (Duffing) coefficient k_nl [N/m^3]; "
        "positive hardens (the thesis's case), negative softens",
    )


class Tyre(Section):
    """Tyre spring and optional damper, Eq 2.28-2.29."""

    stiffness: Stiffness = Field(description="tyre vertical stiffness k_T [N/m]")
    damping: Damping = Field(
        0.0, description="tyre damping c_T [N s/m] (Eq 2.29; the thesis mostly takes 0)"
    )


class PassiveDamper(Section):
    """Passive suspension damper, Eq 2.32: F_C = c dST/dt."""

    kind: Literal["passive"] = Field("passive", description="damper type (default passive)")
    c: Damping = Field(description="viscous damping coefficient [N s/m]")

    #: field holding the coefficient of the linear analyses (modes, frequency response)
    soft_field: ClassVar[str] = "c"


#: Control laws of a semi-active damper, from :data:`suspopt.control.laws.LAWS` (which has
#: their exact definitions).
DAMPER_LAWS = tuple(LAWS)
#: Law parameters of SemiActiveDamper and the laws that use them.
LAW_PARAMETERS: dict[str, tuple[str, ...]] = {
    name: tuple(law.name for law in LAWS.values() if name in law.parameters) for name in PARAMETERS
}


class _SemiActiveFields(Section):
    """Controllable damper switched or varied between ``c_min`` and ``c_max`` (Sec 2.1.6).

    ``law`` picks the control law (:data:`suspopt.control.laws.LAWS`: ``sh_2`` Eq 2.34,
    ``sh_l`` Eq 2.35, ``add`` Eq 2.36, ``sh_add_1`` Eq 2.37, ``sh_add_2`` Eq 2.39,
    ``groundhook`` and ``hybrid``, named in Sec 4.4), each defined there with the project's
    signs (``ST = z_s - z_u``, extension positive); the law's parameters are fields of their
    own (:data:`suspopt.control.laws.PARAMETERS`), given exactly for the laws that take them.
    The linear analyses (modal, frequency response) see the soft state ``c_min``.
    """

    kind: Literal["semi_active"] = Field(description="damper type")
    c_min: Damping = Field(description="soft damping coefficient C_min [N s/m]")
    c_max: Damping = Field(description="stiff damping coefficient C_max [N s/m], at least c_min")
    law: Literal[DAMPER_LAWS] = Field(description="control law: " + " | ".join(DAMPER_LAWS))  # type: ignore[valid-type]

    soft_field: ClassVar[str] = "c_min"

    @model_validator(mode="after")
    def _check(self) -> _SemiActiveFields:
        if self.c_max < self.c_min:
            raise ValueError(f"c_max ({self.c_max}) must be at least c_min ({self.c_min})")
        for name, laws in LAW_PARAMETERS.items():
            given = getattr(self, name) is not None
            if self.law in laws and not given:
                raise ValueError(f"law {self.law!r} needs {name}")
            if given and self.law not in laws:
                raise ValueError(
                    f"{name} is a parameter of law {' / '.join(laws)}, not of "
                    f"{self.law!r}; remove it"
                )
        return self


def _parameter_field(parameter) -> tuple[Any, Any]:
    """The config field of a law parameter: optional, in its range, described."""
    laws = " and ".join(LAW_PARAMETERS[parameter.name])
    bound = {"gt" if parameter.low_open else "ge": parameter.low}
    return (
        quantity(parameter.low, parameter.high) | None,
        Field(
            None,
            **bound,
            le=parameter.high,
            description=f"{parameter.description} (law{'s' if ' and ' in laws else ''} "
            f"{laws} only)",
        ),
    )


SemiActiveDamper = create_model(  # type: ignore[call-overload]  # (fields from the laws)
    "SemiActiveDamper",
    __base__=_SemiActiveFields,
    __module__=__name__,
    __doc__=_SemiActiveFields.__doc__,
    **{name: _parameter_field(p) for name, p in PARAMETERS.items()},
)


def _damper_kind(value: Any) -> str:
    """Tag of a damper: its ``kind`` (``passive`` when omitted, as in every passive config)."""
    if isinstance(value, dict):
        return value.get("kind", "passive")
    return getattr(value, "kind", "passive")


Damper = Annotated[
    Annotated[PassiveDamper, Tag("passive")] | Annotated[SemiActiveDamper, Tag("semi_active")],
    Discriminator(
        _damper_kind,
        custom_error_type="damper_kind",
        custom_error_message="unknown damper kind; use 'passive' (default) or 'semi_active'",
    ),
]


class Corner(Section):
    """One corner: an unsprung mass on a tyre, joined to the body by a spring and a damper."""

    unsprung_mass: Mass = Field(description="unsprung mass m_u [kg]")
    tyre: Tyre
    spring: Spring
    damper: Damper


class Body(Section):
    """Sprung mass of the model and the corner geometry.

    Corner positions follow docs/architecture.md#conventions: ``x = +a_front`` (front) /
    ``-a_rear`` (rear),
    ``y = +b_right`` (right, F1/R1) / ``-b_left`` (left, F2/R2).
    """

    mass: Mass = Field(description="sprung mass of the model [kg] (QC: m_s/4, HC: m_s/2)")
    roll_inertia: Inertia | None = Field(None, description="roll inertia about x [kg m^2]")
    pitch_inertia: Inertia | None = Field(None, description="pitch inertia about y [kg m^2]")
    a_front: VehicleLength | None = Field(None, description="CG to front axle a_F [m]")
    a_rear: VehicleLength | None = Field(None, description="CG to rear axle a_R [m]")
    b_right: VehicleLength | None = Field(None, description="CG to right wheels b_1 [m]")
    b_left: VehicleLength | None = Field(None, description="CG to left wheels b_2 [m]")


class AntiRollBars(Section):
    """Torsional anti-roll bar stiffness per axle [N m/rad].

    Modelled as a torsional spring between the body roll angle and the axle's wheel-pair roll
    angle ``(z_right - z_left)/(b_right + b_left)`` (slip: docs/thesis-slips.md#eq-211).
    """

    front: TorsionalStiffness = Field(0.0, description="front bar k_AR,F [N m/rad]")
    rear: TorsionalStiffness = Field(0.0, description="rear bar k_AR,R [N m/rad]")


def _deep_merge(base: dict, over: dict) -> dict:
    """``over`` on top of ``base``. A sub-section that names another ``kind`` (a semi-active
    damper over a passive default) replaces the default's instead of mixing keys of both
    kinds; one that names no ``kind`` is of the default's kind (``{c_max: 4000}`` over a
    semi-active default changes its ``c_max``)."""
    out = dict(base)
    for key, value in over.items():
        if (
            isinstance(value, dict)
            and isinstance(out.get(key), dict)
            and value.get("kind", _damper_kind(out[key])) == _damper_kind(out[key])
        ):
            out[key] = _deep_merge(out[key], value)
        else:
            out[key] = value
    return out


class Vehicle(Section):
    """A rigid body on corners; the four thesis models are presets
    (docs/architecture.md#conventions)."""

    preset: Literal[tuple(PRESETS)] = Field(  # type: ignore[valid-type]
        description=" | ".join(f"{p.name} ({p.label})" for p in PRESETS.values())
    )
    body: Body
    corner_defaults: dict[str, Any] | None = Field(
        None, description="values shared by every corner; a corner's own keys override them"
    )
    corners: dict[str, Corner] = Field(
        default_factory=dict, description="corners by thesis name: F1, F2, R1, R2"
    )
    anti_roll_bars: AntiRollBars = Field(default_factory=AntiRollBars)
    tyre_lift_off: bool = Field(
        False,
        description="tyres cannot pull (no tensile force); the "
        "thesis assumes permanent contact, so off by default",
    )
    gravity: Annotated[float, bounds(0.1, 100.0)] = Field(
        9.81, description="gravitational acceleration [m/s^2]"
    )

    @model_validator(mode="before")
    @classmethod
    def _apply_corner_defaults(cls, data: Any) -> Any:
        if not isinstance(data, dict) or not isinstance(data.get("corners", {}), dict | None):
            return data  # (the field's own type error names it)
        corners = dict(data.get("corners") or {})
        defaults = data.get("corner_defaults") or {}
        preset = data.get("preset")
        if (
            defaults
            and isinstance(defaults, dict)
            and isinstance(preset, str)
            and preset in PRESET_CORNERS
        ):
            for name in PRESET_CORNERS[preset]:
                own = corners.get(name) or {}
                corners[name] = _deep_merge(defaults, own) if isinstance(own, dict) else own
        data = dict(data)
        data["corners"] = corners
        return data

    @model_validator(mode="after")
    def _check_preset(self) -> Vehicle:
        wanted = PRESET_CORNERS[self.preset]
        extra = sorted(set(self.corners) - set(wanted))
        if extra:
            raise ValueError(
                f"preset {self.preset!r} has corners {list(wanted)}; unexpected corner(s) {extra}"
            )
        missing = [c for c in wanted if c not in self.corners]
        if missing:
            raise ValueError(
                f"preset {self.preset!r} needs corners {list(wanted)}; "
                f"missing {missing} (give them or corner_defaults)"
            )
        need = [f for f in PRESETS[self.preset].required_body if getattr(self.body, f) is None]
        if need:
            raise ValueError(f"preset {self.preset!r} needs body.{', body.'.join(need)}")
        if (self.anti_roll_bars.front or self.anti_roll_bars.rear) and "roll" not in PRESETS[
            self.preset
        ].body_dofs:
            rolling = " or ".join(k for k, p in PRESETS.items() if "roll" in p.body_dofs)
            raise ValueError(f"anti_roll_bars need a model with roll ({rolling})")
        return self


def _partial(defs: dict, name: str) -> str:
    """The name of a copy of ``defs[name]`` in which every key is optional, and so are the keys
    of the sections it refers to (added to ``defs`` as ``<name>Partial``). A union of such
    sections (the damper kinds) takes any of them: a part without its ``kind`` is of the
    default's kind (``_deep_merge``), so it may fit either."""
    partial = name + "Partial"
    if partial not in defs:
        schema = copy.deepcopy(defs[name])
        defs[partial] = schema
        props = schema.get("properties", {})
        schema.pop("required", None)
        schema["title"] = partial
        schema["description"] = (
            schema.get("description", "") + " Here every key may be missing: a corner's own "
            "keys and vehicle.corner_defaults together must give them."
        ).strip()
        _refs_to_partial(defs, props)
        for prop in props.values():
            if "oneOf" in prop:
                prop["anyOf"] = prop.pop("oneOf")
    return partial


def _refs_to_partial(defs: dict, node: Any) -> None:
    """Point every ``$ref`` under ``node`` at the partial copy of its section."""
    if isinstance(node, dict):
        ref = node.get("$ref")
        if isinstance(ref, str) and ref.startswith("#/$defs/"):
            node["$ref"] = "#/$defs/" + _partial(defs, ref[len("#/$defs/") :])
        for value in node.values():
            _refs_to_partial(defs, value)
    elif isinstance(node, list):
        for value in node:
            _refs_to_partial(defs, value)


def corner_defaults_schema(defs: dict) -> None:
    """Make the JSON schema's ``Vehicle`` say what :meth:`Vehicle._apply_corner_defaults` does.

    The merge of ``corner_defaults`` into each corner happens before validation, where a JSON
    schema cannot see it. So in the schema ``corner_defaults`` is a corner whose keys are all
    optional; when it is given, so are a corner's (an empty corner, ``F1: {}`` or ``F1:``,
    takes the defaults; the loader checks the merged corner), and without it every corner is
    complete. The corners are named (F1, F2, R1, R2) so that an editor completes them.
    ``defs`` is the schema's ``$defs``, changed in place."""
    vehicle = defs["Vehicle"]
    props = vehicle["properties"]
    part = {"$ref": "#/$defs/" + _partial(defs, "Corner")}
    names = CORNER_NAMES
    props["corner_defaults"]["anyOf"] = [part, {"type": "null"}]
    props["corners"].pop("additionalProperties")
    props["corners"]["properties"] = {name: {"anyOf": [part, {"type": "null"}]} for name in names}
    props["corners"]["additionalProperties"] = False
    vehicle["if"] = {
        "required": ["corner_defaults"],
        "properties": {"corner_defaults": {"type": "object", "minProperties": 1}},
    }
    vehicle["else"] = {
        "properties": {
            "corners": {"properties": {name: {"$ref": "#/$defs/Corner"} for name in names}}
        }
    }
