"""One corner-based rigid-body vehicle model; QC, HC1, HC2 and FC are presets of it.

The body has a subset of the degrees of freedom {heave, roll, pitch}; corner ``i`` sits at
``(x_i, y_i)`` (``x = +a_F`` front, ``-a_R`` rear; ``y = +b_1`` right, ``-b_2`` left) and carries
an unsprung mass on a tyre, joined to the body by a spring and a damper. The suspension travel
is ``ST_i = z_s + y_i φ - x_i θ - z_ui`` (Eq 2.3, 2.9, 2.17 and Eq 2.26 with the rear roll sign
mended, slip: docs/thesis-slips.md#eq-226) and the tyre deflection ``TD_i = z_ui - z_road,i``
(Eq 2.4, 2.10, 2.18, 2.27).
The vehicle is a :class:`suspopt.network.Network` over ``q = [body DOFs, wheel heaves]``
(measured from static equilibrium) with the road heights under the wheels as inputs, and three
element groups (:func:`vehicle_network`):

- ``suspension``: along ``ST = J q`` (``J`` the travel map), the spring
  ``F_K = k_l ST + k_nl ST^3`` (Eq 2.30-2.31; the cubic term is the group's non-linear part) and
  the damper ``F_C = c dST/dt`` (Eq 2.32; a semi-active damper's controller replaces ``c``);
- ``tyre``: along ``TD = z_u - z_road``, ``F_T = k_T TD + c_T dTD/dt`` (Eq 2.28-2.29); with
  ``tyre_lift_off`` the tyre cannot pull, so ``F_T`` never exceeds the static load;
- ``anti_roll_bar``: torsional springs between the body roll and the axle roll
  ``(z_right - z_left)/(b_1 + b_2)`` (slip: docs/thesis-slips.md#eq-211).

By virtual work these give the equations of motion of every preset (Eq 2.1-2.2, 2.5-2.8,
2.13-2.16, 2.19-2.25) as ``M q'' = -J^T (F_K + F_C) - F_T - ...``; the linear matrices ``K``,
``C`` used for statics, modes and frequency responses come from the same network.

The parameter fields of :class:`VehicleModel` are batched over P designs with shapes
``(P, 1, N)`` (the network holds them as ``(N, P, 1)`` rows); matrices identical for all
designs are stored once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .config import Config, ConfigError
from .config.loader import require_config
from .config.vehicle import DOF_FIELDS, PRESET_BODY_DOFS, PRESET_CORNERS
from .errors import require
from .files import listed
from .network import (
    Elements,
    LinearModel,
    Network,
    check_response_memory,
    frequencies,
    parameter_rows,
    shared_rows,
    widen,
)
from .params import ParamView

__all__ = [
    "VehicleModel",
    "build_vehicle",
    "vehicle_network",
    "modal_analysis",
    "ModalResult",
    "frequency_response",
]


@dataclass
class VehicleModel:
    """Assembled, batched vehicle (see module docstring). Units SI; angles in rad."""

    preset: str
    body_dofs: tuple[str, ...]
    corners: tuple[str, ...]
    P: int
    mass: np.ndarray  # (1|P, 1, n) diagonal of M [kg, kg m^2]
    stiffness: np.ndarray  # (1|P, n, n) K [N/m, N m/rad]
    damping: np.ndarray  # (1|P, n, n) C [N s/m]
    travel_map: np.ndarray  # (1|P, N, n) J: ST = J q
    input_stiffness: np.ndarray  # (1|P, n, N) B_k: the road's force per m under each wheel
    input_damping: np.ndarray  # (1|P, n, N) B_c: per m/s [N s/m]
    unsprung_mass: np.ndarray  # (P, 1, N) [kg]
    tyre_stiffness: np.ndarray  # (P, 1, N) [N/m]
    tyre_damping: np.ndarray  # (P, 1, N) [N s/m]
    spring_linear: np.ndarray  # (P, 1, N) [N/m]
    spring_cubic: np.ndarray  # (P, 1, N) [N/m^3]
    damper: np.ndarray  # (P, 1, N) passive coefficient, C_min if semi-active [N s/m]
    static_tyre_load: np.ndarray  # (P, 1, N) tyre load at rest, compression positive [N]
    gravity: float
    offsets: np.ndarray  # (N,) distance behind the front axle [m] (wheelbase delay)
    sides: tuple[str, ...]  # 'right' | 'left' per corner
    dof_names: tuple[str, ...]
    network: Network  # the equations of motion (module docstring)

    @property
    def n_dof(self) -> int:
        return self.mass.shape[-1]

    @property
    def n_body(self) -> int:
        return len(self.body_dofs)

    @property
    def wheels(self) -> slice:
        """Slice of the wheel heaves in ``q``."""
        return slice(self.n_body, self.n_body + len(self.corners))

    @property
    def linear(self) -> LinearModel:
        """The linear(ised) equations of motion, (P, ...) rows; the road under each wheel the
        inputs. Duffing and lift-off are not in it."""
        P, n, N = self.P, self.n_dof, len(self.corners)
        return LinearModel(
            self.dof_names,
            tuple(f"road.{cn}" for cn in self.corners),
            np.broadcast_to(self.mass[:, 0, :], (P, n)),
            np.broadcast_to(self.stiffness, (P, n, n)),
            np.broadcast_to(self.damping, (P, n, n)),
            np.broadcast_to(self.input_stiffness, (P, n, N)),
            np.broadcast_to(self.input_damping, (P, n, N)),
        )

    def point_map(self, x: float, y: float) -> np.ndarray:
        """Row (n,) giving the body's vertical displacement at the body point (x, y) [m]
        (x + forward, y + right) from q: z_s + y φ - x θ."""
        row = np.zeros(self.n_dof)
        for j, dof in enumerate(self.body_dofs):
            row[j] = {"heave": 1.0, "roll": y, "pitch": -x}[dof]
        return row


def _corner_geometry(pv: ParamView, body_dofs: tuple[str, ...], corners: tuple[str, ...]):
    """Each corner's position (x, y) (P, N) [m]: its lever arms where the body pitches
    (``x``) and rolls (``y``), 0 elsewhere (:class:`~suspopt.config.vehicle.Preset`)."""
    P = pv.P
    x = np.zeros((P, len(corners)))
    y = np.zeros((P, len(corners)))
    body = "vehicle.body."
    for i, name in enumerate(corners):
        if "pitch" in body_dofs:
            x[:, i] = (
                pv.require_positive(body + "a_front")
                if name[0] == "F"
                else -pv.require_positive(body + "a_rear")
            )
        if "roll" in body_dofs:
            y[:, i] = (
                pv.require_positive(body + "b_right")
                if name[1] == "1"
                else -pv.require_positive(body + "b_left")
            )
    return x, y


def _corner_parameters(pv: ParamView, veh, corners: tuple[str, ...]):
    """Per-corner parameters (P, N): unsprung mass [kg], tyre stiffness [N/m] and damping
    [N s/m], spring linear [N/m] and cubic [N/m^3] coefficients, damper coefficient [N s/m]."""

    def corner_param(key: str, positive: bool = False) -> np.ndarray:
        get = pv.require_positive if positive else pv.get
        return np.stack([get(f"vehicle.corners.{c}.{key}") for c in corners], axis=1)

    mu = corner_param("unsprung_mass", True)
    kt, ct = corner_param("tyre.stiffness", True), corner_param("tyre.damping")
    kl, knl = corner_param("spring.linear", True), corner_param("spring.cubic")
    # a semi-active damper enters the linear model (modes, frequency response) at its soft
    # state C_min; the controller (suspopt.control) sets its coefficient while integrating
    c = np.stack(
        [
            pv.get(f"vehicle.corners.{cn}.damper.{veh.corners[cn].damper.soft_field}")
            for cn in corners
        ],
        axis=1,
    )
    for name, arr in (("tyre.damping", ct), ("damper.c (c_min if semi-active)", c)):
        if np.any(arr < 0):
            raise ConfigError(f"params: vehicle.corners.*.{name}: must be >= 0")
    return mu, kt, ct, kl, knl, c


def _wheelbase_offsets(cfg: Config, pv: ParamView, corners: tuple[str, ...]) -> np.ndarray:
    """Distance of each corner behind the front axle (N,) [m], the road's wheelbase delay; zero
    without it."""
    veh = cfg.vehicle
    rear = np.array([cn[0] == "R" for cn in corners])
    wheelbase = (veh.body.a_front or 0.0) + (veh.body.a_rear or 0.0)
    offsets = np.where(rear, wheelbase, 0.0) if cfg.road.wheelbase_delay else np.zeros(len(corners))
    if (pv.varies("vehicle.body.a_front") or pv.varies("vehicle.body.a_rear")) and any(
        cn[0] == "R" for cn in corners
    ):
        raise ConfigError(
            "params: vehicle.body.a_front/a_rear cannot be design parameters "
            "of a model with a rear axle: the road's wheelbase delay is one "
            "per run"
        )
    return offsets


def _mass_and_travel_map(pv: ParamView, body_dofs: tuple[str, ...], mu, x, y):
    """The diagonal of M ``(P, n)`` [kg, kg m^2] (body DOFs, then the wheels' unsprung masses
    ``mu (P, N)``) and the travel map ``J (P, N, n)``, ``ST_i = z_s + y_i φ - x_i θ - z_ui``
    (``x, y`` the corners' positions [m])."""
    P, nb, N = pv.P, len(body_dofs), mu.shape[1]
    n = nb + N
    mass = np.empty((P, n))
    for j, dof in enumerate(body_dofs):
        mass[:, j] = pv.require_positive("vehicle.body." + DOF_FIELDS[dof][0])
    mass[:, nb:] = mu

    # travel map J: ST_i = z_s + y_i φ - x_i θ - z_ui
    J = np.zeros((P, N, n))
    for j, dof in enumerate(body_dofs):
        J[:, :, j] = {"heave": 1.0, "roll": y, "pitch": -x}[dof]
    J[:, np.arange(N), nb + np.arange(N)] = -1.0
    return mass, J


def build_vehicle(cfg: Config, pv: ParamView | None = None) -> VehicleModel:
    """Assemble the batched model of ``cfg.vehicle`` for the designs in ``pv``.

    Parameters
    ----------
    cfg : Config
        The study; its ``vehicle`` section and, for the wheelbase delay, its road.
    pv : ParamView, optional
        The designs' parameters by dotted path (SI units); default the config's one design.

    Returns
    -------
    VehicleModel
        The batched model: masses [kg, kg m^2], stiffness [N/m, N m/rad] and damping
        [N s/m] matrices, the element network and the static tyre loads [N].
    """
    pv = pv or ParamView(require_config(cfg))
    veh = require_config(cfg).vehicle
    P = pv.P
    corners = PRESET_CORNERS[veh.preset]
    body_dofs = PRESET_BODY_DOFS[veh.preset]
    nb, N = len(body_dofs), len(corners)
    x, y = _corner_geometry(pv, body_dofs, corners)

    mu, kt, ct, kl, knl, c = _corner_parameters(pv, veh, corners)

    mass, J = _mass_and_travel_map(pv, body_dofs, mu, x, y)

    bar_map, bar_k = _anti_roll_bars(pv, corners, body_dofs)
    dof_names = tuple(f"body.{d}" for d in body_dofs) + tuple(f"wheel.{cn}" for cn in corners)
    shared_J = shared_rows(J)
    network = vehicle_network(
        dof_names,
        mass,
        shared_J,
        kl,
        knl,
        c,
        kt,
        ct,
        None if bar_map is None else shared_rows(bar_map),
        bar_k,
    )
    linear = network.linear_model()
    K, C = linear.stiffness, linear.damping
    static = _static_tyre_load(mass, K, nb, N, kt, body_dofs, veh.gravity)
    if veh.tyre_lift_off:
        tyre = network.group("tyre")
        tyre.extra, tyre.extra_uses_force = tyre_lift_off(static), True
        tyre.extra_law = ("cap", (parameter_rows(static),))
    offsets = _wheelbase_offsets(cfg, pv, corners)
    sides = tuple("right" if cn[1] == "1" else "left" for cn in corners)
    e = (slice(None), None, slice(None))
    return VehicleModel(
        preset=veh.preset,
        body_dofs=body_dofs,
        corners=corners,
        P=P,
        mass=shared_rows(mass[:, None, :]),
        stiffness=shared_rows(K),
        damping=shared_rows(C),
        travel_map=shared_J,
        input_stiffness=shared_rows(linear.input_stiffness),
        input_damping=shared_rows(linear.input_damping),
        unsprung_mass=mu[e],
        tyre_stiffness=kt[e],
        tyre_damping=ct[e],
        spring_linear=kl[e],
        spring_cubic=knl[e],
        damper=c[e],
        static_tyre_load=static[e],
        gravity=veh.gravity,
        offsets=offsets,
        sides=sides,
        dof_names=dof_names,
        network=network,
    )


def vehicle_network(
    dof_names: tuple[str, ...],
    mass: np.ndarray,
    travel_map: np.ndarray,
    spring_linear: np.ndarray,
    spring_cubic: np.ndarray,
    damper: np.ndarray,
    tyre_stiffness: np.ndarray,
    tyre_damping: np.ndarray,
    bar_map: np.ndarray | None,
    bar_stiffness: np.ndarray | None,
) -> Network:
    """The vehicle's :class:`~suspopt.network.Network` (module docstring).

    ``mass (P, n)``; ``travel_map`` J (1|P, N, n); per-corner ``(P, N)`` arrays: k_l [N/m],
    k_nl [N/m^3], c [N s/m], k_T [N/m], c_T [N s/m]; ``bar_map`` (1|P, B, n) and
    ``bar_stiffness (P, B)`` [N m/rad] or None. Inputs: the road height under each wheel.
    Tyres that may lift off get :func:`tyre_lift_off` once the static loads are known.
    """
    P, N = spring_linear.shape
    n = mass.shape[1]
    nb = n - N
    squeeze = (lambda a: a[0]) if travel_map.shape[0] == 1 else (lambda a: a)
    cubic = parameter_rows(spring_cubic)

    def duffing(width: int):
        k_nl = widen(cubic, width)
        return lambda disp, rate, force, out: np.multiply(
            k_nl, disp * disp * disp, out=out
        )  # k_nl ST^3 (Eq 2.31)

    groups = [
        Elements(
            "suspension",
            squeeze(travel_map),
            np.zeros((N, N)),
            parameter_rows(spring_linear),
            parameter_rows(damper),
            extra=duffing if np.any(spring_cubic) else None,
            extra_law=("poly3", (0.0 * cubic, 0.0 * cubic, cubic))
            if np.any(spring_cubic)
            else None,
        )
    ]
    wheels = np.zeros((N, n))
    wheels[np.arange(N), nb + np.arange(N)] = 1.0
    groups.append(
        Elements(
            "tyre", wheels, -np.eye(N), parameter_rows(tyre_stiffness), parameter_rows(tyre_damping)
        )
    )
    if bar_map is not None and bar_stiffness is not None:
        groups.append(
            Elements(
                "anti_roll_bar",
                squeeze(bar_map),
                np.zeros((bar_map.shape[1], N)),
                parameter_rows(bar_stiffness),
                np.zeros((bar_map.shape[1], P, 1)),
            )
        )
    return Network(
        dof_names, tuple(f"road.{i}" for i in range(N)), parameter_rows(mass), tuple(groups)
    )


def tyre_lift_off(static_load: np.ndarray):
    """Non-linear part of a tyre that cannot pull: ``F_T`` is capped at the static load
    ``(P, N)`` [N], so the total normal load ``static - F_T`` never falls below 0."""
    rows = parameter_rows(static_load)

    def make(width: int):
        load = widen(rows, width)

        def lift_off(disp, rate, force, out):
            np.minimum(force, load, out=out)
            out -= force

        return lift_off

    return make


def _anti_roll_bars(pv: ParamView, corners, body_dofs):
    """Twist map (P, B, n) and stiffness (P, B) of the axles' bars, or (None, None).

    A bar is a torsional spring between the body roll φ and the axle roll (z_R - z_L)/w,
    w = b_1 + b_2: twist = φ - (z_R - z_L)/w (slip: docs/thesis-slips.md#eq-211).
    """
    if "roll" not in body_dofs:
        return None, None
    nb, n = len(body_dofs), len(body_dofs) + len(corners)
    track = pv.get("vehicle.body.b_right") + pv.get("vehicle.body.b_left")
    maps, stiffness = [], []
    for axle, key in (("F", "front"), ("R", "rear")):
        k = pv.get(f"vehicle.anti_roll_bars.{key}")
        if f"{axle}1" not in corners or not np.any(k):
            continue
        a = np.zeros((pv.P, n))
        a[:, body_dofs.index("roll")] = 1.0
        a[:, nb + corners.index(f"{axle}1")] = -1.0 / track
        a[:, nb + corners.index(f"{axle}2")] = 1.0 / track
        maps.append(a)
        stiffness.append(k)
    if not maps:
        return None, None
    return np.stack(maps, axis=1), np.stack(stiffness, axis=1)


def _static_tyre_load(mass, K, nb, N, kt, body_dofs, g) -> np.ndarray:
    """Tyre loads at rest [N] from the linear statics K q0 = -M g (translations only)."""
    load = np.zeros(mass.shape)
    if "heave" in body_dofs:
        load[:, body_dofs.index("heave")] = -mass[:, body_dofs.index("heave")] * g
    load[:, nb:] = -mass[:, nb:] * g
    q0 = np.linalg.solve(K, load[..., None])[..., 0]
    return -kt * q0[:, nb:]


#: A mode is named after one DOF when that DOF holds at least this share of its kinetic
#: energy (three quarters: a half car's two wheels share their hop modes 58/42); otherwise
#: after every DOF holding at least :data:`MODE_PART` of it.
MODE_DOMINANCE = 0.75
MODE_PART = 0.15


@dataclass
class ModalResult:
    """Undamped modes: ``frequency (P, n)`` [Hz] ascending, ``shape (P, n, n)`` (columns,
    normalised to unit max |entry|), ``energy (P, n, n)`` each DOF's share of each mode's
    kinetic energy (rows DOFs, columns modes; columns sum to 1), ``dominant (P, n)`` the DOF
    with the largest share, and ``label (P, n)`` what the mode is: that DOF when it holds at
    least :data:`MODE_DOMINANCE` of the energy, else the DOFs holding at least
    :data:`MODE_PART` of it joined by ``+`` (in phase with the largest) or ``-`` (against
    it), e.g. ``wheel.F1 - wheel.F2`` for a half car's wheels hopping in antiphase. Modes of
    (nearly) equal frequency, such as a full car's four wheel hops within 0.01 Hz, may come
    out as any combination of each other, and so may their labels."""

    frequency: np.ndarray
    shape: np.ndarray
    energy: np.ndarray
    dominant: np.ndarray
    label: np.ndarray
    dof_names: tuple[str, ...]


def _mode_labels(shape: np.ndarray, energy: np.ndarray, names: np.ndarray) -> np.ndarray:
    """:attr:`ModalResult.label` from the shapes and energy shares (P, n, n)."""
    P, n, _ = shape.shape
    labels = np.empty((P, n), dtype=object)
    for p in range(P):  # labels are text: a loop over designs and modes
        for k in range(n):
            share = energy[p, :, k]
            order = np.argsort(-share, kind="stable")
            lead = order[0]
            if share[lead] >= MODE_DOMINANCE:
                labels[p, k] = str(names[lead])
                continue
            parts = [str(names[lead])]
            for j in order[1:]:
                if share[j] < MODE_PART:
                    break
                same = np.sign(shape[p, j, k]) == np.sign(shape[p, lead, k])
                parts.append(("+ " if same else "- ") + str(names[j]))
            labels[p, k] = " ".join(parts)
    return labels.astype(str)


def _vehicle_model(model: object) -> VehicleModel:
    """``model`` when it is a :class:`VehicleModel`, else a TypeError that says how to build
    one (a config given where its model belongs is the usual slip)."""
    return require(model, VehicleModel, "model", "from suspopt.build_vehicle(cfg)")


def modal_analysis(model: VehicleModel) -> ModalResult:
    """Undamped natural frequencies and mode shapes of the linearised model (K φ = ω² M φ).

    Solved as the symmetric problem M^-1/2 K M^-1/2 (M diagonal), batched over designs. The
    Duffing term has zero stiffness at equilibrium and does not enter. Each mode is labelled
    by the DOFs that carry its kinetic energy (:class:`!ModalResult`): on a full car the wheel
    hop modes are collective (a pair of wheels in or against phase), so no single wheel names
    them.

    Parameters
    ----------
    model : VehicleModel
        The assembled model (:func:`build_vehicle`).

    Returns
    -------
    ModalResult
        Natural frequencies ``(P, n)`` [Hz], mode shapes ``(P, n, n)`` (largest entry 1, in
        m or rad), kinetic-energy shares ``(P, n, n)`` [-] and a label per mode.
    """
    linear = _vehicle_model(model).linear
    frequency, shape = linear.modes()
    m = linear.mass
    shape = shape / np.max(np.abs(shape), axis=1, keepdims=True)
    energy = m[:, :, None] * shape**2
    energy = energy / energy.sum(axis=1, keepdims=True)
    names = np.array(model.dof_names)
    return ModalResult(
        frequency=frequency,
        shape=shape,
        energy=energy,
        dominant=names[np.argmax(energy, axis=1)],
        label=_mode_labels(shape, energy, names),
        dof_names=model.dof_names,
    )


def frequency_response(
    model: VehicleModel,
    f: np.ndarray,
    speed: float | None = None,
    corners: tuple[str, ...] | None = None,
) -> np.ndarray:
    """Analytic response of the linear(ised) model to a road input, (P, F, n) [m per m].

    The same unit-amplitude road height ``exp(jωt)`` enters under each wheel in ``corners``
    (default all), the rear ones delayed by ``offset/speed`` when a speed is given: the
    complex DOF amplitudes solve ``(K - ω² M + jω C) Q = (B_k + jω B_c) R``, the road's
    terms ``B_k, B_c`` (the tyres' ``k_T, c_T`` on the wheels) from the network's linear
    model. Body accelerations are ``-ω² Q``. Duffing and lift-off are not in the linear
    model.

    Parameters
    ----------
    model : VehicleModel
        The assembled model (:func:`build_vehicle`).
    f : array_like
        Frequencies ``(F,)`` [Hz].
    speed : float, optional
        Forward speed [m/s] for the wheelbase delay of the rear wheels; none without it (or
        at 0).
    corners : tuple of str, optional
        The corners whose wheels see the road (default all, e.g. ``("F1", "R1")``; one name
        is one corner, ``"F1"``; an empty tuple is an error, not all of them).

    Returns
    -------
    ndarray
        Complex DOF amplitudes ``(P, F, n)`` per metre of road height [m/m, rad/m].
    """
    model = _vehicle_model(model)
    f = frequencies(f)
    speed = None if speed is None else float(speed)
    if speed is not None and not (math.isfinite(speed) and speed >= 0):
        raise ValueError(f"speed must be finite and >= 0 [m/s]; got {speed}")
    corners = None if corners is None else tuple(listed(corners))  # ("F1" is one corner)
    if corners == () or not all(isinstance(c, str) and c in model.corners for c in corners or ()):
        raise ValueError(
            f"corners must be a tuple of this model's corners {model.corners}; got {corners!r}"
        )
    check_response_memory(model.P, f.size, model.n_dof, len(model.corners))
    omega = 2 * np.pi * f
    use = np.array([c in (corners or model.corners) for c in model.corners], dtype=float)
    delay = model.offsets / speed if speed else np.zeros(len(model.corners))
    road = use[None, :] * np.exp(-1j * omega[:, None] * delay[None, :])  # (F, N)
    return model.linear.frequency_response(f, road)
