"""Semi-active dampers: control laws (Sec 2.1.6), digital controller, CDF threshold (Ch. 4).

Signs follow the project's travel ``ST = z_s - z_u`` (extension positive, Eq 2.3), so the
travel rate is ``ṠT = ż_s - ż_u`` and the damper force ``F_C = c ṠT`` (Eq 2.32) pushes the
body down and the wheel up while the damper extends. At each corner ``i``, ``ż_s`` and
``z̈_s`` are the body's vertical velocity and acceleration *at the corner*,
``heave + y_i roll - x_i pitch`` (so on HC1, HC2 and FC the roll and pitch enter every law,
Sec 3.2.2), ``ż_u`` is the corner's wheel velocity, and ``ṠT`` comes from the travel map.

Every law compares an *operational condition* ``X`` with a threshold ``T`` (0 for the thesis's
base laws, Eq 2.33; the CDF strategy's ``T_A``/``T_B`` otherwise, Eq 4.2-4.4). When the law
calls for its stiff state the damper takes ``C_max`` (on-off laws) or a coefficient clipped to
``[C_min, C_max]`` (continuous laws); otherwise ``C_min``. At ``X = T`` exactly the damper is
soft, as Eq 2.33, 2.36 and 2.39 write.

==========  =======================================  ==================  =========================
law         condition X                              stiff when          stiff coefficient
==========  =======================================  ==================  =========================
sh_2        ṠT ż_s  (Eq 2.34, 4.3)                   X > T               C_max
sh_l        ṠT ż_s  (Eq 2.35)                        X > T               clip(α C_max +
                                                                         (1 - α) C_max ż_s / ṠT)
add         ṠT z̈_s  (Eq 2.36)                        X > T               C_max
sh_add_1    ṠT ż_s if S <= 0, else ṠT z̈_s / α_c      X > T               C_max
            (Eq 2.37)
sh_add_2    S = z̈_s² - α_c² ż_s²  (Eq 2.39, 4.4)     X < T               C_max
groundhook  -ṠT ż_u                                  X > T               C_max
hybrid      ṠT (β σ_sky + (1 - β) σ_gnd)             X > T               clip(C_max X / ṠT²)
==========  =======================================  ==================  =========================

``S = z̈_s² - α_c² ż_s²`` is the frequency-range selector with the crossover ``α_c`` in rad/s
(``crossover_frequency``; ERRATA: the thesis prints ``ż_s²`` for ``z̈_s²`` in places).

- **SH-L** (Eq 2.35) with ``α`` = ``linear_weight``: the printed coefficient is unbounded as
  ``ṠT -> 0``; a damper cannot exceed its range, so it is clipped to ``[C_min, C_max]`` (as in
  Savaresi et al.'s linear approximation of the skyhook). With ``α = 1`` it is ``C_max``: SH-2.
- **SH-ADD-1** (Eq 2.37): the SH-2 rule in the low-frequency range (``S <= 0``), the ADD rule
  above it. Deviation: Eq 2.38 prints ``ṠT ż_s < 0`` as the soft condition of the high range;
  Eq 2.37 (and the law's source, Savaresi and Spelta) uses ADD's ``ṠT z̈_s``, followed here.
  The high-range product is divided by ``α_c`` so that both ranges' conditions are in m²/s²
  and one threshold applies to both; at ``T = 0`` this is exactly Eq 2.37 (the sign is kept).
- **Groundhook** (the road-holding law named in Sec 4.4; Valášek et al., Koo et al.): the ideal
  damper between the wheel and the ground pushes the wheel with ``-c_g ż_u``; the real damper
  pushes it with ``+c ṠT``, which can match only when ``-ż_u ṠT > 0``: then ``C_max``.
- **Hybrid skyhook-groundhook** (Ahmadian and Koo): ``σ_sky = ż_s`` where ``ṠT ż_s > 0``,
  else 0; ``σ_gnd = -ż_u`` where ``-ṠT ż_u > 0``, else 0; the requested force
  ``C_max (β σ_sky + (1 - β) σ_gnd)`` (``β`` = ``skyhook_weight``, gain ``C_max``) is realised
  by the coefficient ``C_max X / ṠT²`` clipped to ``[C_min, C_max]``. ``β = 1`` is the
  continuous skyhook (SH-L with ``α = 0``), ``β = 0`` the continuous groundhook.

Where ``ṠT = 0`` the damper force is zero whatever the coefficient; the continuous laws then
take the ratio ``ż_s / ṠT`` (or ``X / ṠT²``) as 0.

**Digital controller** (Sec 4.2): the laws are evaluated every ``ΔT`` (``control.sample_time``,
a whole multiple of the integration step) and the command is held in between (zero-order hold).
With an actuator lag ``τ`` the coefficient follows the command per integration step as the
exact first-order response, ``c <- c_cmd - (c_cmd - c) exp(-dt/τ)`` (i.e.
``c += (c_cmd - c)(1 - exp(-dt/τ))``), the value at the end of the step being used over the
step, so ``τ -> 0`` is the instantaneous damper; the simulator applies it to the damper
coefficients every step (:attr:`SemiActiveController.lag_decay`). The laws that need ``z̈_s`` (add, sh_add_1,
sh_add_2) evaluate the equations of motion at sample instants only, with the coefficient in
force just before the sample.

**CDF threshold** (Ch. 4): see :class:`suspopt.config.control.Threshold` and
:func:`threshold_for_share`. An adaptive threshold keeps every sample of the condition
(``duration / ΔT`` x P x N floats) and refits from all of them (Fig. 4.4). The Student-t fit
costs a few tens of passes over that history per refit; for large populations the normal and
empirical fits are far cheaper.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.special import digamma, ndtri, stdtrit

from .config import Config, ConfigError
from .config.control import Control
from .params import ParamView
from .vehicle import VehicleModel, matvec

__all__ = [
    "LAWS", "Law", "law_condition", "stiff_coefficient", "fit_student_t", "distribution_quantile",
    "threshold_for_share", "SemiActiveController", "build_controller",
]


@dataclass(frozen=True)
class Law:
    """What the controller needs to know about a law (see the module docstring)."""

    unit: str                  # unit of the condition X
    stiff_below: bool          # stiff when X < T (SH-ADD-2), else when X > T
    continuous: bool           # stiff coefficient varies inside [C_min, C_max]
    needs_acceleration: bool   # uses the body acceleration z̈_s at the corner


LAWS: dict[str, Law] = {
    "sh_2": Law("m^2/s^2", False, False, False),          # Eq 2.34
    "sh_l": Law("m^2/s^2", False, True, False),           # Eq 2.35
    "add": Law("m^2/s^3", False, False, True),            # Eq 2.36
    "sh_add_1": Law("m^2/s^2", False, False, True),       # Eq 2.37
    "sh_add_2": Law("m^2/s^4", True, False, True),        # Eq 2.39
    "groundhook": Law("m^2/s^2", False, False, False),    # Sec 4.4
    "hybrid": Law("m^2/s^2", False, True, False),         # Sec 4.4
}


def _ratio(numerator: np.ndarray, denominator: np.ndarray) -> np.ndarray:
    """``numerator / denominator``, 0 where the denominator is 0."""
    return np.divide(numerator, denominator, out=np.zeros(np.broadcast_shapes(
        numerator.shape, denominator.shape)), where=denominator != 0)


def _frequency_selector(body_vel, body_acc, crossover):
    """``S = z̈_s² - α_c² ż_s²`` (Eq 2.37-2.39 with ERRATA) [m²/s⁴]."""
    return body_acc * body_acc - crossover * crossover * (body_vel * body_vel)


def _hybrid_velocity(travel_vel, body_vel, wheel_vel, skyhook_weight):
    """``β σ_sky + (1 - β) σ_gnd`` [m/s] of the hybrid law."""
    sky = np.where(travel_vel * body_vel > 0, body_vel, 0.0)
    ground = np.where(travel_vel * wheel_vel < 0, -wheel_vel, 0.0)
    return skyhook_weight * sky + (1.0 - skyhook_weight) * ground


def law_condition(law: str, travel_vel: np.ndarray, body_vel: np.ndarray,
                  wheel_vel: np.ndarray, body_acc: np.ndarray | None = None,
                  crossover: np.ndarray | float = 1.0,
                  skyhook_weight: np.ndarray | float = 1.0) -> np.ndarray:
    """Operational condition ``X`` of ``law`` (table of the module docstring).

    ``travel_vel`` ṠT, ``body_vel`` ż_s (body at the corner), ``wheel_vel`` ż_u [m/s],
    ``body_acc`` z̈_s [m/s²] (laws add, sh_add_1, sh_add_2), ``crossover`` α_c [rad/s],
    ``skyhook_weight`` β [-]; any broadcastable shapes. Unit: ``LAWS[law].unit``.
    """
    if law in ("sh_2", "sh_l"):
        return travel_vel * body_vel
    if law == "add":
        return travel_vel * body_acc
    if law == "sh_add_1":
        low = _frequency_selector(body_vel, body_acc, crossover) <= 0
        return np.where(low, travel_vel * body_vel, travel_vel * body_acc / crossover)
    if law == "sh_add_2":
        return _frequency_selector(body_vel, body_acc, crossover)
    if law == "groundhook":
        return -(travel_vel * wheel_vel)
    if law == "hybrid":
        return travel_vel * _hybrid_velocity(travel_vel, body_vel, wheel_vel, skyhook_weight)
    raise ValueError(f"unknown control law {law!r}; known: {', '.join(LAWS)}")


def stiff_coefficient(law: str, c_min, c_max, travel_vel, body_vel, condition,
                      linear_weight=1.0) -> np.ndarray:
    """Coefficient [N s/m] of ``law`` in its stiff state: ``C_max`` for the on-off laws, the
    clipped SH-L (Eq 2.35) or hybrid coefficient for the continuous ones."""
    if law == "sh_l":
        c = linear_weight * c_max + (1.0 - linear_weight) * c_max * _ratio(body_vel, travel_vel)
    elif law == "hybrid":
        c = c_max * _ratio(condition, travel_vel * travel_vel)
    else:
        return c_max
    return np.clip(c, c_min, c_max)


# --- CDF threshold: fitting the history of the condition (Eq 4.5-4.7) -----------------------

#: Student-t EM: iteration cap, and the relative change of μ, s and ν at which it stops.
_T_MAX_ITERATIONS = 200
_T_TOLERANCE = 1e-4
#: Bisection steps of the ν update (log ν to 5e-7) and the range of ν.
_NU_BISECTIONS = 24
_NU_RANGE = (0.3, 1.0e3)


def _solve_df(constant: np.ndarray) -> np.ndarray:
    """ν solving ``log(ν/2) - ψ(ν/2) + constant = 0`` (EM's ν step), by bisection on log ν.

    The left side falls from +inf to ``constant`` (< 0) as ν grows, so the root is unique; it is
    clipped to ``_NU_RANGE``."""
    lo = np.full(constant.shape, np.log(0.5 * _NU_RANGE[0]))     # bisection on log(ν/2)
    hi = np.full(constant.shape, np.log(0.5 * _NU_RANGE[1]))
    for _ in range(_NU_BISECTIONS):
        mid = 0.5 * (lo + hi)
        above = mid - digamma(np.exp(mid)) + constant > 0
        lo = np.where(above, mid, lo)
        hi = np.where(above, hi, mid)
    return 2.0 * np.exp(0.5 * (lo + hi))


def fit_student_t(samples: np.ndarray, axis: int = 0,
                  start: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Maximum-likelihood location ``μ``, scale ``s`` and degrees of freedom ``ν`` of a
    location-scale Student-t fitted along ``axis``, vectorised over the other axes.

    The thesis fits the conditions with a t distribution (Sec 4.2.3) without saying how. Here:
    the ECM algorithm of Liu and Rubin (1995) in its parameter-expanded form (the scale update
    divides by the sum of the weights, Liu, Rubin and Wu 1998; same maximum, faster). Each
    iteration weights the samples ``w = (ν + 1)/(ν + d²)`` (``d`` the standardised residual),
    moves ``μ`` to the weighted mean, sets ``s² = Σ w (x - μ)² / Σ w`` and ``ν`` to the root of
    its EM equation (``_NU_BISECTIONS`` bisection steps on ``log ν`` in ``_NU_RANGE``). The
    loop stops when every column's ``μ`` (in units of ``s``), ``s`` and ``ν`` change by less
    than ``_T_TOLERANCE`` relative, or after ``_T_MAX_ITERATIONS``; it costs about nine passes
    over the samples per iteration. ``start = (μ, s, ν)`` (NaN where unknown) warm-starts it,
    else it starts from the median, 1.4826 MAD and ν = 5. EM approaches a large ν (near-normal
    data) slowly; there the quantiles hardly depend on ν. Samples that are all equal give
    ``s = 0``; columns with non-finite samples give NaN.
    """
    x = np.moveaxis(np.asarray(samples, dtype=float), axis, 0)
    m = x.shape[0]
    flat = ~(np.max(x, axis=0) > np.min(x, axis=0))
    loc = np.full(x.shape[1:], np.nan) if start is None else np.array(start[0], dtype=float)
    scale = np.full(x.shape[1:], np.nan) if start is None else np.array(start[1], dtype=float)
    df = np.full(x.shape[1:], 5.0) if start is None else np.array(start[2], dtype=float)
    cold = ~(np.isfinite(loc) & (scale > 0) & np.isfinite(df))
    if cold.any():
        median = np.median(x, axis=0)
        mad = 1.4826 * np.median(np.abs(x - median), axis=0)
        loc = np.where(cold, median, loc)
        scale = np.where(cold, np.where(mad > 0, mad, np.std(x, axis=0)), scale)
        df = np.where(cold, 5.0, df)
    scale = np.where(flat | ~(scale > 0), 1.0, scale)
    r, w = np.empty_like(x), np.empty_like(x)
    for _ in range(_T_MAX_ITERATIONS):
        np.subtract(x, loc, out=r)
        np.multiply(r, r, out=w)
        w *= 1.0 / (scale * scale)
        w += df
        np.divide(df + 1.0, w, out=w)                     # E-step weights
        sum_w = np.sum(w, axis=0)
        sum_wr = np.einsum("i...,i...->...", w, r)
        sum_wd2 = m * (df + 1.0) - df * sum_w              # Σ w d², as w (ν + d²) = ν + 1
        np.log(w, out=r)
        half = 0.5 * (df + 1.0)
        new_df = _solve_df(1.0 + np.mean(r, axis=0) - sum_w / m + digamma(half)
                           - np.log(half))
        step = sum_wr / sum_w
        spread = np.maximum(scale * scale * sum_wd2 - sum_wr * step, 0.0) / sum_w
        new_scale = np.where(spread > 0, np.sqrt(spread), scale)
        done = ((np.abs(step) <= _T_TOLERANCE * new_scale)
                & (np.abs(new_scale - scale) <= _T_TOLERANCE * scale)
                & (np.abs(new_df - df) <= _T_TOLERANCE * df)) | ~np.isfinite(step)
        loc, scale, df = loc + step, new_scale, new_df
        if done.all():
            break
    return loc, np.where(flat, 0.0, scale), df


def _t_quantile(fit: tuple[np.ndarray, np.ndarray, np.ndarray], level) -> np.ndarray:
    """Quantile of a fitted location-scale t, ``μ + s t_ν⁻¹(level)``."""
    loc, scale, df = fit
    return loc + scale * stdtrit(df, level)


def _empirical_quantile(x: np.ndarray, level: np.ndarray) -> np.ndarray:
    """Sample quantile along axis 0 at a per-column ``level`` (numpy's 'linear' method)."""
    s = np.sort(x, axis=0)
    position = level * (x.shape[0] - 1)
    lo = np.floor(position).astype(int)
    hi = np.minimum(lo + 1, x.shape[0] - 1)
    a = np.take_along_axis(s, lo[None], axis=0)[0]
    b = np.take_along_axis(s, hi[None], axis=0)[0]
    return a + (b - a) * (position - lo)


def distribution_quantile(samples: np.ndarray, level: np.ndarray | float,
                          distribution: str, axis: int = 0) -> np.ndarray:
    """Quantile at ``level`` (0-1, broadcast over the non-fitted axes) of the distribution
    fitted to ``samples`` along ``axis``: ``student_t`` (:func:`fit_student_t`, then
    ``μ + s t_ν⁻¹(level)``), ``normal`` (``μ + σ Φ⁻¹(level)`` with the sample mean and standard
    deviation: ERRATA Eq 4.7, ``T = μ + Z σ``) or ``empirical`` (the sample quantile).
    Vectorised: no loop over the other axes."""
    x = np.moveaxis(np.asarray(samples, dtype=float), axis, 0)
    level = np.broadcast_to(np.asarray(level, dtype=float), x.shape[1:])
    if distribution == "empirical":
        return _empirical_quantile(x, level)
    if distribution == "normal":
        return np.mean(x, axis=0) + np.std(x, axis=0) * ndtri(level)
    if distribution == "student_t":
        return _t_quantile(fit_student_t(x, axis=0), level)
    raise ValueError(f"unknown distribution {distribution!r}; use student_t, normal or "
                     "empirical")


def threshold_for_share(condition: np.ndarray, c_max_share: np.ndarray | float, law: str,
                        distribution: str = "student_t", axis: int = -1) -> np.ndarray:
    """Threshold ``T`` that leaves the share ``c_max_share`` of the samples at ``C_max``
    (Eq 4.5-4.7 with ERRATA Eq 4.7: the quantile of the distribution fitted to ``condition``).

    ``c_max_share`` is the thesis's ``1 - N%`` (0-1). The quantile level is ``1 - c_max_share``
    for laws that stiffen above ``T`` (Eq 4.6: ``P(X < T_A) = N%``) and ``c_max_share`` for
    SH-ADD-2, which stiffens below it (Eq 4.4). This is both the thesis's offline design
    (Sec 4.2.3, from a run of the base law) and the adaptive controller's refit.
    """
    share = np.asarray(c_max_share, dtype=float)
    level = share if LAWS[law].stiff_below else 1.0 - share
    return distribution_quantile(condition, level, distribution, axis=axis)


# --- the controller --------------------------------------------------------------------------

def _per_design(pv: ParamView, path: str, low: float, high: float | None = None,
                low_open: bool = False) -> np.ndarray:
    """``pv.get(path)``, checking every design's value lies in the field's range."""
    value = pv.get(path)
    bad = (value <= low) if low_open else (value < low)
    if high is not None:
        bad |= value > high
    if bad.any():
        rng = f"{'(' if low_open else '['}{low:g}, {'inf)' if high is None else f'{high:g}]'}"
        raise ConfigError(f"params: {path}: must be in {rng} (designs "
                          f"{np.flatnonzero(bad)[:5].tolist()})")
    return value


class SemiActiveController:
    """Digital controller of the semi-active dampers (see the module docstring); implements the
    simulator's ``Controller`` protocol. Built by :func:`build_controller`.

    Arrays are (P, 1, N) over designs and corners; passive corners hold ``C_min = C_max = c``
    and their records are NaN. Records (signals ``<name>.<corner>``): ``damper_state`` (the
    command's place in the range, ``(c - C_min)/(C_max - C_min)``: 0 soft, 1 stiff, fractional
    for the continuous laws), ``control_condition`` (X of the latest sample) and
    ``control_threshold`` (T in force). Like ``damping``, a record at an output instant holds
    what was in force over the integration step ending there, i.e. the latest sample before it.
    """

    def __init__(self, model: VehicleModel, laws: list[str | None], c_min: np.ndarray,
                 c_max: np.ndarray, linear_weight: np.ndarray, crossover: np.ndarray,
                 skyhook_weight: np.ndarray, dt: float, sample_every: int, n_steps: int,
                 actuator_lag: np.ndarray, threshold: np.ndarray,
                 c_max_share: np.ndarray | None = None, learn_time: np.ndarray | None = None,
                 refit_factor: np.ndarray | None = None, distribution: str = "student_t"):
        N = len(model.corners)
        self._passive = np.array([law is None for law in laws])
        present = sorted({law for law in laws if law is not None}, key=list(LAWS).index)
        self._groups = [(law, None if len(present) == 1 and not self._passive.any()
                         else np.array([x == law for x in laws])) for law in present]
        self._needs_acc = any(LAWS[law].needs_acceleration for law in present)
        below = np.array([law is not None and LAWS[law].stiff_below for law in laws])
        self._below = below if below.any() and not below.all() else bool(below.all())
        self._c_min, self._c_max = c_min, c_max
        self._switchable = c_max > c_min
        self._range = np.where(self._switchable, c_max - c_min, 1.0)
        self._linear_weight, self._crossover = linear_weight, crossover
        self._skyhook_weight = skyhook_weight
        self._nb = model.n_body
        # one product gives the travel rates, the body's velocities at the corners and the
        # wheels' velocities: rows [J; J_body; wheels] of the vehicle velocities
        J = model.travel_map
        body = np.zeros_like(J)
        body[:, :, :model.n_body] = J[:, :, :model.n_body]
        wheels = np.zeros((1,) + J.shape[1:])
        wheels[0, np.arange(N), model.wheels.start + np.arange(N)] = 1.0
        self._rates_t = np.ascontiguousarray(np.swapaxes(np.concatenate(
            [J, body, np.broadcast_to(wheels, J.shape)], axis=1), 1, 2))
        self._body_t = np.ascontiguousarray(np.swapaxes(J[:, :, :model.n_body], 1, 2))
        self.samples = 0               # samples taken: the records change only with them
        self._every = sample_every
        self._decay = np.exp(-dt / np.where(actuator_lag > 0, actuator_lag, 1.0)) \
            * (actuator_lag > 0)
        self._lagged = bool(np.any(actuator_lag > 0))
        self._threshold = threshold
        self._adaptive = c_max_share is not None
        if self._adaptive:
            share = c_max_share[:, None, None]
            self._level = np.where(below[None, None, :], share, 1.0 - share)[:, 0, :]
            self._period = refit_factor * learn_time
            self._next_fit = learn_time.astype(float).copy()
            self._history = np.empty((n_steps // sample_every + 1,) + threshold.shape[::2])
            self._n_history = 0
            self._distribution = distribution
            self._t_fit = tuple(np.full(threshold.shape[::2], np.nan) for _ in range(3))
            self._half_step = 0.5 * dt
        units = {LAWS[law].unit for law in present}
        unit = units.pop() if len(units) == 1 else "; ".join(
            f"{c}: {LAWS[law].unit}" for c, law in zip(model.corners, laws) if law is not None)
        self.units = {"damper_state": "1", "control_condition": unit, "control_threshold": unit}
        self._N = N

    def start(self, P: int) -> np.ndarray:
        """Command at rest: the soft state (P, 1, N)."""
        self._cmd = np.broadcast_to(self._c_min, (P, 1, self._N)).copy()
        self._condition = np.zeros_like(self._cmd)
        self._stiff = np.zeros(self._cmd.shape, dtype=bool)
        self._records: dict[str, np.ndarray] | None = None
        return self._cmd

    @property
    def sample_every(self) -> int:
        """Integration steps per sample (ΔT / dt)."""
        return self._every

    @property
    def lag_decay(self) -> np.ndarray | None:
        """The actuator's factor ``exp(-dt/τ)`` per integration step (P, 1, 1), 0 without a
        lag; None when no design has one."""
        return self._decay if self._lagged else None

    def sample(self, k: int, t: float, state) -> np.ndarray:
        """The command (P, 1, N) [N s/m] from the sample at step ``k`` (``t = k dt``), held
        until the next sample (see the protocol in simulate.py)."""
        self._sample(t, state)
        return self._cmd

    def _sample(self, t: float, state) -> None:
        N = self._N
        rates = matvec(self._rates_t, state.velocity())
        travel_vel, body_vel, wheel_vel = (rates[..., :N], rates[..., N:2 * N],
                                           rates[..., 2 * N:])
        body_acc = matvec(self._body_t, state.acceleration()[..., :self._nb]) \
            if self._needs_acc else None
        condition = None
        for law, mask in self._groups:
            x = law_condition(law, travel_vel, body_vel, wheel_vel, body_acc, self._crossover,
                              self._skyhook_weight)
            condition = x if mask is None else np.where(mask, x, 0.0 if condition is None
                                                        else condition)
        if self._adaptive:
            self._refit(t, condition)
        if self._below is True:
            stiff = condition < self._threshold
        elif self._below is False:
            stiff = condition > self._threshold
        else:
            stiff = np.where(self._below, condition < self._threshold,
                             condition > self._threshold)
        c_stiff = self._c_max
        for law, mask in self._groups:
            if LAWS[law].continuous:
                c = stiff_coefficient(law, self._c_min, self._c_max, travel_vel, body_vel,
                                      condition, self._linear_weight)
                c_stiff = c if mask is None else np.where(mask, c, c_stiff)
        self._cmd = np.where(stiff, c_stiff, self._c_min)
        self._condition, self._stiff = condition, stiff
        self._records = None
        self.samples += 1

    def _refit(self, t: float, condition: np.ndarray) -> None:
        """Store the sample; at each design's refit instants set its threshold to the
        quantile of the history (Fig. 4.4: first at t >= T_learn, then every κ T_learn)."""
        self._history[self._n_history] = condition[:, 0]
        self._n_history += 1
        due = t + self._half_step >= self._next_fit
        if not due.any():
            return
        idx = np.flatnonzero(due)
        history = self._history[:self._n_history]
        if idx.size < due.size:
            history = history[:, idx]
        if self._distribution == "student_t":       # warm-started from the last fit
            fit = fit_student_t(history, start=tuple(a[idx] for a in self._t_fit))
            for stored, new in zip(self._t_fit, fit):
                stored[idx] = new
            threshold = _t_quantile(fit, self._level[idx])
        else:
            threshold = distribution_quantile(history, self._level[idx], self._distribution)
        self._threshold = self._threshold.copy()
        self._threshold[idx, 0] = threshold
        late = t + self._half_step - self._next_fit[idx]
        self._next_fit[idx] += self._period[idx] * (np.floor(late / self._period[idx]) + 1.0)

    def record(self) -> dict[str, np.ndarray]:
        """Damper state, condition and threshold of the latest sample, (P, N) each (computed
        once per sample: they change only at sample instants)."""
        if self._records is None:
            state = np.where(self._switchable, (self._cmd - self._c_min) / self._range,
                             self._stiff)[:, 0]
            condition, threshold = self._condition[:, 0], self._threshold[:, 0]
            if self._passive.any():
                state, condition, threshold = (np.where(self._passive, np.nan, a)
                                               for a in (state, condition, threshold))
            self._records = {"damper_state": state, "control_condition": condition,
                             "control_threshold": threshold}
        return self._records


def build_controller(cfg: Config, pv: ParamView, model: VehicleModel
                     ) -> SemiActiveController | None:
    """The controller of ``cfg``'s semi-active dampers for the designs of ``pv``; None when
    every damper is passive. Law parameters, lag and threshold settings may vary per design
    (dotted paths in ``pv``); the sample time is one per run."""
    dampers = [cfg.vehicle.corners[c].damper for c in model.corners]
    if all(d.kind == "passive" for d in dampers):
        return None
    control = cfg.control or Control()
    sim = cfg.simulation
    ratio = control.sample_time / sim.dt
    if ratio < 1 - 1e-9 or abs(ratio - round(ratio)) > 1e-6:
        raise cfg.error(("control", "sample_time"), f"the controller's sample time "
                        f"{control.sample_time:g} s must be a whole multiple of simulation.dt "
                        f"({sim.dt:g} s)")
    if pv.varies("control.sample_time"):
        raise ConfigError("params: control.sample_time cannot vary between designs: the "
                          "controller samples once per run")

    def setting(path: str, default: float, low: float, high: float | None = None,
                low_open: bool = False) -> np.ndarray:
        if cfg.control is None:
            return np.full(pv.P, default)
        return _per_design(pv, path, low, high, low_open)

    def corner(name: str, damper, field: str, default: float, low: float,
               high: float | None = None, low_open: bool = False) -> np.ndarray:
        if damper.kind == "passive" or getattr(damper, field) is None:
            return np.full(pv.P, default)
        return _per_design(pv, f"vehicle.corners.{name}.damper.{field}", low, high, low_open)

    laws, c_min, c_max, alpha, crossover, beta = [], [], [], [], [], []
    for name, damper in zip(model.corners, dampers):
        if damper.kind == "passive":
            c = _per_design(pv, f"vehicle.corners.{name}.damper.c", 0.0)
            laws.append(None)
            c_min.append(c)
            c_max.append(c)
        else:
            laws.append(damper.law)
            lo = _per_design(pv, f"vehicle.corners.{name}.damper.c_min", 0.0)
            hi = _per_design(pv, f"vehicle.corners.{name}.damper.c_max", 0.0)
            if np.any(hi < lo):
                raise ConfigError(f"params: vehicle.corners.{name}.damper.c_max: must be at "
                                  f"least c_min (designs {np.flatnonzero(hi < lo)[:5].tolist()})")
            c_min.append(lo)
            c_max.append(hi)
        alpha.append(corner(name, damper, "linear_weight", 1.0, 0.0, 1.0))
        crossover.append(corner(name, damper, "crossover_frequency", 1.0, 0.0, low_open=True))
        beta.append(corner(name, damper, "skyhook_weight", 1.0, 0.0, 1.0))

    def stack(values: list[np.ndarray]) -> np.ndarray:
        return np.stack(values, axis=1)[:, None, :]

    lag = setting("control.actuator_lag", 0.0, 0.0)[:, None, None]
    threshold = np.zeros((pv.P, 1, len(model.corners)))
    settings = {}
    spec = control.threshold
    if spec is not None and spec.mode == "fixed":
        units = {LAWS[law].unit for law in laws if law is not None}
        if len(units) > 1:
            raise cfg.error(("control", "threshold", "value"), "one fixed threshold cannot serve "
                            f"conditions of different units ({', '.join(sorted(units))}); "
                            "give the corners laws of one unit or use mode adaptive")
        threshold = threshold + pv.get("control.threshold.value")[:, None, None]
    elif spec is not None:
        base = "control.threshold."
        settings = dict(
            c_max_share=_per_design(pv, base + "c_max_share", 0.0, None, True),
            learn_time=_per_design(pv, base + "learn_time", 0.0, low_open=True),
            refit_factor=_per_design(pv, base + "refit_factor", 0.0, low_open=True),
            distribution=spec.distribution)
        if np.any(settings["c_max_share"] >= 1):
            raise ConfigError(f"params: {base}c_max_share: must be in (0, 1)")
    return SemiActiveController(
        model, laws, stack(c_min), stack(c_max), stack(alpha), stack(crossover), stack(beta),
        sim.dt, int(round(ratio)), sim.n_steps, lag, threshold, **settings)
