"""The ISO 2631-1 frequency weightings: as defined, and as recursive digital filters (the one
way signals are weighted).

ISO 2631-1:1997 Annex A defines each weighting as an analogue product ``H(s)`` of up to four
second-order stages: :data:`WEIGHTINGS` holds their parameters and :func:`weighting_response`
gives ``H(j2πf)`` (thesis Eq 2.79; docs/iso-facts.md#filter-structure-annex-a). The
ride-comfort metrics built on them are :mod:`suspopt.metrics.iso2631`, which re-exports
these names. Sampled at ``fs`` Hz, it
is realised here as ``H_d(z) = C(z) · Π_k S_k(z)``:

- ``S_k(z)``: each Annex A stage (band-limiting high-pass and low-pass, acceleration-velocity
  transition, upward step) by the matched z-transform: its poles and finite zeros mapped
  exactly, ``z = exp(s/fs)`` (the high-pass's double zero at 0 Hz to ``(1 - z⁻¹)²``), and its
  gain at 0 Hz kept (at the Nyquist frequency for the high-pass). A stage's zeros sit beside its poles,
  so no section amplifies the rounding of the one before it; the filter is stable because the
  analogue one is.
- ``C(z)``: a short FIR correction of degree ``M``, fitted by weighted linear least squares so
  that the complex response matches ``H(j2πf)`` in relative terms from 0 Hz to ``fs/4``, with
  Lawson's re-weighting towards the smallest largest error, while ``|H_d - H|`` above ``fs/4``
  (to the Nyquist frequency) is kept small with a weight ``λ``. ``C`` is close to 1 at low
  frequencies, so its coefficients are of order one.

:func:`design` tries ``λ`` = 1, 0.1, 0.01 and, for each, ``M`` = 2, 4, ... 24, and keeps the first
filter whose largest relative error up to ``fs/4`` is within :data:`TARGET` (checked on a finer
grid than the fit's); if none is, the one with the smallest error. The filter records both of its
errors (:attr:`WeightingFilter.error`, :attr:`WeightingFilter.out_of_band`); ``docs/`` tabulates
them against the sample rate. What the sample rate allows: a causal filter cannot follow ``H``
up to the Nyquist frequency and also match it below ``fs/4``, so at low rates the error above
``fs/4`` grows, and below about 500 Hz (Wj: 1 kHz) the error below ``fs/4`` exceeds the target.

The output is the response of the filter starting at rest (the signal taken as zero before the
record), like the causal analogue weighting. Rows of a batch are filtered independently, so a
design's weighted signal has the same bits alone and in a batch; the fit takes its sums in
numpy's own loops, not the threaded BLAS, so that the coefficients have the same bits in every
process (an executor's workers included). Deviation from the thesis: Eq 2.79 applies the
weighting to the spectrum of the record; this is its causal time-domain equivalent.
"""

from __future__ import annotations

import difflib
import functools
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
    "TARGET",
    "WeightingFilter",
    "design",
]

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


#: Largest relative error of the complex response from 0 Hz to ``fs/4`` that :func:`design`
#: aims at (half of the 0.1 % the filters are held to).
TARGET = 5e-4
#: Share of the sample rate up to which the response is fitted.
BAND = 0.25
_DEGREES = tuple(range(2, 25, 2))
_OUT_WEIGHTS = (1.0, 0.1, 0.01)
_LAWSON_STEPS = 12
_Q_BAND = 1.0 / math.sqrt(2.0)


@dataclass(frozen=True)
class WeightingFilter:
    """One ISO 2631-1 weighting at one sample rate ``fs`` [Hz] as a recursive filter.

    ``numerator``: the FIR correction ``C(z)`` (coefficients of ``z⁰, z⁻¹, ...``), applied
    first; ``sections``: the matched stages ``S_k`` as scipy ``sos`` rows
    ``[b0, b1, b2, 1, a1, a2]``; ``error``: largest relative error of the complex response from
    0 Hz to ``fs/4``; ``out_of_band``: largest ``|H_d - H|`` from ``fs/4`` to ``fs/2`` (``H`` is
    dimensionless).
    """

    weighting: str
    fs: float
    numerator: np.ndarray
    sections: np.ndarray
    error: float
    out_of_band: float

    def response(self, f: np.ndarray | float) -> np.ndarray:
        """Complex response ``H_d(exp(j2πf/fs))`` at frequencies ``f`` [Hz]."""
        zi = np.exp(-2j * math.pi * np.asarray(f, dtype=float) / self.fs)
        return _cascade(self.numerator, zi, _stages(self.sections, zi))

    def initial_state(self, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
        """The filter at rest for signals of leading shape ``shape`` (for :meth:`apply`): the
        last ``M`` input samples (zeros) and the sections' states."""
        fir = np.zeros((*shape, len(self.numerator) - 1))
        return fir, np.zeros((len(self.sections), *shape, 2))

    def apply(
        self, a: np.ndarray, state: tuple[np.ndarray, np.ndarray] | None = None
    ) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray]]:
        """Weighted signal of ``a`` (time on the last axis, any unit: the output has it) and
        the filter's state after it; ``state`` continues a signal cut into pieces (default: at
        rest). Pieces give the bits of the whole signal filtered at once. The arithmetic is
        the one every engine uses, compiled (:func:`suspopt.loops._compiled.weight_rows`:
        the FIR taps, then each section in transposed direct form II)."""
        from .loops import compiled_reductions

        a = np.asarray(a, dtype=float)
        if state is None:
            state = self.initial_state(a.shape[:-1])
        history, poles = state
        if a.size == 0:
            return a.copy(), (np.array(history, dtype=float), np.array(poles, dtype=float))
        lead, n, m = a.shape[:-1], a.shape[-1], len(self.numerator) - 1
        rows = np.ascontiguousarray(a.reshape(-1, n))
        history = np.array(history, dtype=float).reshape(rows.shape[0], m)
        poles = np.array(poles, dtype=float).reshape(len(self.sections), rows.shape[0], 2)
        out = np.empty_like(rows)
        compiled_reductions().weight_rows(self.numerator, self.sections, rows, history, poles, out)
        shaped = (history.reshape(*lead, m), poles.reshape(len(self.sections), *lead, 2))
        return out.reshape(a.shape), shaped


def _cascade(numerator: np.ndarray, zi: np.ndarray, stages: np.ndarray) -> np.ndarray:
    """``C(z) · Π S_k(z)`` at ``zi = z⁻¹`` from the stages' product ``stages`` there."""
    return np.polyval(numerator[::-1], zi) * stages


def _quadratic(row: np.ndarray, zi: np.ndarray) -> np.ndarray:
    """``c0 + c1 z⁻¹ + c2 z⁻²`` at ``zi = z⁻¹`` as a product of its root factors, which
    keeps its relative accuracy where a root is close to ``z = 1`` (no cancellation)."""
    c0, c1, c2 = row
    if c2 == 0.0:
        return c0 + c1 * zi
    disc = np.sqrt(complex(c1 * c1 - 4.0 * c0 * c2))
    r1 = (-c1 + disc) / (2.0 * c0) if c1 <= 0 else (-c1 - disc) / (2.0 * c0)
    r2 = c2 / (c0 * r1)
    return c0 * (1.0 - r1 * zi) * (1.0 - r2 * zi)


def _stages(sections: np.ndarray, zi: np.ndarray) -> np.ndarray:
    """``Π_k S_k`` at ``zi = z⁻¹``."""
    value = np.ones_like(zi)
    for row in sections:
        value = value * _quadratic(row[:3], zi) / _quadratic(row[3:], zi)
    return value


def _roots(f: float, q: float) -> tuple[complex, complex]:
    """Roots [1/s] of ``1 + s/(Qω) + s²/ω²`` with ``ω = 2πf``."""
    w = 2.0 * math.pi * f
    root = np.sqrt(complex(1.0 / (4.0 * q * q) - 1.0))
    return w * (-1.0 / (2.0 * q) + root), w * (-1.0 / (2.0 * q) - root)


def _mapped(roots, fs: float) -> list[float]:
    """``[1, c1, c2]`` of ``Π (1 - exp(r/fs) z⁻¹)`` over one or two roots ``r`` [1/s]."""
    z = [np.exp(r / fs) for r in roots]
    if len(z) == 1:
        return [1.0, -float(z[0].real), 0.0]
    return [1.0, -float((z[0] + z[1]).real), float((z[0] * z[1]).real)]


def _at_dc(roots, fs: float) -> float:
    """``Π (1 - exp(r/fs))`` over the roots [1/s]: a mapped factor's value at 0 Hz, by
    ``expm1`` (the coefficients' sum cancels where a root maps close to ``z = 1``)."""
    return float(np.prod([-np.expm1(r / fs) for r in roots]).real) if roots else 1.0


def _sections(params, fs: float) -> np.ndarray:
    """The matched stages as ``sos`` rows, each with its analogue gain at 0 Hz (the
    high-pass: its gain 1 at the Nyquist frequency, ``(1 - z⁻¹)²`` over its poles)."""
    rows = [[1.0, -2.0, 1.0, *_mapped(_roots(params.f1, _Q_BAND), fs)]]
    rows[0][:3] = [c * (1.0 - rows[0][4] + rows[0][5]) / 4.0 for c in rows[0][:3]]
    stages: list[tuple[tuple, tuple, float]] = [((), _roots(params.f2, _Q_BAND), 1.0)]
    if not math.isinf(params.f4):
        zero = () if math.isinf(params.f3) else (-2.0 * math.pi * params.f3,)
        stages.append((zero, _roots(params.f4, params.q4), 1.0))
    if not math.isinf(params.f5):
        gain = (params.f5 / params.f6) ** 2
        stages.append((_roots(params.f5, params.q5), _roots(params.f6, params.q6), gain))
    for zeros, poles, gain in stages:
        top = _mapped(zeros, fs) if zeros else [1.0, 0.0, 0.0]
        bottom = _mapped(poles, fs)
        scale = gain * _at_dc(poles, fs) / _at_dc(zeros, fs)
        rows.append([c * scale for c in top] + bottom)
    return np.array(rows)


def _grids(name: str, fs: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies [Hz] of the fitted band (log and linear spacing from a thousandth of the
    high-pass corner) and of the rest to fs/2."""

    top = BAND * fs
    low = 1e-3 * WEIGHTINGS[name].f1
    inside = np.union1d(np.geomspace(low, top, n), np.linspace(0.0, top, n)[1:])
    return inside, np.linspace(top, 0.5 * fs, n // 2)[1:]


@dataclass(frozen=True)
class _Grid:
    """One frequency grid of a design, evaluated once: ``z⁻¹``, the matched stages ``Π S_k``
    and the analogue response, below fs/4 (``*_in``) and above it (``*_out``)."""

    zi_in: np.ndarray
    stages_in: np.ndarray
    h_in: np.ndarray
    zi_out: np.ndarray
    stages_out: np.ndarray
    h_out: np.ndarray


def _grid(name: str, fs: float, sections: np.ndarray, n: int) -> _Grid:

    inside, outside = _grids(name, fs, n)
    zi_in, zi_out = np.exp(-2j * math.pi * inside / fs), np.exp(-2j * math.pi * outside / fs)
    return _Grid(
        zi_in,
        _stages(sections, zi_in),
        weighting_response(inside, name),
        zi_out,
        _stages(sections, zi_out),
        weighting_response(outside, name),
    )


def _fit(grid: _Grid, degree: int, weight_out: float) -> np.ndarray:
    """``C``'s coefficients: relative least squares below fs/4, Lawson-re-weighted, plus the
    absolute error above it weighted by ``weight_out``. The columns are ``z⁻ᵐ Π_k S_k``,
    m = 0..degree."""
    powers = np.arange(degree + 1)
    a_in = (grid.stages_in[:, None] * grid.zi_in[:, None] ** powers) / grid.h_in[:, None]
    a_out = weight_out * (grid.stages_out[:, None] * grid.zi_out[:, None] ** powers)
    b_out = weight_out * grid.h_out
    lawson = np.ones(len(grid.zi_in))
    for _ in range(_LAWSON_STEPS):
        root = np.sqrt(lawson)[:, None]
        coefficients = _least_squares(
            np.vstack([a_in * root, a_out]), np.concatenate([root[:, 0], b_out])
        )
        lawson = lawson * np.abs(np.einsum("ij,j->i", a_in, coefficients) - 1.0)
        lawson = lawson / lawson.mean()
    return coefficients


def _least_squares(matrix: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Real ``x`` minimising ``|matrix x - rhs|`` (complex rows), by the normal equations
    with their sums taken by ``einsum`` (numpy's own loops, not the threaded BLAS): the
    coefficients, and so every weighted signal, have the same bits in every process and
    thread count. Columns are scaled to unit norm first."""
    stacked = np.concatenate([matrix.real, matrix.imag])
    target = np.concatenate([rhs.real, rhs.imag])
    norms = np.sqrt(np.einsum("ij,ij->j", stacked, stacked))
    stacked = stacked / norms
    gram = np.einsum("ij,ik->jk", stacked, stacked)
    return np.linalg.solve(gram, np.einsum("ij,i->j", stacked, target)) / norms


def _errors(grid: _Grid, numerator: np.ndarray) -> tuple[float, float]:
    """(largest relative error up to fs/4, largest absolute error above) on ``grid``, the
    stages evaluated once."""
    inside = _cascade(numerator, grid.zi_in, grid.stages_in)
    outside = _cascade(numerator, grid.zi_out, grid.stages_out)
    relative = np.abs(inside / grid.h_in - 1.0)
    return float(relative.max()), float(np.abs(outside - grid.h_out).max())


@functools.lru_cache(maxsize=64)
def design(weighting: str, fs: float) -> WeightingFilter:
    """The recursive filter of the ISO 2631-1 weighting ``weighting`` (a name of
    :data:`~suspopt.metrics.iso2631.WEIGHTINGS`) at the sample rate ``fs`` [Hz]; see the
    module docstring for the method. Cached per process."""

    params = WEIGHTINGS[weighting]
    sections = _sections(params, fs)
    fitted, checked = _grid(weighting, fs, sections, 600), _grid(weighting, fs, sections, 4000)
    best: WeightingFilter | None = None
    for weight_out in _OUT_WEIGHTS:
        for degree in _DEGREES:
            numerator = _fit(fitted, degree, weight_out)
            error, out_of_band = _errors(checked, numerator)
            found = WeightingFilter(weighting, fs, numerator, sections, error, out_of_band)
            if best is None or error < best.error:
                best = found
            if error <= TARGET:
                return found
    assert best is not None
    return best
