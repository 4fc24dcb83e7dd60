"""Fitting the history of a law's condition for the CDF threshold (Ch. 4, Eq 4.5-4.7).

:func:`threshold_for_share` gives the threshold ``T`` that leaves a share of the samples at
``C_max``: the quantile of a distribution fitted to the condition (Eq 4.7 as mended, slip:
docs/thesis-slips.md#eq-47), :func:`distribution_quantile`, by a location-scale Student-t fit
(the thesis's), a normal fit or the empirical quantile. :func:`fit_student_t` is a vectorised
Newton maximum-likelihood fit of many columns at once; :class:`~suspopt.control.summary.StudentTSummary` refits a
growing history from a fixed-size summary, so that an adaptive controller's refit costs the
same however long the run (its quantiles agree with the exact full-history fit's to about
1e-4 of the scale).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .laws import LAWS

__all__ = [
    "fit_student_t",
    "distribution_quantile",
    "threshold_for_share",
    "t_quantile",
]

#: Student-t fit: cap on the log-likelihood evaluations, and the size of the last Newton step
#: (μ in units of s, log s and log ν) at which it stops: the error left is about its square.
_T_MAX_EVALUATIONS = 50
_T_TOLERANCE = 1e-3
#: The range of ν.
NU_RANGE = (0.3, 1.0e3)


def robust_location_scale(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Middle order statistic of ``x`` along axis 0 and 1.4826 times the median absolute
    deviation from it (the standard deviation where that is 0): the t fits' start and the
    summary's coordinate, so neither needs more. Columns are partitioned in place in one
    transposed copy, along its contiguous axis (np.median along axis 0 is several times
    slower)."""
    shape, flat = x.shape[1:], x.reshape(x.shape[0], -1)
    columns = np.array(flat.T, order="C")  # a copy, partitioned in place
    k = (x.shape[0] - 1) // 2
    columns.partition(k, axis=1)
    middle = columns[:, k].copy()
    columns -= middle[:, None]  # the same values, in another order
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
    from scipy.special import digamma, gammaln  # (loaded by the fits that use them)

    def wsum(a: np.ndarray) -> np.ndarray:
        return np.sum(a, axis=0) if weights is None else np.einsum("ij,ij->j", weights, a)

    r = x - loc
    s2 = scale * scale
    den = r * r
    den += df * s2  # s² (ν + d²)
    w = np.divide((df + 1.0) * s2, den)
    wr = w * r  # w d s
    s_w, s_wd = wsum(w), wsum(wr) / scale
    wr *= w
    s_wwd = wsum(wr) / scale
    w *= w
    s_ww = wsum(w)
    log_terms = wsum(np.log(den, out=den)) - total * np.log(df * s2)
    nu, nu1 = df, df + 1.0
    s_wd2 = total * nu1 - nu * s_w  # Σ w d²
    s_w2d2 = nu1 * s_w - nu * s_ww  # Σ w² d²
    s_w2d3 = nu1 * s_wd - nu * s_wwd  # Σ w² d³
    s_w2d4 = total * nu1 * nu1 - 2.0 * nu * nu1 * s_w + nu * nu * s_ww
    half, half1 = 0.5 * nu, 0.5 * nu1
    loglik = (
        total * (gammaln(half1) - gammaln(half) - 0.5 * np.log(nu) - np.log(scale))
        - half1 * log_terms
    )
    d_nu = (
        total * 0.5 * (digamma(half1) - digamma(half) - 1.0 / nu)
        - 0.5 * log_terms
        + 0.5 * s_wd2 / nu
    )
    trigamma = 0.25 * _trigamma_step(half)  # ∂²/∂ν² of log Γ terms
    d2_nu = (
        total * (trigamma + 0.5 / (nu * nu))
        + 0.5 * (2.0 * s_wd2 - s_w2d2) / (nu * nu1)
        - 0.5 * s_wd2 / (nu * nu)
    )
    grad = (s_wd, s_wd2 - total, nu * d_nu)
    hess = (
        2.0 * s_w2d2 / nu1 - s_w,  # μ μ
        2.0 * s_w2d3 / nu1 - 2.0 * s_wd,  # log s, μ
        nu * (s_wd - s_wwd) / nu1,  # log ν, μ
        2.0 * s_w2d4 / nu1 - 2.0 * s_wd2,  # log s, log s
        nu * (s_wd2 - s_w2d2) / nu1,  # log ν, log s
        nu * nu * d2_nu + nu * d_nu,
    )  # log ν, log ν
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
    x = np.add.outer((0.5, 0.0), a)  # rows: a + 1/2, a
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
    is positive definite. Divisions by zero are the caller's to silence (:func:`fit_t`)."""
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


def _ascent_step(
    grad: np.ndarray, hess: tuple, trigamma, total, df
) -> tuple[np.ndarray, np.ndarray]:
    """Step in ``(μ/s, log s, log ν)``: Newton's where the Hessian is negative definite, else
    Fisher scoring's (the t's expected information, positive definite), so always uphill;
    shortened to at most 1 in every coordinate. ``ν`` at a bound of ``NU_RANGE`` with the
    gradient pointing out is held. Returns the step and where it is Newton's."""
    out = ((df >= NU_RANGE[1]) & (grad[2] > 0)) | ((df <= NU_RANGE[0]) & (grad[2] < 0))
    free = ~out
    held = (grad[0], grad[1], np.where(out, 0.0, grad[2]))  # (ν's held where it is at a bound)
    h11, h21, h31, h22, h32, h33 = hess
    newton, concave = _solve_symmetric(
        (-h11, -h21, -h31 * free, -h22, -h32 * free, np.where(out, 1.0, -h33)), held
    )
    if concave.all():
        step = newton
    else:
        nu, nu1, nu3 = df, df + 1.0, df + 3.0
        info_nu = -trigamma - (nu + 5.0) / (2.0 * nu * nu1 * nu3)  # per sample, in ν
        zero = np.zeros_like(nu)
        fisher, _ = _solve_symmetric(
            (
                total * nu1 / nu3,
                zero,
                zero,
                total * 2.0 * nu / nu3,
                -total * free * 2.0 * nu / (nu1 * nu3),
                np.where(out, 1.0, total * nu * nu * info_nu),
            ),
            held,
        )
        step = np.where(concave, newton, fisher)
    step /= np.maximum(1.0, _largest(step))
    return step, concave


def _largest(step: np.ndarray) -> np.ndarray:
    """Largest magnitude of the three coordinates of ``step`` per column."""
    return np.maximum(np.maximum(np.abs(step[0]), np.abs(step[1])), np.abs(step[2]))


def _moved(loc, scale, df, step):
    """Parameters after ``step`` (see :func:`_ascent_step`)."""
    return (
        loc + step[0] * scale,
        scale * np.exp(step[1]),
        np.clip(df * np.exp(step[2]), *NU_RANGE),
    )


def fit_t(
    x: np.ndarray,
    weights: np.ndarray | None,
    loc,
    scale,
    df,
    active,
    tolerance: float = _T_TOLERANCE,
):
    """Maximum-likelihood ``(μ, s, ν)`` of a location-scale t over ``x`` (samples along axis 0,
    with multiplicities ``weights`` or None), from ``(loc, scale, df)``, for the columns
    ``active`` (the others are returned as given). Newton's method with a backtracking line
    search (see :func:`fit_student_t`), stopping at a Newton step below ``tolerance``; columns
    stop one by one, and only the unfinished ones are evaluated."""
    loc, scale, df = (np.array(a, dtype=float) for a in (loc, scale, df))
    x = x.reshape(x.shape[0], -1)
    weights = None if weights is None else weights.reshape(x.shape)
    work = np.flatnonzero(active)  # the columns still iterating
    if work.size == 0:
        return loc, scale, df
    if work.size < x.shape[1]:
        x, weights = x[:, work], None if weights is None else weights[:, work]
    total = np.full(x.shape[1], float(x.shape[0])) if weights is None else np.sum(weights, axis=0)
    params = tuple(a.reshape(-1)[work] for a in (loc, scale, df))
    loglik: Any = None  # at params
    step: Any = None  # the step from there

    def finish(which: np.ndarray, values: tuple) -> None:
        for whole, value in zip((loc, scale, df), values):
            whole.reshape(-1)[work[which]] = value[which]

    with np.errstate(divide="ignore", invalid="ignore"):
        for _ in range(_T_MAX_EVALUATIONS):
            trial = params if step is None else _moved(params[0], params[1], params[2], step)
            new_loglik, grad, hess, trigamma = _t_derivatives(x, weights, total, *trial)
            better = None  # the trial point is accepted if not lower
            if step is not None:
                better = new_loglik >= loglik - 1e-12 * np.abs(loglik)
                if better.all():
                    better = None
                else:
                    trial = tuple(np.where(better, t, p) for t, p in zip(trial, params))
                    new_loglik = np.where(better, new_loglik, loglik)
            params, loglik = trial, new_loglik
            new_step, newton = _ascent_step(grad, hess, trigamma, total, params[2])
            if better is not None:  # rejected: a quarter of the last step
                new_step = np.where(better, new_step, 0.25 * step)
                newton &= better
            step = new_step
            converged = newton & (_largest(step) < tolerance)
            going = ~converged & np.isfinite(loglik)
            if going.all():
                continue
            if converged.any():
                finish(converged, _moved(params[0], params[1], params[2], step))
            finish(~going & ~converged, params)
            if not going.any():
                return loc, scale, df
            x, total, work = x[:, going], total[going], work[going]
            weights = None if weights is None else weights[:, going]
            params, loglik, step = tuple(p[going] for p in params), loglik[going], step[:, going]
    finish(np.ones(work.size, dtype=bool), params)
    return loc, scale, df


def fit_student_t(
    samples: np.ndarray,
    axis: int = 0,
    start: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
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
    ``NU_RANGE``. Near the maximum it converges quadratically, also for near-normal data,
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
        middle, spread = robust_location_scale(x)
        loc = np.where(cold, middle, loc)
        scale = np.where(cold, spread, scale)
        df = np.where(cold, 5.0, df)
    df = np.clip(df, *NU_RANGE)
    loc, scale, df = fit_t(x, None, loc, np.where(flat, 1.0, scale), df, ~flat)
    return (
        np.where(finite, loc, np.nan),
        np.where(finite, np.where(flat, 0.0, scale), np.nan),
        np.where(finite, df, np.nan),
    )


def t_quantile(fit: tuple[np.ndarray, np.ndarray, np.ndarray], level) -> np.ndarray:
    """Quantile of a fitted location-scale t, ``μ + s t_ν⁻¹(level)``."""
    loc, scale, df = fit
    from scipy.special import stdtrit

    return loc + scale * stdtrit(df, level)


def _empirical_quantile(x: np.ndarray, level: np.ndarray) -> np.ndarray:
    """Sample quantile along axis 0 at a per-column ``level`` (numpy's 'linear' method).

    Where every column has the same level (one share for every design, a refit's usual case)
    the two order statistics are found by selection: ``np.partition`` at the lower one, the
    next one the smallest value above it (``fmin``: NaN, sorted last, only when all above are
    NaN). About half a sort's time for a refit of 1000 columns of 1250 samples; the values
    are a sort's."""
    n = x.shape[0]
    position = level * (n - 1)
    lo = np.floor(position).astype(int)
    if lo.size and n > 1 and np.all(lo == lo.flat[0]):
        k = int(lo.flat[0])
        part = np.partition(x, k, axis=0)
        a = part[k]
        b = np.fmin.reduce(part[k + 1 :], axis=0) if k + 1 < n else a
    else:
        s = np.sort(x, axis=0)
        a = np.take_along_axis(s, lo[None], axis=0)[0]
        b = np.take_along_axis(s, np.minimum(lo + 1, n - 1)[None], axis=0)[0]
    return a + (b - a) * (position - lo)


def distribution_quantile(
    samples: np.ndarray, level: np.ndarray | float, distribution: str, axis: int = 0
) -> np.ndarray:
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
        return t_quantile(fit_student_t(x, axis=0), level)
    raise ValueError(f"unknown distribution {distribution!r}; use student_t, normal or empirical")


def threshold_for_share(
    condition: np.ndarray,
    c_max_share: np.ndarray | float,
    law: str,
    distribution: str = "student_t",
    axis: int = -1,
) -> np.ndarray:
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
