"""The seat and its passenger as one :class:`SeatModel` (Sec 2.2-2.3): the isolator builders,
the seat's network and its signals, and the linearised seat (transmissibility, modes).
Equations and signs: :mod:`suspopt.seat`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..config import Config, ConfigError
from ..network import Elements, LinearModel, Network, parameter_rows, shared_rows, widen
from ..params import ParamView
from . import mechanisms
from .mechanisms import Mechanism

#: Body parts of the passenger, bottom to top (Fig. 2.14, Table 2.3).
PASSENGER_PARTS = ("pelvis", "abdomen", "diaphragm", "thorax", "torso", "back", "head")
#: The part (or the seat) each part's own k_i, c_i join it to (slip: docs/thesis-slips.md#eq-270).
_BELOW = {
    "pelvis": "seat",
    "abdomen": "pelvis",
    "diaphragm": "abdomen",
    "thorax": "diaphragm",
    "torso": "thorax",
    "back": "pelvis",
    "head": "back",
}
#: First part of the names of seat and passenger signals.
SIGNAL_HEADS = ("seat",) + PASSENGER_PARTS
_UNITS = {
    "x": "m",
    "vel": "m/s",
    "acc": "m/s^2",
    "base": "m",
    "base_vel": "m/s",
    "base_acc": "m/s^2",
    "travel": "m",
    "travel_vel": "m/s",
    "travel_margin": "m",
    "inner_x": "m",
    "inner_acc": "m/s^2",
}


def signal_units(name: str) -> str:
    """SI unit of a seat or passenger signal (``seat.acc``, ``head.x``, ...)."""
    return _UNITS[name.split(".", 1)[1]]


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

    def force(
        self, q: np.ndarray, v: np.ndarray, base: np.ndarray, base_vel: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
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
            table["seat.travel_margin"] = lambda q, v, a, b, bv, ba: (
                mech.limit - np.abs(mech.coordinate(q[mech.node] - b))
            )
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
    return (
        [(0, 1, k_v, get("damping"))],
        None,
        {
            "static_deflection": mechanisms.ps_static_deflection(load, k_v, g),
            "vertical_stiffness": k_v,
        },
    )


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
        geometry: tuple[np.ndarray, ...]
        limit: np.ndarray | None
        if kind == "nss1":
            a_o, gamma = get("wall_distance"), get("gamma")
            geometry, limit = (a_o, a_o / gamma), None
            x_st = mechanisms.nss1_static_deflection(a_o, gamma)
        elif kind == "nss2":
            a_o, l_o, b = get("wall_distance"), get("spring_free_length"), get("bar_length")
            geometry, limit = (a_o, l_o, b), b
            x_st = mechanisms.nss2_static_deflection(a_o, l_o, b)
        else:
            geometry = (
                get("cam_radius"),
                get("roller_radius"),
                get("cam_offset"),
                get("precompression"),
            )
            cam, roller, offset, precompression = geometry
            limit = mechanisms.nss3_contact_limit(cam, roller, offset, precompression)
            x_st = mechanisms.nss3_static_deflection(cam, roller, offset)
        k_v = mechanisms.vertical_stiffness(load, x_st, g)
        k_h = get("stiffness_ratio") * k_v
        params = tuple(p[:, None] for p in (k_h,) + geometry)
        law, series = _FORMS[kind]
        mech = Mechanism(
            node=0,
            law=_scaled(law, params),
            rest=None,
            series=series(*params) if form == "taylor" else None,
            limit=None if limit is None else limit[:, None],
        )
        return (
            [(0, 1, k_v, get("damping"))],
            mech,
            {
                "static_deflection": x_st,
                "vertical_stiffness": k_v,
                "horizontal_stiffness": k_h,
            },
        )

    return build


def _kdamper(get: Callable[[str], np.ndarray], load: np.ndarray, g: float, form: str):
    """NSS4, Eq 2.59-2.69: ``K_S`` floor-seat, ``K_v`` and ``C_v`` seat-inner mass, the
    mechanism floor-inner mass at rest at ``u_0``; ``X_ST`` from Eq 2.64."""
    k_s, k_v, k_h = (get("support_stiffness"), get("inner_stiffness"), get("horizontal_stiffness"))
    a_o, l_o, b = get("wall_distance"), get("spring_free_length"), get("bar_length")
    u_0 = get("hinge_offset")
    params = tuple(p[:, None] for p in (k_h, a_o, l_o, b))
    preload = mechanisms.nss4_force(u_0, k_h, a_o, l_o, b)
    mech = Mechanism(
        node=1,
        law=_scaled(mechanisms.nss4_law, params),
        rest=u_0[:, None],
        series=mechanisms.nss4_taylor(u_0[:, None], *params) if form == "taylor" else None,
        limit=b[:, None],
    )
    return (
        [(0, 1, k_s, 0.0), (1, 2, k_v, get("damping"))],
        mech,
        {
            "static_deflection": mechanisms.nss4_static_deflection(
                load, get("inner_mass"), k_s, preload, g
            ),
            "vertical_stiffness": k_v,
            "horizontal_stiffness": k_h,
            "support_stiffness": k_s,
            "mechanism_preload": preload,
            "c_I": (l_o - a_o) / b,
        },
    )


#: Exact force law (the parameters of the ``*_force`` function after the travel, giving the
#: function of the travel) and Taylor coefficients of NSS1-NSS3.
#: Each NSS kind's exact law and its Taylor series: (parameters...) -> law, -> (k1, k2, k3).
_FORMS: dict[str, tuple[Callable[..., Any], Callable[..., Any]]] = {
    "nss1": (mechanisms.carrella_law, mechanisms.nss1_taylor),
    "nss2": (mechanisms.nss2_law, mechanisms.nss2_taylor),
    "nss3": (mechanisms.nss3_law, mechanisms.nss3_taylor),
}
#: Isolator builders: (get, load [kg], g, form) -> (links, mechanism, quantities). Links are
#: (node_a, node_b, stiffness, damping) over the nodes 0 floor, 1 seat, 2 inner mass.
_ISOLATORS = {
    "ps": _passive,
    "nss1": _negative_stiffness("nss1"),
    "nss2": _negative_stiffness("nss2"),
    "nss3": _negative_stiffness("nss3"),
    "nss4": _kdamper,
}


def build_seat(cfg: Config, pv: ParamView | None = None) -> SeatModel:
    """Assemble the batched :class:`SeatModel` of ``cfg.seat`` for the designs in ``pv``."""
    pv = pv or ParamView(cfg)
    seat = cfg.seat
    if seat is None:
        raise ConfigError("seat: the config has no seat section")
    if pv.varies("seat.position"):
        raise ConfigError(
            "params: seat.position cannot be a design parameter: the seat's "
            "point on the body is one per run"
        )

    def get(key: str) -> np.ndarray:
        return pv.get(f"seat.{key}")

    inner = seat.kind == "nss4"
    parts = PASSENGER_PARTS if seat.passenger is not None else ()
    names = ("seat",) + (("seat.inner",) if inner else ()) + parts
    node = {name: i for i, name in enumerate(("floor",) + names)}  # 0 floor, 1 seat, ...
    masses = [pv.require_positive("seat.mass")] + (
        [pv.require_positive("seat.inner_mass")] if inner else []
    )
    load = masses[0]  # the isolator carries the seat and the passenger
    links = []
    for part in parts:
        m = pv.require_positive(f"seat.passenger.{part}.mass")
        masses.append(m)
        load = load + m
        links.append(
            (
                node[part],
                node[_BELOW[part]],
                get(f"passenger.{part}.stiffness"),
                get(f"passenger.{part}.damping"),
            )
        )
    if parts:
        links.append(
            (
                node["torso"],
                node["back"],
                get("passenger.torso_back.stiffness"),
                get("passenger.torso_back.damping"),
            )
        )
    form = getattr(seat, "form", "exact")
    with np.errstate(divide="ignore", invalid="ignore"):  # undefined geometry -> NaN
        iso_links, mechanism, isolator = _ISOLATORS[seat.kind](get, load, cfg.vehicle.gravity, form)
        mass = np.stack(masses, axis=1)[:, None, :]
        network = seat_network(names, mass[:, 0, :], iso_links + links, mechanism)
    return SeatModel(
        kind=seat.kind,
        dof_names=names,
        mass=shared_rows(mass),
        point=(seat.position.x, seat.position.y),
        coupled=seat.coupling == "two_way",
        network=network,
        mechanism=mechanism,
        isolator={**isolator, "load_mass": load},
    )


def seat_network(
    dof_names: tuple[str, ...], mass: np.ndarray, links: list, mechanism: Mechanism | None
) -> Network:
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
        groups.append(
            Elements(
                "mechanism",
                carried,
                -np.ones((1, 1)),
                zero,
                zero,
                extra=mechanism.element_force,
                extra_law=mechanism.compiled_law(),
                extra_slope=-mechanism.slope()[None, :, None],
            )
        )
    return Network(dof_names, ("floor",), parameter_rows(mass), tuple(groups))


def build_attachments(cfg: Config, pv: ParamView) -> list[SeatModel]:
    """The body attachments of ``cfg``: its seat (and passenger), or none."""
    return [] if cfg.seat is None else [build_seat(cfg, pv)]


# --------------------------------------------------------------------------------------------
# Linearised model, transmissibility, modes


def linearise(seat: SeatModel) -> LinearModel:
    """The seat linearised about static equilibrium (:meth:`Network.linear_model` of its
    network): the links as they are, the mechanism with its slope at rest
    (:meth:`Mechanism.slope`), the floor motion ``z_s`` the one input:
    ``M q'' + C q' + K q = b_k z_s + b_c z_s'`` (``input_stiffness (P, m, 1)``)."""
    return seat.network.linear_model()


def base_transmissibility(lin: LinearModel, f: np.ndarray) -> np.ndarray:
    """Acceleration transmissibility ``z̈_i / z̈_s`` of every DOF from the floor, Eq 2.86,
    complex, (P, F, m).

    The DOF amplitudes under a unit floor displacement
    (:meth:`~suspopt.network.LinearModel.frequency_response`); the acceleration ratio equals
    the displacement ratio. Seat-to-head transmissibility (STHT, Eq 2.86 with i = head,
    Fig. 8.26: ``z̈_head / z̈_s``) is the ``head`` column.
    """
    return lin.frequency_response(f)


def natural_frequencies(lin: LinearModel) -> np.ndarray:
    """Undamped natural frequencies with the floor held still, (P, m) [Hz], ascending."""
    return lin.modes()[0]
