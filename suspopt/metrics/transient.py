"""Transient-response metrics of a step or bump response (thesis Sec 2.4.1, Tables 3.3-3.9).

``transient_metrics(t, y)`` takes the time samples ``t`` (s, ``(T,)``) and responses ``y``
(``(T,)`` or ``(P, T)``, any unit) and returns a dict of ``()`` or ``(P,)`` arrays. Only the
samples at or after ``start`` (the time the excitation starts) are analysed.

Rules (Sec 2.4.1 leaves them open; these are the control-engineering conventions):

- initial value ``y_0``: the first analysed sample; steady state ``SST``: the mean of the final
  ``final_fraction`` of the analysed samples.
- change ``Δ = SST - y_0``. The response *returns to its initial value* (e.g. an acceleration,
  whose steady state is 0) when ``|Δ| <= band·max|y - y_0|``; otherwise it *settles at a new
  level* (e.g. a displacement).
- direction: the sign of ``Δ``, or for a returning response the sign of its largest excursion,
  so negative-going responses are handled by the signed excursion ``s·(y - y_0)``.
- reference amplitude ``R``: ``|Δ|``, or the peak excursion for a returning response.
- peak ``M_p``: the response value at the largest signed excursion; ``t_p`` its time.
- overshoot: ``100·s·(M_p - SST)/|Δ|`` in %; NaN for a returning response.
- rise time ``t_r``: from the first crossing of ``0.1 R`` to the first crossing of ``0.9 R`` by
  the signed excursion, crossings linearly interpolated between samples. Sec 2.4.1 says 10 % and
  90 % of ``M_p``; the steady-state change is used instead (as MATLAB's ``stepinfo`` does) so the
  rise time does not depend on the overshoot; a returning response uses its peak, as the thesis.
- settling time ``t_s``: the time after which ``|y - SST|`` stays within ``band·R`` (default 2 %),
  interpolated; NaN unless it falls before the final averaging window (the record is too
  short to show that the response stays in the band, and its steady state is not yet known).

Times are reported absolute (``peak_time``, ``settling_time``: like the thesis's tables, e.g.
t_p = 2.47 s for a bump at 2 s) and from ``start`` (``*_from_start``).
"""

from __future__ import annotations

import numpy as np

__all__ = ["transient_metrics"]


def _take(x: np.ndarray, index: np.ndarray) -> np.ndarray:
    """``x[..., index]`` with one index per leading row."""
    return np.take_along_axis(x, index[..., None], axis=-1)[..., 0]


def _first_crossing(t: np.ndarray, excursion: np.ndarray, level: np.ndarray) -> np.ndarray:
    """First time ``excursion`` reaches ``level`` per row, linearly interpolated; NaN if never."""
    reached = excursion >= level[..., None]
    k = np.argmax(reached, axis=-1)
    before = np.maximum(k - 1, 0)
    e0, e1 = _take(excursion, before), _take(excursion, k)
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = np.where((k > 0) & (e1 != e0), (level - e0) / (e1 - e0), 0.0)
    time = t[before] + fraction * (t[k] - t[before])
    return np.where(reached.any(axis=-1), time, np.nan)


def _settling_time(t: np.ndarray, deviation: np.ndarray, half_width: np.ndarray) -> np.ndarray:
    """Time after which ``|deviation|`` stays within ``half_width``, interpolated."""
    outside = np.abs(deviation) > half_width[..., None]
    n = t.size
    last = n - 1 - np.argmax(outside[..., ::-1], axis=-1)
    after = np.minimum(last + 1, n - 1)
    d0, d1 = _take(deviation, last), _take(deviation, after)
    edge = np.sign(d0) * half_width
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = np.where(d1 != d0, (edge - d0) / (d1 - d0), 0.0)
    time = t[last] + fraction * (t[after] - t[last])
    return np.where(outside.any(axis=-1), time, t[0])


def transient_metrics(
    t: np.ndarray,
    y: np.ndarray,
    band: float = 0.02,
    start: float | None = None,
    final_fraction: float = 0.1,
) -> dict[str, np.ndarray]:
    """Rise time, peak, peak time, overshoot, steady state and settling time (Sec 2.4.1).

    ``t`` in s, ``(T,)``; ``y`` ``(T,)`` or ``(P, T)`` in the response's unit; ``band`` the
    settling band as a fraction of the reference amplitude; ``start`` in s (default ``t[0]``);
    ``final_fraction`` the share of the analysed samples averaged for the steady state. See the
    module docstring for the rules. Keys (values ``()`` or ``(P,)``):
    ``initial_value``, ``steady_state``, ``peak`` (unit of ``y``), ``overshoot`` (%),
    ``rise_time`` (s), ``peak_time``, ``settling_time`` (absolute, s),
    ``peak_time_from_start``, ``settling_time_from_start`` (s), ``returns_to_initial`` (bool).
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    start = float(t[0]) if start is None else float(start)
    analysed = t >= start
    if not analysed.any():
        raise ValueError(f"start = {start} s is after the last sample t = {t[-1]} s")
    first = int(np.argmax(analysed))
    t, y = t[first:], y[..., first:]
    final = max(1, int(np.ceil(final_fraction * t.size)))

    initial = y[..., 0]
    steady = np.mean(y[..., -final:], axis=-1)
    excursion = y - initial[..., None]
    change = steady - initial
    largest_at = np.argmax(np.abs(excursion), axis=-1)
    largest = np.abs(_take(excursion, largest_at))
    returns = np.abs(change) <= band * largest
    direction = np.where(returns, np.sign(_take(excursion, largest_at)), np.sign(change))
    reference = np.where(returns, largest, np.abs(change))

    signed = direction[..., None] * excursion
    peak_at = np.argmax(signed, axis=-1)
    peak = _take(y, peak_at)
    with np.errstate(invalid="ignore", divide="ignore"):
        overshoot = np.where(returns, np.nan, 100.0 * direction * (peak - steady) / np.abs(change))
    rise_time = _first_crossing(t, signed, 0.9 * reference) - _first_crossing(
        t, signed, 0.1 * reference
    )
    peak_time = t[peak_at]
    settling_time = _settling_time(t, y - steady[..., None], band * reference)
    settling_time = np.where(settling_time < t[-final], settling_time, np.nan)
    return {
        "initial_value": initial,
        "steady_state": steady,
        "peak": peak,
        "overshoot": overshoot,
        "rise_time": rise_time,
        "peak_time": peak_time,
        "settling_time": settling_time,
        "peak_time_from_start": peak_time - start,
        "settling_time_from_start": settling_time - start,
        "returns_to_initial": returns,
    }
