"""ISO 2631-1 frequency weightings and the ride-comfort metrics built on them (thesis Sec 2.4.2).

Signals are accelerations in m/s² with time on the last axis: ``(T,)`` or ``(P, T)``; reductions
return a scalar or ``(P,)``. ``weighting`` is one of ``"Wk", "Wd", "Wf", "Wc", "We", "Wj"``
(case-insensitive) or ``None`` / ``"none"`` for the unweighted signal.

Method of weighting: the analogue response ``H(j2πf)`` of ISO 2631-1 Annex A (parameters in
``docs/iso-facts.md#filter-structure-annex-a``) is realised as a recursive digital filter at the
record's sample rate (:mod:`suspopt.weighting`: the analogue poles mapped exactly,
a numerator fitted so that the complex response is within 0.1 % of ``H`` from 0 Hz to a quarter
of the sample rate for fs >= 500 Hz, 0.05 % from 1 kHz; the errors at other rates are tabulated
in ``docs/iso-facts.md``). The filter starts at rest, so the output is the response of the causal
weighting to the record with the signal taken as zero before it, and it runs in one pass (or in
pieces, for the streamed reductions), with no transform of the whole record.
"""

from __future__ import annotations

import math

import numpy as np

from ..weighting import (
    MAX_SAMPLE_RATE,
    MIN_SAMPLE_RATE,
    WEIGHTINGS,
    WeightingParameters,
    canonical_name,
    check_rate,
    parameters,
    weighting_response,
)

__all__ = [
    "MIN_SAMPLE_RATE",
    "MAX_SAMPLE_RATE",
    "WEIGHTINGS",
    "WeightingParameters",
    "MTVV_RATIO_LIMIT",
    "VDV_RATIO_LIMIT",
    "COMFORT_REACTIONS",
    "weighting_response",
    "weighting_filter",
    "SUM_BLOCK",
    "power_state",
    "weighted_value",
    "running_state",
    "weight",
    "weighted_rms",
    "running_rms",
    "mtvv",
    "vdv",
    "crest_factor",
    "ratio_tests",
    "comfort_reaction",
]

_INF = math.inf

MTVV_RATIO_LIMIT = 1.5
"""ISO 2631-1 6.3.3 (thesis Eq 2.84): above MTVV/a_w = 1.5 the basic method underestimates."""

VDV_RATIO_LIMIT = 1.75
"""ISO 2631-1 6.3.3 (thesis Eq 2.85): above VDV/(a_w T^¼) = 1.75 the basic method falls short."""


COMFORT_REACTIONS: tuple[tuple[float, float, str], ...] = (
    (0.0, 0.315, "not uncomfortable"),
    (0.315, 0.63, "a little uncomfortable"),
    (0.5, 1.0, "fairly uncomfortable"),
    (0.8, 1.6, "uncomfortable"),
    (1.25, 2.5, "very uncomfortable"),
    (2.0, _INF, "extremely uncomfortable"),
)
"""ISO 2631-1 Annex C.2.3 comfort reactions: (lower, upper, wording), a_w in m/s²."""

# sorted() of a set, not np.unique: np.unique of an array holding inf imports numpy.ma (26 ms)
_ZONE_EDGES = np.array(sorted({edge for band in COMFORT_REACTIONS for edge in band[:2]}))[1:-1]
_ZONE_LABELS = np.array(
    [
        " / ".join(label for lower, upper, label in COMFORT_REACTIONS if lower <= start < upper)
        for start in np.concatenate(([0.0], _ZONE_EDGES))
    ]
)


def _check(a: np.ndarray, fs: float) -> tuple[np.ndarray, float]:
    a = np.asarray(a, dtype=float)
    if a.ndim == 0 or a.shape[-1] == 0:
        raise ValueError("acceleration must have a non-empty time axis (last axis)")
    return a, check_rate(fs)


def weighting_filter(weighting: str | None, fs: float):
    """The recursive filter (:class:`suspopt.weighting.WeightingFilter`) that realises the ISO
    2631-1 weighting ``weighting`` at the sample rate ``fs`` [Hz] (at least 100 Hz), or None
    for the unweighted signal. :func:`weight` is its output from rest; a signal that arrives
    in pieces (the streamed reductions of :mod:`suspopt.streaming`) is filtered piece by piece
    with its state, to the same bits."""
    fs = check_rate(fs)
    if weighting is None or parameters(weighting) is None:
        return None
    from ..weighting import design

    return design(canonical_name(weighting), fs)


def weight(a: np.ndarray, fs: float, weighting: str | None) -> np.ndarray:
    """Frequency-weighted acceleration ``a_w(t)`` in m/s², same shape as ``a`` (Eq 2.79).

    ``a`` in m/s² sampled at ``fs`` Hz (>= 100 Hz), time on the last axis. The weighting runs as
    the recursive filter of :func:`suspopt.weighting.design` (see the module
    docstring), which keeps the weighting's phase: the output is the causal filter's response
    from rest. Deviation from the thesis: Eq 2.79 writes the weighting on the spectrum of the
    whole record; this is its causal time-domain equivalent, matched to the analogue response
    up to ``fs/4``.
    """
    a, fs = _check(a, fs)
    found = weighting_filter(weighting, fs)
    return a.copy() if found is None else found.apply(a)[0]


SUM_BLOCK = 256
"""Samples per block of the weighted metrics' sums (r.m.s., VDV, crest factor): each block is
summed on its own and carried into the total at its end (:func:`power_state`), as the
compiled kernel sums the signals it forms itself."""


def power_state(aw: np.ndarray, state: tuple | None = None) -> tuple:
    """The streamed state of the weighted samples ``aw (..., T)``: ``(count, sums, peak)``,
    ``sums (4, ...)`` the current block's and the total sum of ``a_w²``, the same of ``a_w⁴``
    (:data:`SUM_BLOCK` samples a block), ``peak (...)`` the largest ``|a_w|``, after ``state``
    (the samples before; default none). Sample by sample by the steps every engine uses
    (:func:`suspopt.loops._compiled.powers`), so pieces give the whole record's bits.
    :func:`weighted_value` makes a metric of it."""
    from ..loops import compiled_reductions

    a = np.asarray(aw, dtype=np.float64)
    lead = a.shape[:-1]
    kept = np.zeros((5, *lead))
    if state is None:
        count, kept[4] = 0, -np.inf  # (the largest |a_w|: none yet)
    else:
        count, kept[:4], kept[4] = state
    rows = kept.reshape(5, -1)
    flat = np.ascontiguousarray(a.reshape(-1, a.shape[-1]))
    compiled_reductions().power_rows(flat, count, SUM_BLOCK, rows)  # (in place)
    kept = rows.reshape(5, *lead)
    return count + a.shape[-1], kept[:4], kept[4]


def weighted_value(metric: str, state: tuple, fs: float) -> np.ndarray:
    """The weighted metric ``metric`` of the weighted samples whose streamed state is
    ``state`` (:func:`power_state`) at ``fs`` [Hz]: ``rms_weighted`` ``(Σ a_w² / n)^½``
    (Eq 2.78), ``vdv`` ``(Σ a_w⁴ / fs)^¼`` (Eq 2.82), ``crest_factor`` ``max |a_w| / a_w``
    (Eq 2.83, NaN for an all-zero signal)."""
    count, sums, peak = state
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        if metric == "vdv":
            return ((sums[3] + sums[2]) / fs) ** 0.25
        rms = np.sqrt((sums[1] + sums[0]) / count)
        return rms if metric == "rms_weighted" else peak / rms


def running_state(squared: np.ndarray, fs: float, tau: float, state: tuple | None = None):
    """Eq 2.80 over the squared weighted samples ``squared (..., T)`` that follow ``state``:
    ``(running r.m.s. (..., T), state)``, the state being the running sum of ``a_w²`` and its
    last ``τ fs`` values divided by ``fs`` (default: the record starts here, zero before)."""
    width = max(1, round(tau * fs))
    lead = squared.shape[:-1]
    total, history = state if state is not None else (np.zeros(lead), np.zeros((*lead, width)))
    summed = np.cumsum(np.concatenate([total[..., None], squared], axis=-1), axis=-1)[..., 1:]
    energy = summed / fs
    joined = np.concatenate([history, energy], axis=-1)
    lagged = joined[..., : energy.shape[-1]]
    rms = np.sqrt(np.maximum(energy - lagged, 0.0) / (width / fs))
    return rms, (summed[..., -1], joined[..., joined.shape[-1] - width :])


def weighted_rms(a: np.ndarray, fs: float, weighting: str | None) -> np.ndarray:
    """Weighted r.m.s. acceleration ``RC = a_w`` in m/s² (thesis Eq 2.78, ISO 2631-1 Eq 1).

    ``[(1/T) ∫_0^T a_w² dt]^½`` with the record's ``N`` samples each standing for ``1/fs``
    seconds (``T = N/fs``), i.e. the mean of the squared samples. Returns ``a.shape[:-1]``.
    """
    a, fs = _check(a, fs)
    return weighted_value("rms_weighted", power_state(weight(a, fs, weighting)), fs)


def running_rms(a: np.ndarray, fs: float, weighting: str | None, tau: float = 1.0) -> np.ndarray:
    """Running r.m.s. ``a_w(t0)`` in m/s², shape of ``a`` (thesis Eq 2.80, ISO 2631-1 6.3.1 Eq 2).

    Linear integration over the window ``(t0 - τ, t0]`` of ``τ`` seconds (rounded to whole
    samples): ``[(1/τ) ∫ a_w² dt]^½``. Before ``t0 = τ`` the window reaches back before the
    record, where the signal is taken as zero (the vehicle at rest), so the series ramps up.
    """
    a, fs = _check(a, fs)
    return running_state(np.square(weight(a, fs, weighting)), fs, tau)[0]


def mtvv(a: np.ndarray, fs: float, weighting: str | None, tau: float = 1.0) -> np.ndarray:
    """Maximum transient vibration value in m/s² (thesis Eq 2.81, ISO 2631-1 6.3.1 Eq 4).

    The maximum over time of :func:`running_rms`. The thesis's Eq 2.81 prints ``max(z̈_i(t))``;
    ISO 2631-1 defines MTVV as the maximum of the running r.m.s., which is what is computed.
    """
    return np.max(running_rms(a, fs, weighting, tau), axis=-1)


def vdv(a: np.ndarray, fs: float, weighting: str | None) -> np.ndarray:
    """Vibration dose value ``(∫_0^T a_w⁴ dt)^¼`` in m/s^1.75 (Eq 2.82, ISO 2631-1 6.3.2 Eq 5).

    Not divided by the duration. Rectangle rule over the samples, as :func:`weighted_rms`.
    """
    a, fs = _check(a, fs)
    return weighted_value("vdv", power_state(weight(a, fs, weighting)), fs)


def crest_factor(a: np.ndarray, fs: float, weighting: str | None) -> np.ndarray:
    """Crest factor ``max|a_w| / rms(a_w)``, dimensionless (thesis Eq 2.83, ISO 2631-1 6.2.1).

    NaN for an all-zero signal. The basic method (r.m.s.) suffices while it is at most 9.
    """
    a, fs = _check(a, fs)
    return weighted_value("crest_factor", power_state(weight(a, fs, weighting)), fs)


def ratio_tests(
    a: np.ndarray, fs: float, weighting: str | None, tau: float = 1.0
) -> dict[str, np.ndarray | float]:
    """Whether the basic r.m.s. evaluation suffices (thesis Eq 2.84-2.85, ISO 2631-1 6.3.3).

    Returns ``mtvv_ratio = MTVV/a_w`` and ``vdv_ratio = VDV/(a_w T^¼)`` (dimensionless, ``T``
    the record duration in s), their ISO limits ``mtvv_limit = 1.5`` and ``vdv_limit = 1.75``
    and ``basic_method_sufficient``, true where neither ratio exceeds its limit. The thesis
    prints the limits as equalities; ISO 2631-1 uses them as thresholds, as done here.
    """
    a, fs = _check(a, fs)
    aw = weight(a, fs, weighting)
    sums = power_state(aw)
    rms = weighted_value("rms_weighted", sums, fs)
    duration = aw.shape[-1] / fs
    with np.errstate(invalid="ignore", divide="ignore"):
        mtvv_ratio = np.max(running_state(np.square(aw), fs, tau)[0], axis=-1) / rms
        vdv_ratio = weighted_value("vdv", sums, fs) / (rms * duration**0.25)
    return {
        "mtvv_ratio": mtvv_ratio,
        "vdv_ratio": vdv_ratio,
        "mtvv_limit": MTVV_RATIO_LIMIT,
        "vdv_limit": VDV_RATIO_LIMIT,
        "basic_method_sufficient": (
            (mtvv_ratio <= MTVV_RATIO_LIMIT) & (vdv_ratio <= VDV_RATIO_LIMIT)
        ),
    }


def comfort_reaction(rms: float | np.ndarray) -> str | np.ndarray:
    """ISO 2631-1 Annex C.2.3 comfort reaction(s) to a weighted r.m.s. ``rms`` in m/s².

    The ISO bands overlap (``COMFORT_REACTIONS``). Rule: each band is half-open,
    ``lower <= rms < upper``, and a value that lies in two bands gets both wordings joined by
    ``" / "`` in order of severity, e.g. 0.55 -> ``"a little uncomfortable / fairly
    uncomfortable"``, 0.63 -> ``"fairly uncomfortable"``. Returns a ``str`` for a scalar and an
    array of ``str`` of the same shape otherwise. Negative or NaN values are errors.
    """
    values = np.asarray(rms, dtype=float)
    if np.any(~(values >= 0.0)):
        raise ValueError("weighted r.m.s. acceleration must be a non-negative number")
    labels = _ZONE_LABELS[np.searchsorted(_ZONE_EDGES, values, side="right")]
    return str(labels) if labels.ndim == 0 else labels
