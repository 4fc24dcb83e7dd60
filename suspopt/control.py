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
(``crossover_frequency``; the thesis prints ``ż_s²`` for ``z̈_s²`` in places, slip:
docs/thesis-slips.md#eq-237).

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
coefficients every step (:attr:`SemiActiveController.lag_decay`). The laws that need ``z̈_s``
(add, sh_add_1, sh_add_2) evaluate the equations of motion at sample instants only, with the
coefficient in force just before the sample.

**CDF threshold** (Ch. 4): see :class:`suspopt.config.control.Threshold` and
:func:`threshold_for_share`. An adaptive threshold keeps every sample of the condition
(``duration / ΔT`` x P x N floats) and refits from all of them (Fig. 4.4): the normal and
empirical fits from the samples themselves, the Student-t fit from a fixed-size summary that
takes in each sample once (:class:`StudentTSummary`; its quantiles agree with the exact
full-history fit's to about 1e-4 of the scale), so a refit costs the same however long the
history.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .config import Config, ConfigError
from .config.control import Control
from .params import ParamView
from .vehicle import VehicleModel

__all__ = [
    "LAWS", "Law", "law_condition", "stiff_coefficient", "fit_student_t", "distribution_quantile",
    "threshold_for_share", "StudentTSummary", "SemiActiveController", "build_controller",
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
    """``S = z̈_s² - α_c² ż_s²`` (Eq 2.37-2.39; slip: docs/thesis-slips.md#eq-237) [m²/s⁴]."""
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

#: Student-t fit: cap on the log-likelihood evaluations, and the size of the last Newton step
#: (μ in units of s, log s and log ν) at which it stops: the error left is about its square.
_T_MAX_EVALUATIONS = 50
_T_TOLERANCE = 1e-3
#: The range of ν.
_NU_RANGE = (0.3, 1.0e3)


def _robust_location_scale(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Middle order statistic of ``x`` along axis 0 and 1.4826 times the median absolute
    deviation from it (the standard deviation where that is 0): the t fits' start and the
    summary's coordinate, so neither needs more. Columns are partitioned in place in one
    transposed copy, along its contiguous axis (np.median along axis 0 is several times
    slower)."""
    shape, flat = x.shape[1:], x.reshape(x.shape[0], -1)
    columns = np.array(flat.T, order="C")            # a copy, partitioned in place
    k = (x.shape[0] - 1) // 2
    columns.partition(k, axis=1)
    middle = columns[:, k].copy()
    columns -= middle[:, None]                       # the same values, in another order
    np.abs(columns, out=columns)
    columns.partition(k, axis=1)
    scale = 1.4826 * columns[:, k]
    if not np.all(scale > 0):
        scale = np.where(scale > 0, scale, np.std(flat, axis=0))
    return middle.reshape(shape), scale.reshape(shape)


def _t_derivatives(x: np.ndarray, weights: np.ndarray | None, total, loc, scale, df):
    """Log-likelihood (without its constant), gradient and Hessian of a location-scale t with
    ``(μ, s, ν) = (loc, scale, df)`` over the samples ``x`` (axis 0; ``weights`` their
    multiplicities, None for 1; ``total`` their sum), per column. Coordinates
    ``(μ/s, log s, log ν)``, ``s`` held at its current value in the first; gradient as its
    three entries, Hessian as its six ``(h11, h21, h31, h22, h32, h33)``, and
    ``(ψ'((ν+1)/2) - ψ'(ν/2))/4`` for :func:`_ascent_step`.

    With ``d = (x - μ)/s`` and the E-step weight ``w = (ν + 1)/(ν + d²)`` everything follows
    from five sums, ``Σw, Σw², Σwd, Σw²d`` and ``L = Σ log(1 + d²/ν)``, because
    ``w d² = ν + 1 - ν w``."""
    from scipy.special import digamma, gammaln     # (loaded by the fits that use them)

    def wsum(a: np.ndarray) -> np.ndarray:
        return np.sum(a, axis=0) if weights is None else np.einsum("ij,ij->j", weights, a)

    r = x - loc
    s2 = scale * scale
    den = r * r
    den += df * s2                                   # s² (ν + d²)
    w = np.divide((df + 1.0) * s2, den)
    wr = w * r                                       # w d s
    s_w, s_wd = wsum(w), wsum(wr) / scale
    wr *= w
    s_wwd = wsum(wr) / scale
    w *= w
    s_ww = wsum(w)
    log_terms = wsum(np.log(den, out=den)) - total * np.log(df * s2)
    nu, nu1 = df, df + 1.0
    s_wd2 = total * nu1 - nu * s_w                   # Σ w d²
    s_w2d2 = nu1 * s_w - nu * s_ww                   # Σ w² d²
    s_w2d3 = nu1 * s_wd - nu * s_wwd                 # Σ w² d³
    s_w2d4 = total * nu1 * nu1 - 2.0 * nu * nu1 * s_w + nu * nu * s_ww
    half, half1 = 0.5 * nu, 0.5 * nu1
    loglik = total * (gammaln(half1) - gammaln(half) - 0.5 * np.log(nu) - np.log(scale)) \
        - half1 * log_terms
    d_nu = total * 0.5 * (digamma(half1) - digamma(half) - 1.0 / nu) - 0.5 * log_terms \
        + 0.5 * s_wd2 / nu
    trigamma = 0.25 * _trigamma_step(half)                            # ∂²/∂ν² of log Γ terms
    d2_nu = total * (trigamma + 0.5 / (nu * nu)) \
        + 0.5 * (2.0 * s_wd2 - s_w2d2) / (nu * nu1) - 0.5 * s_wd2 / (nu * nu)
    grad = (s_wd, s_wd2 - total, nu * d_nu)
    hess = (2.0 * s_w2d2 / nu1 - s_w,                # μ μ
            2.0 * s_w2d3 / nu1 - 2.0 * s_wd,         # log s, μ
            nu * (s_wd - s_wwd) / nu1,               # log ν, μ
            2.0 * s_w2d4 / nu1 - 2.0 * s_wd2,        # log s, log s
            nu * (s_wd2 - s_w2d2) / nu1,             # log ν, log s
            nu * nu * d2_nu + nu * d_nu)             # log ν, log ν
    return loglik, grad, hess, trigamma


#: Bernoulli numbers' terms B_2k of the trigamma's asymptotic series, k = 1..5.
_TRIGAMMA_SERIES = (1.0 / 6.0, -1.0 / 30.0, 1.0 / 42.0, -1.0 / 30.0, 5.0 / 66.0)


def _trigamma_step(a: np.ndarray) -> np.ndarray:
    """``ψ'(a + 1/2) - ψ'(a)`` for ``a > 0``, ``ψ'`` the trigamma function: both by the
    recurrence ``ψ'(x) = ψ'(x + 1) + 1/x²`` to ``x + 6`` and the asymptotic series
    ``ψ'(x) ~ 1/x + 1/(2x²) + Σ B_2k / x^(2k+1)`` there (Abramowitz & Stegun 6.4.6, 6.4.12),
    relative error below 1e-11 for ``a >= 0.15`` (ν >= 0.3; tests/test_control.py). Several
    times faster than scipy's Hurwitz zeta for the t fit's hundreds to thousands of columns;
    it enters only the Hessian, so it changes no fit's maximum."""
    x = np.add.outer((0.5, 0.0), a)                  # rows: a + 1/2, a
    total = np.zeros_like(x)
    for _ in range(6):
        total += 1.0 / (x * x)
        x += 1.0
    inverse = 1.0 / x
    inverse2 = inverse * inverse
    series = _TRIGAMMA_SERIES[-1]
    for b in _TRIGAMMA_SERIES[-2::-1]:
        series = series * inverse2 + b
    total += inverse + inverse2 * (0.5 + inverse * series)
    return total[0] - total[1]


def _solve_symmetric(a: tuple, b: tuple) -> tuple[np.ndarray, np.ndarray]:
    """``p`` (3, columns) solving ``A p = b`` for the symmetric 3x3 ``A`` given as ``(a11, a21,
    a31, a22, a32, a33)`` per column (LDLᵀ) and ``b`` as its three entries, and whether ``A``
    is positive definite. Divisions by zero are the caller's to silence (:func:`_fit_t`)."""
    a11, a21, a31, a22, a32, a33 = a
    l21, l31 = a21 / a11, a31 / a11
    d2 = a22 - l21 * a21
    l32 = (a32 - l31 * a21) / d2
    d3 = a33 - l31 * a31 - l32 * l32 * d2
    y2 = b[1] - l21 * b[0]
    p = np.empty((3,) + np.shape(d3))
    p[2] = (b[2] - l31 * b[0] - l32 * y2) / d3
    p[1] = y2 / d2 - l32 * p[2]
    p[0] = b[0] / a11 - l21 * p[1] - l31 * p[2]
    return p, (a11 > 0) & (d2 > 0) & (d3 > 0)


def _ascent_step(grad: np.ndarray, hess: tuple, trigamma, total, df
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Step in ``(μ/s, log s, log ν)``: Newton's where the Hessian is negative definite, else
    Fisher scoring's (the t's expected information, positive definite), so always uphill;
    shortened to at most 1 in every coordinate. ``ν`` at a bound of ``_NU_RANGE`` with the
    gradient pointing out is held. Returns the step and where it is Newton's."""
    out = ((df >= _NU_RANGE[1]) & (grad[2] > 0)) | ((df <= _NU_RANGE[0]) & (grad[2] < 0))
    free = ~out
    grad = (grad[0], grad[1], np.where(out, 0.0, grad[2]))
    h11, h21, h31, h22, h32, h33 = hess
    newton, concave = _solve_symmetric((-h11, -h21, -h31 * free, -h22, -h32 * free,
                                        np.where(out, 1.0, -h33)), grad)
    if concave.all():
        step = newton
    else:
        nu, nu1, nu3 = df, df + 1.0, df + 3.0
        info_nu = -trigamma - (nu + 5.0) / (2.0 * nu * nu1 * nu3)     # per sample, in ν
        zero = np.zeros_like(nu)
        fisher, _ = _solve_symmetric(
            (total * nu1 / nu3, zero, zero, total * 2.0 * nu / nu3,
             -total * free * 2.0 * nu / (nu1 * nu3),
             np.where(out, 1.0, total * nu * nu * info_nu)), grad)
        step = np.where(concave, newton, fisher)
    step /= np.maximum(1.0, _largest(step))
    return step, concave


def _largest(step: np.ndarray) -> np.ndarray:
    """Largest magnitude of the three coordinates of ``step`` per column."""
    return np.maximum(np.maximum(np.abs(step[0]), np.abs(step[1])), np.abs(step[2]))


def _moved(loc, scale, df, step):
    """Parameters after ``step`` (see :func:`_ascent_step`)."""
    return (loc + step[0] * scale, scale * np.exp(step[1]),
            np.clip(df * np.exp(step[2]), *_NU_RANGE))


def _fit_t(x: np.ndarray, weights: np.ndarray | None, loc, scale, df, active,
           tolerance: float = _T_TOLERANCE):
    """Maximum-likelihood ``(μ, s, ν)`` of a location-scale t over ``x`` (samples along axis 0,
    with multiplicities ``weights`` or None), from ``(loc, scale, df)``, for the columns
    ``active`` (the others are returned as given). Newton's method with a backtracking line
    search (see :func:`fit_student_t`), stopping at a Newton step below ``tolerance``; columns
    stop one by one, and only the unfinished ones are evaluated."""
    loc, scale, df = (np.array(a, dtype=float) for a in (loc, scale, df))
    x = x.reshape(x.shape[0], -1)
    weights = None if weights is None else weights.reshape(x.shape)
    work = np.flatnonzero(active)                # the columns still iterating
    if work.size == 0:
        return loc, scale, df
    if work.size < x.shape[1]:
        x, weights = x[:, work], None if weights is None else weights[:, work]
    total = np.full(x.shape[1], float(x.shape[0])) if weights is None else \
        np.sum(weights, axis=0)
    params = tuple(a.reshape(-1)[work] for a in (loc, scale, df))
    loglik = step = None                         # at params, and the step from there

    def finish(which: np.ndarray, values: tuple) -> None:
        for whole, value in zip((loc, scale, df), values):
            whole.reshape(-1)[work[which]] = value[which]

    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(_T_MAX_EVALUATIONS):
            trial = params if step is None else _moved(*params, step)
            new_loglik, grad, hess, trigamma = _t_derivatives(x, weights, total, *trial)
            better = None                        # the trial point is accepted if not lower
            if step is not None:
                better = new_loglik >= loglik - 1e-12 * np.abs(loglik)
                if better.all():
                    better = None
                else:
                    trial = tuple(np.where(better, t, p) for t, p in zip(trial, params))
                    new_loglik = np.where(better, new_loglik, loglik)
            params, loglik = trial, new_loglik
            new_step, newton = _ascent_step(grad, hess, trigamma, total, params[2])
            if better is not None:               # rejected: a quarter of the last step
                new_step = np.where(better, new_step, 0.25 * step)
                newton &= better
            step = new_step
            converged = newton & (_largest(step) < tolerance)
            going = ~converged & np.isfinite(loglik)
            if going.all():
                continue
            if converged.any():
                finish(converged, _moved(*params, step))
            finish(~going & ~converged, params)
            if not going.any():
                return loc, scale, df
            x, total, work = x[:, going], total[going], work[going]
            weights = None if weights is None else weights[:, going]
            params, loglik, step = tuple(p[going] for p in params), loglik[going], step[:, going]
    finish(np.ones(work.size, dtype=bool), params)
    return loc, scale, df


def fit_student_t(samples: np.ndarray, axis: int = 0,
                  start: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Maximum-likelihood location ``μ``, scale ``s`` and degrees of freedom ``ν`` of a
    location-scale Student-t fitted along ``axis``, vectorised over the other axes.

    The thesis fits the conditions with a t distribution (Sec 4.2.3) without saying how. Here:
    Newton's method on the log-likelihood in ``(μ, log s, log ν)`` with its exact gradient and
    Hessian (five sums over the samples per evaluation, :func:`_t_derivatives`); where the
    Hessian is not negative definite the step is Fisher scoring's, and a step that lowers the
    likelihood is cut to a quarter, so every accepted step climbs. It stops when a Newton step
    is below ``_T_TOLERANCE`` in ``μ/s``, ``log s`` and ``log ν`` (the step is taken: the error
    left is of order its square) or after ``_T_MAX_EVALUATIONS``; ``ν`` stays in
    ``_NU_RANGE``. Near the maximum it converges quadratically, also for near-normal data,
    where EM is slow. ``start = (μ, s, ν)`` (NaN where unknown) warm-starts it, else it starts
    from the median (the middle order statistic), 1.4826 MAD and ν = 5. Samples that are all
    equal give ``s = 0``; columns with non-finite samples give NaN. Where an atom holds a large
    share of the samples (a rest at exactly 0), the likelihood also has a maximum collapsing
    onto it (``s -> 0``, ν at its lower bound), which a fit may reach or not depending on its
    start. The adaptive controller fits a bounded summary of the history with the same method
    (:class:`StudentTSummary`).
    """
    x = np.moveaxis(np.asarray(samples, dtype=float), axis, 0)
    high, low = np.max(x, axis=0), np.min(x, axis=0)
    finite = np.isfinite(high) & np.isfinite(low)
    flat = ~(high > low) | ~finite
    loc = np.full(x.shape[1:], np.nan) if start is None else np.array(start[0], dtype=float)
    scale = np.full(x.shape[1:], np.nan) if start is None else np.array(start[1], dtype=float)
    df = np.full(x.shape[1:], 5.0) if start is None else np.array(start[2], dtype=float)
    cold = ~(np.isfinite(loc) & (scale > 0) & np.isfinite(df))
    if cold.any():
        middle, spread = _robust_location_scale(x)
        loc = np.where(cold, middle, loc)
        scale = np.where(cold, spread, scale)
        df = np.where(cold, 5.0, df)
    df = np.clip(df, *_NU_RANGE)
    loc, scale, df = _fit_t(x, None, loc, np.where(flat, 1.0, scale), df, ~flat)
    return (np.where(finite, loc, np.nan), np.where(finite, np.where(flat, 0.0, scale), np.nan),
            np.where(finite, df, np.nan))


def _t_quantile(fit: tuple[np.ndarray, np.ndarray, np.ndarray], level) -> np.ndarray:
    """Quantile of a fitted location-scale t, ``μ + s t_ν⁻¹(level)``."""
    loc, scale, df = fit
    from scipy.special import stdtrit

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
    deviation: ``T = μ + Z σ``, slip: docs/thesis-slips.md#eq-47) or ``empirical`` (the
    sample quantile).
    Vectorised: no loop over the other axes."""
    x = np.moveaxis(np.asarray(samples, dtype=float), axis, 0)
    level = np.broadcast_to(np.asarray(level, dtype=float), x.shape[1:])
    if distribution == "empirical":
        return _empirical_quantile(x, level)
    if distribution == "normal":
        from scipy.special import ndtri

        return np.mean(x, axis=0) + np.std(x, axis=0) * ndtri(level)
    if distribution == "student_t":
        return _t_quantile(fit_student_t(x, axis=0), level)
    raise ValueError(f"unknown distribution {distribution!r}; use student_t, normal or "
                     "empirical")


def threshold_for_share(condition: np.ndarray, c_max_share: np.ndarray | float, law: str,
                        distribution: str = "student_t", axis: int = -1) -> np.ndarray:
    """Threshold ``T`` that leaves the share ``c_max_share`` of the samples at ``C_max``
    (Eq 4.5-4.7 as mended: the quantile of the distribution fitted to ``condition``; slip:
    docs/thesis-slips.md#eq-47).

    ``c_max_share`` is the thesis's ``1 - N%`` (0-1). The quantile level is ``1 - c_max_share``
    for laws that stiffen above ``T`` (Eq 4.6: ``P(X < T_A) = N%``) and ``c_max_share`` for
    SH-ADD-2, which stiffens below it (Eq 4.4). This is both the thesis's offline design
    (Sec 4.2.3, from a run of the base law) and the adaptive controller's refit.
    """
    share = np.asarray(c_max_share, dtype=float)
    level = share if LAWS[law].stiff_below else 1.0 - share
    return distribution_quantile(condition, level, distribution, axis=axis)


#: Summary of a growing history: ``_SUMMARY_BINS`` bins of equal width on ``[-U, U]``,
#: ``U = _SUMMARY_RANGE``, in ``u = asinh((x - m0)/s0)`` (values beyond fall in the end bins).
_SUMMARY_BINS = 64
_SUMMARY_RANGE = 8.0
#: The summary's fits stop at a Newton step below this (see _T_TOLERANCE): the error left,
#: about its square, is a few 1e-5 of s, below the grouping error.
_SUMMARY_TOLERANCE = 5e-3


class StudentTSummary:
    """A fixed-size summary of growing sample histories and the Student-t fit from it: the
    adaptive controller's refit (Eq 4.5-4.7 with the t of Sec 4.2.3) at a cost that does not
    grow with the history.

    It estimates what :func:`fit_student_t` does on the whole history - the same maximum-
    likelihood ``(μ, s, ν)`` - from grouped data: a deviation in method, not in what is
    estimated. Each column's samples are binned in the coordinate ``u = asinh((x - m0)/s0)``,
    linear within ``s0`` of ``m0`` and logarithmic beyond, so the bins are fine at the centre
    and span heavy tails: ``_SUMMARY_BINS`` bins of width ``Δu = 0.25`` on ``|u| <= 8``, i.e.
    ``|x - m0|`` up to ``1490 s0``; farther values fall in the end bins. Per bin it keeps the
    count and the first two moments of ``u`` about the bin's centre, and takes in each sample
    once, when a refit comes. A fit replaces each bin by two points of half its count at
    ``ū ± σ_u`` (the two-point rule that matches the bin's mean and variance) and maximises
    the weighted likelihood with :func:`fit_student_t`'s Newton method, warm-started from the
    column's last fit and stopped at a Newton step below ``_SUMMARY_TOLERANCE``: typically 2-4
    evaluations over at most ``2 x _SUMMARY_BINS`` points per column, however long the
    history.

    Error: the two-point rule errs at third order in ``Δu``; in the tails the terms of the
    likelihood are nearly linear in ``u`` (``log(1 + d²/ν) ≈ 2u + const``, ``w ≈ 0``), so the
    end bins' exact moments carry them. The fitted quantiles at 0.27 and 0.73 (the thresholds
    of a 27 % share) lie within ``5e-4 s`` of the exact full-history fit's, mostly within
    ``1e-4 s``, on SH-2 and SH-ADD-2 condition histories from class C roads and on t samples
    with ν from 1 to 30 (tests/test_control.py): far below the exact fit's own sampling error
    (``~ s/√n``) and, in the C_max share, below 0.02 points.

    The coordinate ``(m0, s0)`` is set at a column's first fit from its robust location and
    scale (:func:`_robust_location_scale`), ``s0`` half the scale. The error above holds while
    the fitted ``s`` lies in ``[s0, 16 s0]`` and ``μ`` within ``s/2`` of ``m0``. When a fit
    leaves that (the road changed) and the history has at least doubled since the coordinate
    was set, the column is rebinned from the raw history on ``(μ, s/2)`` and refitted; the
    doubling bounds the rebinning to twice the samples in all. A fit that collapsed onto an
    atom (ν at its lower bound, see :func:`fit_student_t`) restarts at the next refit from the
    summary's median and interquartile range, as the exact fit starts afresh. Columns whose
    samples are all equal give ``s = 0`` and are binned once they differ; a non-finite sample
    makes the column's fit NaN from then on.

    Columns are independent (designs x corners, flattened); :meth:`fit` takes the history as
    an array ``(n, columns)`` whose rows only ever grow.
    """

    def __init__(self, columns: int):
        self._moments = np.zeros((3, _SUMMARY_BINS, columns))    # count, Σ o, Σ o² per bin
        self._centre = np.zeros(columns)                         # m0
        self._spread = np.ones(columns)                          # s0
        self._binned = np.zeros(columns, dtype=bool)
        self._built_rows = np.zeros(columns, dtype=np.intp)      # rows when (m0, s0) were set
        self._low = np.full(columns, np.inf)                     # range of the samples
        self._high = np.full(columns, -np.inf)
        self._rows = 0                                           # history rows summarised
        self._fit = tuple(np.full(columns, np.nan) for _ in range(3))

    def fit(self, history: np.ndarray, columns: np.ndarray | slice = slice(None)
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(μ, s, ν)`` of ``columns`` (indices or a slice) from all rows of ``history``
        ``(n, columns)``; the summary first takes in the rows it has not seen (of every
        column)."""
        self._take_in(history)
        index = np.arange(self._centre.size)[columns]
        low, high = self._low[index], self._high[index]
        finite = np.isfinite(low) & np.isfinite(high)
        varied = finite & (high > low)
        new = index[varied & ~self._binned[index]]
        if new.size:
            centre, spread = _robust_location_scale(history[:, self._select(new)])
            for stored, start in zip(self._fit, (centre, spread, 5.0)):
                stored[new] = start
            self._rebin(history, new, centre, 0.5 * spread)
        fitted = index[varied]
        collapsed = fitted[self._fit[2][fitted] <= _NU_RANGE[0]]
        if collapsed.size:                       # on an atom last time: start afresh
            middle, lower, upper = self._quantiles(collapsed, (0.5, 0.25, 0.75))
            for stored, start in zip(self._fit, (middle, (upper - lower) / 1.349, 5.0)):
                stored[collapsed] = start
        self._refit(fitted)
        loc, scale, df = (a[fitted] for a in self._fit)
        stale = ((scale < self._spread[fitted]) | (scale > 16.0 * self._spread[fitted])
                 | (np.abs(loc - self._centre[fitted]) > 0.5 * scale)) \
            & (history.shape[0] >= 2 * self._built_rows[fitted]) & (df > _NU_RANGE[0])
        if stale.any():
            moved = fitted[stale]
            self._rebin(history, moved, loc[stale], 0.5 * scale[stale])
            self._refit(moved)
        loc = np.where(varied, np.nan, np.where(finite, low, np.nan))
        scale = np.where(finite, 0.0, np.nan)
        df = np.where(finite, 5.0, np.nan)
        for out, value in zip((loc, scale, df), self._fit):
            out[varied] = value[fitted]
        return loc, scale, df

    def _select(self, columns: np.ndarray) -> np.ndarray | slice:
        """``columns`` (sorted, distinct) as an index, a slice when they are all of them (no
        copies)."""
        return slice(None) if columns.size == self._centre.size else columns

    def _take_in(self, history: np.ndarray) -> None:
        """Extend the range of every column and the bins of the binned ones by the rows of
        ``history`` after ``self._rows``."""
        block = history[self._rows:]
        if block.shape[0] == 0:
            return
        self._low = np.minimum(self._low, np.min(block, axis=0))
        self._high = np.maximum(self._high, np.max(block, axis=0))
        binned = np.flatnonzero(self._binned)
        if binned.size:
            which = self._select(binned)
            finite = bool(np.isfinite(self._low[which]).all()
                          and np.isfinite(self._high[which]).all())
            if isinstance(which, slice):
                self._bin(block, self._centre, self._spread, finite, self._moments)
            else:
                moments = np.zeros((3, _SUMMARY_BINS, binned.size))
                self._bin(block[:, which], self._centre[which], self._spread[which], finite,
                          moments)
                self._moments[:, :, which] += moments
        self._rows = history.shape[0]

    def _rebin(self, history: np.ndarray, columns: np.ndarray, centre, spread) -> None:
        """Bin ``columns`` afresh from all rows of ``history`` on the coordinate
        ``(centre, spread)``."""
        which = self._select(columns)
        self._centre[which], self._spread[which] = centre, spread
        moments = np.zeros((3, _SUMMARY_BINS, columns.size))
        self._bin(history[:self._rows, which], centre, spread, True, moments)
        self._moments[:, :, which] = moments
        self._binned[which] = True
        self._built_rows[which] = self._rows

    @staticmethod
    def _bin(block: np.ndarray, centre: np.ndarray, spread: np.ndarray, finite: bool,
             moments: np.ndarray) -> None:
        """Add the count and first two moments of the offset ``o`` from the bin's centre (in
        bin widths) per bin and column of the samples ``block`` ``(n, columns)`` to
        ``moments`` (3, bins, columns), C-contiguous; ``finite`` says every sample is finite
        (else non-finite ones go to the centre: their columns' fits are NaN anyway)."""
        bins, columns = _SUMMARY_BINS, block.shape[1]
        position = np.subtract(block, centre)
        position /= spread
        if not finite:
            position[~np.isfinite(position)] = 0.0
        np.arcsinh(position, out=position)
        position += _SUMMARY_RANGE
        position *= bins / (2.0 * _SUMMARY_RANGE)            # in bin widths from -U
        key = position.astype(np.intp)                        # = floor where it matters:
        np.clip(key, 0, bins - 1, out=key)                    # below 0 is the first bin
        position -= key
        position -= 0.5                                       # offset from the bin's centre
        key *= columns
        key += np.arange(columns)
        key, offset = key.ravel(), position.ravel()
        count, first, second = (m.reshape(-1) for m in moments)
        np.add.at(count, key, 1.0)
        np.add.at(first, key, offset)
        np.multiply(offset, offset, out=offset)
        np.add.at(second, key, offset)

    def _quantiles(self, columns: np.ndarray, levels) -> list[np.ndarray]:
        """Sample quantiles of ``columns`` at ``levels`` from their bins (linear in ``u``
        within a bin): a fresh start for a fit."""
        which = self._select(columns)
        count = self._moments[0][:, which]
        below = np.cumsum(count, axis=0)
        width = 2.0 * _SUMMARY_RANGE / _SUMMARY_BINS
        out = []
        for level in levels:
            target = level * below[-1]
            k = np.argmax(below >= target, axis=0)
            inside = np.take_along_axis(count, k[None], axis=0)[0]
            before = np.take_along_axis(below, k[None], axis=0)[0] - inside
            u = (k + (target - before) / inside) * width - _SUMMARY_RANGE
            out.append(self._centre[which] + self._spread[which] * np.sinh(u))
        return out

    def _points(self, columns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The two-point representation of the bins of ``columns``: values ``(2 bins',
        columns)`` and their weights, ``bins'`` the span of bins any of them occupies."""
        count, first, second = self._moments[:, :, self._select(columns)]
        occupied = np.flatnonzero(np.any(count > 0, axis=1))
        span = slice(occupied[0], occupied[-1] + 1)
        count, first, second = count[span], first[span], second[span]
        with np.errstate(divide="ignore", invalid="ignore"):
            mean = np.where(count > 0, first / count, 0.0)
            sd = np.sqrt(np.maximum(np.where(count > 0, second / count, 0.0) - mean * mean,
                                    0.0))
        width = 2.0 * _SUMMARY_RANGE / _SUMMARY_BINS
        middle = (np.arange(_SUMMARY_BINS)[span] + 0.5) * width - _SUMMARY_RANGE
        u = np.concatenate([middle[:, None] + width * (mean - sd),
                            middle[:, None] + width * (mean + sd)])
        which = self._select(columns)
        values = self._centre[which] + self._spread[which] * np.sinh(u)
        return values, np.concatenate([count, count]) * 0.5

    def _refit(self, columns: np.ndarray) -> None:
        """Fit ``columns`` from their bins, warm-started from their last fit."""
        if columns.size == 0:
            return
        values, weights = self._points(columns)
        which = self._select(columns)
        start = tuple(a[which] for a in self._fit)
        fit = _fit_t(values, weights, *start, np.ones(columns.size, dtype=bool),
                     _SUMMARY_TOLERANCE)
        for stored, new in zip(self._fit, fit):
            stored[which] = new


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


def _rows_map(matrix: np.ndarray) -> np.ndarray:
    """A (1|P, r, n) map of the vehicle's DOFs as (r, n) when every design shares it."""
    return np.ascontiguousarray(matrix[0] if matrix.shape[0] == 1 else matrix)


def _by_rows(matrix: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``matrix @ rows`` for the vehicle's DOF rows ``(n, P)`` [m/s or m/s^2], as the per-corner
    layout (P, 1, r) of the laws (a view)."""
    out = np.dot(matrix, rows) if matrix.ndim == 2 else np.einsum("prc,cp->rp", matrix, rows)
    return out.T[:, None, :]


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
        self._fixed = not self._switchable.all()     # some corner has C_min = C_max
        self._range = np.where(self._switchable, c_max - c_min, 1.0)
        self._linear_weight, self._crossover = linear_weight, crossover
        self._skyhook_weight = skyhook_weight
        # one product gives the travel rates, the body's velocities at the corners and the
        # wheels' velocities: rows [J; J_body; wheels] of the vehicle velocities
        J = model.travel_map
        body = np.zeros_like(J)
        body[:, :, :model.n_body] = J[:, :, :model.n_body]
        wheels = np.zeros((1,) + J.shape[1:])
        wheels[0, np.arange(N), model.wheels.start + np.arange(N)] = 1.0
        self._rates = _rows_map(np.concatenate([J, body, np.broadcast_to(wheels, J.shape)],
                                               axis=1))
        self._body = _rows_map(body)
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
            self._next_due = float(np.min(self._next_fit))     # the earliest of them
            self._history = np.empty((n_steps // sample_every + 1,) + threshold.shape[::2])
            self._n_history = 0
            self._distribution = distribution
            self._t_summary = StudentTSummary(self._history[0].size) \
                if distribution == "student_t" else None
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
        rates = _by_rows(self._rates, state.velocity())
        travel_vel, body_vel, wheel_vel = (rates[..., :N], rates[..., N:2 * N],
                                           rates[..., 2 * N:])
        body_acc = _by_rows(self._body, state.acceleration()) if self._needs_acc else None
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
        self.samples += 1

    def _refit(self, t: float, condition: np.ndarray) -> None:
        """Store the sample; at each design's refit instants set its threshold to the
        quantile of the history (Fig. 4.4: first at t >= T_learn, then every κ T_learn)."""
        self._history[self._n_history] = condition[:, 0]
        self._n_history += 1
        if t + self._half_step < self._next_due:
            return
        due = t + self._half_step >= self._next_fit
        idx = np.flatnonzero(due)
        history = self._history[:self._n_history]
        if self._t_summary is not None:              # bounded: from the summary, see its class
            n, corners = history.shape[0], history.shape[-1]
            columns = slice(None) if idx.size == due.size else \
                (idx[:, None] * corners + np.arange(corners)).ravel()
            fit = self._t_summary.fit(history.reshape(n, -1), columns)
            threshold = _t_quantile(tuple(a.reshape(idx.size, corners) for a in fit),
                                    self._level[idx])
        else:
            if idx.size < due.size:
                history = history[:, idx]
            threshold = distribution_quantile(history, self._level[idx], self._distribution)
        self._threshold = self._threshold.copy()
        self._threshold[idx, 0] = threshold
        late = t + self._half_step - self._next_fit[idx]
        self._next_fit[idx] += self._period[idx] * (np.floor(late / self._period[idx]) + 1.0)
        self._next_due = float(np.min(self._next_fit))

    def record(self) -> dict[str, np.ndarray]:
        """What the latest sample decided, (P, N) each, as :meth:`published` turns it into
        the records: the command [N s/m], the condition and the threshold in force, and where
        some corner has ``C_min = C_max``, whether the law asked for the stiff state. Arrays
        the controller never writes again."""
        out = {"command": self._cmd[:, 0], "condition": self._condition[:, 0],
               "threshold": self._threshold[:, 0]}
        if self._fixed:                          # only where C_min = C_max does it tell more
            out["stiff"] = self._stiff[:, 0]
        return out

    def published(self, raw: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """The records (S, P, N) from :meth:`record`'s values of S samples stacked: damper
        state (the command's place in the range, ``(c - C_min)/(C_max - C_min)``: 0 soft,
        1 stiff, fractional for the continuous laws; where ``C_min = C_max``, whether the law
        asked for the stiff state), condition and threshold; NaN at passive corners.
        Computed once for the whole run, when a record is first read."""
        switchable, c_min, span = (a[:, 0] for a in (self._switchable, self._c_min,
                                                      self._range))
        state = raw["command"] - c_min
        state /= span
        if self._fixed:
            state = np.where(switchable, state, raw["stiff"])
        records = {"damper_state": state, "control_condition": raw["condition"],
                   "control_threshold": raw["threshold"]}
        if self._passive.any():
            records = {name: np.where(self._passive, np.nan, value)
                       for name, value in records.items()}
        return records


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
