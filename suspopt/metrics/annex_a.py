"""The ISO 2631-1 frequency weightings as defined: the parameters of Annex A and the analogue
response ``H(j2πf)`` each gives (thesis Eq 2.79; docs/iso-facts.md#filter-structure-annex-a),
with the sample rates a weighting is realised at. :mod:`.filters` realises them as recursive
digital filters, :mod:`.iso2631` computes the ride-comfort metrics with those.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "WEIGHTINGS",
    "WeightingParameters",
    "MIN_SAMPLE_RATE",
    "MAX_SAMPLE_RATE",
    "weighting_response",
    "canonical_name",
    "parameters",
    "check_rate",
]

_Q_BAND = 1.0 / math.sqrt(2.0)
MIN_SAMPLE_RATE = 100.0
#: Highest sample rate a weighting is designed for [Hz]: a config's shortest output step
#: (0.1 µs); above it the poles crowd z = 1 past what the filter's coefficients resolve.
MAX_SAMPLE_RATE = 1.0e7
_UNWEIGHTED = "none"


@dataclass(frozen=True)
class WeightingParameters:
    """Corner frequencies (Hz) and quality factors of one ISO 2631-1 Annex A weighting.

    ``math.inf`` for ``f3`` drops the numerator of the acceleration-velocity transition, for
    ``f4`` the whole transition, for ``f5``/``f6`` the upward step (the table in
    docs/iso-facts.md#filter-structure-annex-a); the Q of
    an absent stage is unused and set to 1.
    """

    f1: float
    f2: float
    f3: float
    f4: float
    q4: float
    f5: float
    q5: float
    f6: float
    q6: float


_INF = math.inf
WEIGHTINGS: dict[str, WeightingParameters] = {
    "Wk": WeightingParameters(0.4, 100.0, 12.5, 12.5, 0.63, 2.37, 0.91, 3.35, 0.91),
    "Wd": WeightingParameters(0.4, 100.0, 2.0, 2.0, 0.63, _INF, 1.0, _INF, 1.0),
    "Wf": WeightingParameters(0.08, 0.63, _INF, 0.25, 0.86, 0.0625, 0.80, 0.10, 0.80),
    "Wc": WeightingParameters(0.4, 100.0, 8.0, 8.0, 0.63, _INF, 1.0, _INF, 1.0),
    "We": WeightingParameters(0.4, 100.0, 1.0, 1.0, 0.63, _INF, 1.0, _INF, 1.0),
    "Wj": WeightingParameters(0.4, 100.0, _INF, _INF, 1.0, 3.75, 0.91, 5.32, 0.91),
}
"""ISO 2631-1:1997 Annex A parameters of the six weightings
(docs/iso-facts.md#filter-structure-annex-a)."""
_BY_LOWER_NAME = {name.lower(): name for name in WEIGHTINGS}


def parameters(weighting: str | None) -> WeightingParameters | None:
    """Look a weighting up by name; ``None`` means unweighted. Unknown names suggest matches."""
    if weighting is None or weighting.lower() == _UNWEIGHTED:
        return None
    if weighting.lower() in _BY_LOWER_NAME:
        return WEIGHTINGS[_BY_LOWER_NAME[weighting.lower()]]
    close = difflib.get_close_matches(weighting, [*WEIGHTINGS, _UNWEIGHTED], n=3)
    hint = f" Did you mean {', '.join(close)}?" if close else ""
    raise ValueError(
        f"unknown ISO 2631-1 weighting {weighting!r}; choose one of "
        f"{', '.join(WEIGHTINGS)} or 'none'.{hint}"
    )


def _second_order(s: np.ndarray, f: float, q: float) -> np.ndarray:
    """``1 + s/(Qω) + s²/ω²`` with ``ω = 2πf``; 1 where ``f`` is infinite."""
    if math.isinf(f):
        return np.ones_like(s)
    w = 2.0 * math.pi * f
    return 1.0 + s / (q * w) + (s / w) ** 2


def _response(f: np.ndarray | float, params: WeightingParameters) -> np.ndarray:
    """Analogue Annex A product at frequencies ``f`` (Hz); see :func:`weighting_response`."""
    s = 2j * math.pi * np.asarray(f, dtype=float)
    high_pass = (s / (2.0 * math.pi * params.f1)) ** 2 / _second_order(s, params.f1, _Q_BAND)
    low_pass = 1.0 / _second_order(s, params.f2, _Q_BAND)
    numerator = np.ones_like(s) if math.isinf(params.f3) else 1.0 + s / (2.0 * math.pi * params.f3)
    transition = numerator / _second_order(s, params.f4, params.q4)
    step = _second_order(s, params.f5, params.q5) / _second_order(s, params.f6, params.q6)
    if not math.isinf(params.f5):
        step = step * (params.f5 / params.f6) ** 2
    return high_pass * low_pass * transition * step


def weighting_response(f: np.ndarray | float, weighting: str | None) -> np.ndarray:
    """Complex analogue response ``H(j2πf)`` of an ISO 2631-1 weighting (dimensionless).

    ISO 2631-1:1997 Annex A, the product of (``s = j2πf``, ``ω_i = 2πf_i``, Q1 = Q2 = 1/√2):

    - band-limiting high-pass ``s²/(s² + ω1 s/Q1 + ω1²)`` and low-pass
      ``ω2²/(s² + ω2 s/Q2 + ω2²)``,
    - acceleration-velocity transition ``(1 + s/ω3)/(1 + s/(Q4ω4) + s²/ω4²)``,
    - upward step ``(1 + s/(Q5ω5) + s²/ω5²)/(1 + s/(Q6ω6) + s²/ω6²)·(ω5/ω6)²``.

    This is one factor ``WP`` or ``WA`` of the thesis's Eq 2.79. ``f`` in Hz, any shape; the
    unweighted response is 1.
    """
    params = parameters(weighting)
    if params is None:
        return np.ones_like(np.asarray(f, dtype=float), dtype=complex)
    return _response(f, params)


def check_rate(fs: float) -> float:
    if not fs >= MIN_SAMPLE_RATE:
        raise ValueError(
            f"sampling rate fs = {fs} Hz is below the supported {MIN_SAMPLE_RATE:g} Hz"
        )
    if not fs <= MAX_SAMPLE_RATE * (1.0 + 1e-9):  # (a rate from a sample grid's rounding)
        raise ValueError(
            f"sampling rate fs = {fs} Hz is above the supported {MAX_SAMPLE_RATE:g} Hz"
        )
    return float(fs)


def canonical_name(weighting: str) -> str:
    """The name of a known weighting as :data:`WEIGHTINGS` spells it (``"wk"`` -> ``"Wk"``)."""
    return _BY_LOWER_NAME[str(weighting).lower()]
