"""The FMU's outputs: every signal of the design's signal table (:func:`suspopt.result.
signal_table`), as the C runtime computes it from the network's quantities.

Each signal of the table is one of the network's quantities at the current state - a DOF's
displacement, velocity or acceleration, a road input, an element's deformation, its rate, its
elastic, viscous or total force, its damping coefficient in force, a tyre's static load, the
body's motion under the seat - or a difference of two of them, the seat's travel margin, or a
controller record. :func:`add_outputs` maps the table's names to those recipes; a signal this
module does not know is refused by name (the FMU would lack it), so a new signal of the table
cannot silently go missing from the FMU. The quantities' layout ``Q`` is the runtime's
(``sources/runtime.c``, ``su_quantities``).
"""

from __future__ import annotations

import re

import numpy as np

from ..errors import ConfigError
from ..result import signal_table
from .description import RECORDS, Description

__all__ = ["add_outputs", "quantity_layout", "fmi_name"]

VALUE, DIFF, MARGIN, RECORD = range(4)

#: One-line descriptions of the signal heads (the FMU's variables' ``description``).
_DESCRIPTIONS = {
    "body": "body {dof} {what}",
    "wheel": "wheel {corner} {what}",
    "travel": "suspension travel ST = z_s + y phi - x theta - z_u (Eq 2.3)",
    "travel_vel": "suspension travel rate",
    "tyre_deflection": "tyre deflection TD = z_u - z_road (Eq 2.4)",
    "tyre_force": "tyre normal load, compression positive (static load less F_T)",
    "spring_force": "spring force F_K = k_l ST + k_nl ST^3 (Eq 2.30-2.31)",
    "damper_force": "damper force F_C = c dST/dt (Eq 2.32)",
    "damping": "damper coefficient in force",
    "road": "road height under the wheel",
    "road_vel": "road height rate under the wheel",
    "damper_state": "damper state (c - C_min)/(C_max - C_min): 0 soft, 1 stiff",
    "control_condition": "control law condition X of the latest sample",
    "control_threshold": "control threshold T in force",
}
_WHAT = {"": "displacement", "vel": "velocity", "acc": "acceleration"}


def quantity_layout(n: int, nu: int, R: int) -> dict[str, int]:
    """Where each quantity starts in the runtime's vector ``Q`` (module docstring)."""
    sizes = [
        ("q", n),
        ("v", n),
        ("a", n),
        ("u", nu),
        ("ud", nu),
        ("d", R),
        ("dv", R),
        ("f_elastic", R),
        ("f_viscous", R),
        ("f_total", R),
        ("c_now", R),
        ("static", R),
        ("base", 3),
        ("mech", 1),
    ]
    layout, at = {}, 0
    for name, size in sizes:
        layout[name] = at
        at += size
    layout["size"] = at
    return layout


def fmi_name(name: str) -> str:
    """``name`` as an FMI structured name: letters, digits and ``_`` between dots, each part
    starting with a letter or ``_``."""
    parts = [re.sub(r"[^A-Za-z0-9_]", "_", p) or "_" for p in name.split(".")]
    return ".".join(p if not p[0].isdigit() else "_" + p for p in parts)


def _derivative(suffix: str) -> str:
    return {"": "q", "_vel": "v", "_acc": "a", "_x": "q"}[suffix]


def _vehicle(name: str, d: Description, Q: dict, group_row) -> tuple[int, int, int, str] | None:
    """The recipe of a vehicle signal, or None."""
    corners, dofs = d.info["corners"], d.info["dof_names"]
    head, _, rest = name.partition(".")
    if head == "body":
        dof, _, deriv = rest.partition("_")
        j = dofs.index(f"body.{dof}")
        what = _WHAT[deriv]
        return VALUE, Q[_derivative("_" + deriv if deriv else "")] + j, 0, f"body {dof} {what}"
    if head == "wheel":
        corner, _, signal = rest.partition(".")
        deriv = signal.partition("_")[2]
        j = dofs.index(f"wheel.{corner}")
        what = _WHAT[deriv]
        return VALUE, Q[_derivative("_" + deriv if deriv else "")] + j, 0, f"wheel {corner} {what}"
    if rest not in corners:
        return None
    c = corners.index(rest)
    per_row = {
        "travel": ("suspension", "d"),
        "travel_vel": ("suspension", "dv"),
        "tyre_deflection": ("tyre", "d"),
        "spring_force": ("suspension", "f_elastic"),
        "damper_force": ("suspension", "f_viscous"),
        "damping": ("suspension", "c_now"),
    }
    text = _DESCRIPTIONS.get(head, head) + f" at {rest}"
    if head in per_row:
        group, quantity = per_row[head]
        return VALUE, Q[quantity] + group_row(group, c), 0, text
    if head == "tyre_force":
        r = group_row("tyre", c)
        return DIFF, Q["static"] + r, Q["f_total"] + r, text
    if head in ("road", "road_vel"):
        return VALUE, Q["u" if head == "road" else "ud"] + c, 0, text
    if head in RECORDS and d.structure.get("controlled"):
        return RECORD, RECORDS.index(head), c, text
    return None


def _seat(name: str, d: Description, Q: dict, offset: int) -> tuple[int, int, int, str] | None:
    """The recipe of a seat or passenger signal (:meth:`suspopt.seat.SeatModel.signals`),
    ``offset`` the seat's first DOF, or None."""
    dofs = d.info["dof_names"]
    head, _, signal = name.partition(".")
    base = {"base": 0, "base_vel": 1, "base_acc": 2}
    if head == "seat" and signal in base:
        return VALUE, Q["base"] + base[signal], 0, f"floor under the seat: body {signal}"
    if head == "seat" and signal in ("travel", "travel_vel"):
        what = "q" if signal == "travel" else "v"
        return DIFF, Q[what] + offset, Q["base"] + (signal == "travel_vel"), "seat travel x - z_s"
    if head == "seat" and signal == "travel_margin":
        return MARGIN, Q["mech"], 0, "seat mechanism's travel margin to its geometric limit"
    if head == "seat" and signal.startswith("inner_"):
        j = dofs.index("seat.inner")
        return VALUE, Q[_derivative(signal[5:])] + j, 0, f"NSS4 inner mass {signal[6:]}"
    part = "seat" if head == "seat" else head
    if part in dofs and signal in ("x", "vel", "acc"):
        j = dofs.index(part)
        what = {"x": "q", "vel": "v", "acc": "a"}[signal]
        return VALUE, Q[what] + j, 0, f"{part} {_WHAT[signal if signal != 'x' else '']}"
    return None


def add_outputs(d: Description, prepared, network) -> None:
    """The outputs of ``d`` (module docstring): ``d.info["outputs"]`` as (FMI name, signal
    name, unit, description) and ``d.structure["out_kind"|"out_i"|"out_j"]``; the seat's mount
    and mechanism entries."""
    model, controller, attachments = prepared.model, prepared.controller, prepared.attachments
    units = dict(getattr(controller, "units", {}))
    table = signal_table(model, units, attachments)
    n, nu, R = network.n, len(model.corners), d.structure["R"]
    Q = quantity_layout(n, nu, R)
    groups = {g: (s, m) for g, s, m in d.structure["groups"]}

    def group_row(group: str, c: int) -> int:
        return groups[group][0] + c

    offset = model.n_dof
    _mount(d, model, attachments, groups)
    kinds, outs, info = [], [], []
    for name, signal in table.items():
        recipe = _vehicle(name, d, Q, group_row)
        if recipe is None and attachments:
            recipe = _seat(name, d, Q, offset)
        if recipe is None:
            raise ConfigError(f"signal {name}: the FMU exporter has no output for it")
        kind, i, j, text = recipe
        kinds.append(kind)
        outs.append((i, j))
        info.append((fmi_name(name), name, signal.unit, text))
    d.structure.update(
        out_kind=np.array(kinds, int),
        out_i=np.array([i for i, _ in outs], int),
        out_j=np.array([j for _, j in outs], int),
        nq=Q["size"],
    )
    d.info["outputs"] = info


def _mount(d: Description, model, attachments, groups) -> None:
    """The seat's point on the body (its row of the vehicle's DOFs) and its mechanism's rest
    position and limit (for ``seat.travel_margin``)."""
    point = np.zeros(model.n_dof)
    rest, limit, row = 0.0, 0.0, -1
    if attachments:
        seat = attachments[0]
        point = model.point_map(*seat.point)
        mech = getattr(seat, "mechanism", None)
        if mech is not None:
            row = groups["mechanism"][0]
            rest = 0.0 if mech.rest is None else float(np.asarray(mech.rest).ravel()[0])
            limit = np.nan if mech.limit is None else float(np.asarray(mech.limit).ravel()[0])
    d.structure["mech_row"] = row
    d.structure["seated"] = int(bool(attachments))
    d.put("seat_point", point)
    d.put("mech_rest", rest)
    d.put("mech_limit", limit)
