"""Design quantities of a seat without simulation (Sec 8.2-8.4): ``X_ST``, the geometric and
static constraints of Tables 8.7-8.11 and the passenger mass change of Sec 8.4.3."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ..config import Config, ConfigError
from ..config.loader import require_config
from ..params import ParamView
from .model import PASSENGER_PARTS, build_seat, linearise

#: Unit of each constraint value of :func:`seat_constraints`.
CONSTRAINT_UNITS = {
    "stability": "N/m",
    "gamma2_above_one": "-",
    "gamma2_within_gamma1": "-",
    "stiffness_ratio_limit": "-",
    "static_deflection_exists": "-",
    "roller_radius_positive": "m",
    "cam_offset_positive": "m",
    "cam_offset_within_radius": "m",
    "precompression_positive": "m",
    "roller_within_cam": "m",
    "cam_offset_ratio": "m",
    "c_I_upper": "-",
    "c_I_lower": "-",
    "hinge_within_bar": "m",
}


def seat_static_deflection(cfg: Config, params: Mapping[str, Any] | None = None) -> np.ndarray:
    """``X_ST`` of every design (P,) [m] (the thesis's objective f_2, Eq 8.2)."""
    return build_seat(cfg, ParamView(cfg, params)).static_deflection


def seat_constraints(
    cfg: Config, params: Mapping[str, Any] | None = None, mu: float = 0.8
) -> dict[str, np.ndarray]:
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
        out.update(
            gamma2_above_one=1.0 - g2,
            gamma2_within_gamma1=g2 - g1,
            stiffness_ratio_limit=get("stiffness_ratio") - g1 / (2.0 * (1.0 + g1 - g2)),
            static_deflection_exists=g2 - 1.0 - g1,
        )
    elif seat.kind == "nss3":
        R, r, d = get("cam_radius"), get("roller_radius"), get("cam_offset")
        out.update(
            roller_radius_positive=-r,
            cam_offset_positive=-d,
            cam_offset_within_radius=d - R,
            precompression_positive=-get("precompression"),
            roller_within_cam=r - R,
            cam_offset_ratio=d - mu * R,
        )
    elif seat.kind == "nss4":
        c_i = seat.isolator["c_I"]
        out.update(
            c_I_upper=c_i - 0.1,
            c_I_lower=-0.1 - c_i,
            hinge_within_bar=np.abs(get("hinge_offset")) - get("bar_length"),
        )
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
    seat = require_config(cfg).seat
    load_mass = np.atleast_1d(np.asarray(load_mass, dtype=float))
    if seat is None:
        raise ConfigError("seat: the config has no seat section")
    bad = np.flatnonzero(~(np.isfinite(load_mass) & (load_mass > 0)))
    if load_mass.ndim != 1 or bad.size:  # (0, -5 and NaN gave masses the run then refused)
        raise ValueError(
            f"load_mass must be (P,) finite loads > 0 [kg]; got {load_mass.ravel()[bad[:3]]}"
            if bad.size
            else f"load_mass must be (P,) finite loads > 0 [kg]; got shape {load_mass.shape}"
        )
    old = float(build_seat(cfg).isolator["load_mass"][0])
    if seat.passenger is None:
        params = {"seat.mass": load_mass}
    else:
        scale = (load_mass - seat.mass) / (old - seat.mass)
        params = {
            f"seat.passenger.{part}.mass": getattr(seat.passenger, part).mass * scale
            for part in PASSENGER_PARTS
        }
    if seat.kind in ("nss1", "nss2", "nss3"):
        params["seat.stiffness_ratio"] = seat.stiffness_ratio * old / load_mass
    return params
