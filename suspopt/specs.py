"""Metric specs: ``{metric, signal, corners, reduce, weighting, ...}`` evaluated on a Result.

A spec names a metric of :data:`METRICS` and the signal it applies to. ``signal`` is either a
full signal name (``body.heave_acc``) or a per-corner family (``travel``), which yields one value
per corner (``corners`` picks them, default all) unless ``reduce`` combines them (``mean``,
``max``, ``min``, ``sum``; e.g. Eq 5.5-5.6 average the front and rear corners). Metrics of the
``derived`` kind (dissipated power, spring usage, dynamic tyre load) take their signals from the
corner itself and need no ``signal``. Values are (P,) arrays in SI units.

The same specs serve ``simulate`` (what to store under /metrics) and, later, objectives and
constraints.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import suggest
from .metrics import energy, iso2631, springs, stats, transient

__all__ = ["METRICS", "MetricDef", "evaluate_spec", "spec_signals", "metric_unit"]


@dataclass(frozen=True)
class MetricDef:
    """A metric: ``kind`` says what it is computed from (statistic | iso2631 | transient |
    switches | derived), ``unit`` maps the signal's unit to the metric's, ``compute(spec,
    result, signal)`` gives its (P,) values from one signal of a Result, and a ``derived``
    metric reads the per-corner signals of ``family`` (it takes no ``signal``) and, when
    ``also`` names another family, that family's signal of the same corner. ``stream`` says
    how a run that keeps no (P, T) signal (:mod:`suspopt.streaming`) gets it: ``moments``
    (from the signal's count, mean and squared deviations), ``extremes`` (its maximum and
    minimum), ``window_max`` (the largest of ``compute`` over the windows of time: a maximum
    over time of a value per sample), ``weighted`` (an ISO 2631 weighted metric, from the
    weighting's filter run on window by window) or ``keep`` (``compute`` on the signal kept
    whole). ``extremes(spec, model, signal)``, for a ``window_max`` metric, says whether its
    value over a record is its value over the record's largest and smallest sample alone
    (for the designs of ``model``); then the compiled kernel may keep those two instead of
    the signal (:mod:`suspopt.integrator.accumulators`).
    Adding a metric is adding one entry to :data:`METRICS`."""

    kind: str
    unit: Callable[[str], str]
    description: str
    compute: Callable[[Any, Any, str], np.ndarray]
    family: str | None = None
    also: str | None = None
    stream: str = "keep"
    extremes: Callable[[Any, Any, str], bool] | None = None


def _same(u: str) -> str:
    return u


def _square(u: str) -> str:
    return f"({u})^2" if " " in u or "/" in u else f"{u}^2"


def _fixed(unit: str) -> Callable[[str], str]:
    return lambda _u: unit


def _rate(result) -> float:
    """The output sample rate of a Result [Hz]."""
    return 1.0 / (result.time[1] - result.time[0])


def _statistic(name: str) -> MetricDef:
    description = {
        "var": "variance (Eq 2.87, 2.89, 2.91, 5.4)",
        "std": "standard deviation",
        "rms": "root mean square",
        "max": "maximum (Eq 2.88, 2.90)",
        "min": "minimum",
        "max_abs": "maximum absolute value",
        "mean": "mean",
        "peak_to_peak": "maximum minus minimum",
    }[name]
    function = stats.STATISTICS[name]
    return MetricDef(
        "statistic",
        _square if name == "var" else _same,
        description,
        lambda spec, r, signal: function(r.signals[signal]),
        stream="moments" if name in ("var", "std", "rms", "mean") else "extremes",
    )


def _weighted(function) -> Callable[[Any, Any, str], np.ndarray]:
    return lambda spec, r, signal: function(r.signals[signal], _rate(r), spec.weighting)


def _transient(key: str) -> Callable[[Any, Any, str], np.ndarray]:
    def compute(spec, r, signal):
        start = getattr(r.config.road, "start", None)
        return transient.transient_metrics(r.time, r.signals[signal], band=spec.band, start=start)[
            key
        ]

    return compute


def _corner(r, signal: str) -> tuple[str, int]:
    corner = signal.rsplit(".", 1)[1]
    return corner, r.model.corners.index(corner)


def _dissipated_power(spec, r, signal):
    corner, _ = _corner(r, signal)
    return energy.mean_dissipated_power(
        r.signals[f"damper_force.{corner}"], r.signals[signal], r.time
    )


def _spring_usage(spec, r, signal):
    _, c = _corner(r, signal)
    return springs.nonlinear_spring_usage(
        r.signals[signal], r.model.spring_linear[:, 0, c], r.model.spring_cubic[:, 0, c]
    )


def _spring_usage_extremes(spec, model, signal: str) -> bool:
    """Eq 5.3's ratio grows with the travel's square when ``k_l > 0`` and ``k_nl >= 0``
    (:func:`suspopt.metrics.springs.nonlinear_spring_usage`), so its largest value is at the
    record's largest or smallest travel."""
    c = model.corners.index(signal.rsplit(".", 1)[1])
    k_l, k_nl = model.spring_linear[:, 0, c], model.spring_cubic[:, 0, c]
    return bool(np.all(k_l > 0.0) and np.all(k_nl >= 0.0))


def _dynamic_tyre_load(spec, r, signal):
    _, c = _corner(r, signal)
    return stats.dynamic_tyre_load_ratio(r.signals[signal], r.model.static_tyre_load[:, 0, c])


METRICS: dict[str, MetricDef] = {
    **{name: _statistic(name) for name in stats.STATISTICS},
    "rms_weighted": MetricDef(
        "iso2631",
        _same,
        "ISO 2631-1 weighted r.m.s., RC (Eq 2.78)",
        _weighted(iso2631.weighted_rms),
        stream="weighted",
    ),
    "vdv": MetricDef(
        "iso2631",
        lambda u: f"{u} s^0.25" if u != "m/s^2" else "m/s^1.75",
        "vibration dose value (Eq 2.82)",
        _weighted(iso2631.vdv),
        stream="weighted",
    ),
    "mtvv": MetricDef(
        "iso2631",
        _same,
        "maximum transient vibration value (Eq 2.81)",
        lambda spec, r, signal: iso2631.mtvv(
            r.signals[signal], _rate(r), spec.weighting, tau=spec.tau
        ),
        stream="weighted",
    ),
    "crest_factor": MetricDef(
        "iso2631",
        _fixed("1"),
        "crest factor (Eq 2.83)",
        _weighted(iso2631.crest_factor),
        stream="weighted",
    ),
    "peak": MetricDef("transient", _same, "transient peak M_p (Sec 2.4.1)", _transient("peak")),
    "peak_time": MetricDef(
        "transient", _fixed("s"), "time of the peak t_p (Sec 2.4.1)", _transient("peak_time")
    ),
    "rise_time": MetricDef(
        "transient", _fixed("s"), "10-90 % rise time t_r (Sec 2.4.1)", _transient("rise_time")
    ),
    "settling_time": MetricDef(
        "transient", _fixed("s"), "settling time t_s (Sec 2.4.1)", _transient("settling_time")
    ),
    "overshoot": MetricDef(
        "transient", _fixed("%"), "overshoot M_ov (Sec 2.4.1)", _transient("overshoot")
    ),
    "steady_state": MetricDef(
        "transient", _same, "steady state SST (Sec 2.4.1)", _transient("steady_state")
    ),
    "switches": MetricDef(
        "switches",
        _fixed("1"),
        "number of state changes SW (Sec 2.4.6)",
        lambda spec, r, signal: energy.damper_switches(r.signals[signal]),
    ),
    "dissipated_power": MetricDef(
        "derived",
        _fixed("W"),
        "mean damper power DE (Eq 2.92)",
        _dissipated_power,
        family="travel_vel",
        also="damper_force",
    ),
    "spring_usage": MetricDef(
        "derived",
        _fixed("1"),
        "non-linear spring usage (Eq 5.3)",
        _spring_usage,
        family="travel",
        stream="window_max",
        extremes=_spring_usage_extremes,
    ),
    "dynamic_tyre_load": MetricDef(
        "derived",
        _fixed("1"),
        "std of dynamic tyre load over static load",
        _dynamic_tyre_load,
        family="tyre_force",
    ),
}
_REDUCE: dict[str, Callable[..., np.ndarray]] = {
    "mean": np.mean,
    "max": np.max,
    "min": np.min,
    "sum": np.sum,
}


def spec_signals(spec, available: list[str], corners: tuple[str, ...]) -> list[str]:
    """Signal names a spec reads, one per corner for a family; raise ValueError if unknown."""
    kind = METRICS[spec.metric].kind
    if kind == "derived":
        if spec.signal is not None:
            raise ValueError(f"metric {spec.metric!r} takes no signal (it uses each corner's own)")
        family = METRICS[spec.metric].family
    elif spec.signal is None:
        raise ValueError(f"metric {spec.metric!r} needs a signal")
    else:
        family = spec.signal
    if family in available:
        if spec.corners:
            raise ValueError(f"signal {family!r} is not per corner; drop 'corners'")
        return [family]
    wanted = spec.corners or [c for c in corners if f"{family}.{c}" in available]
    names = [f"{family}.{c}" for c in wanted]
    missing = [n for n in names if n not in available]
    if not names or missing:
        bad = missing[0] if missing else family
        families = sorted({n.rsplit(".", 1)[0] for n in available} | set(available))
        close = suggest(bad, families + available)
        raise ValueError(
            f"unknown signal {bad!r}" + (f"; did you mean {', '.join(close)}?" if close else "")
        )
    return names


def metric_unit(spec, signal_unit: str) -> str:
    return METRICS[spec.metric].unit(signal_unit)


def evaluate_spec(
    spec, result, signal_units: Callable[[str], str]
) -> list[tuple[str, np.ndarray, str]]:
    """``[(name, values (P,), unit), ...]`` of one spec on a Result."""
    names = spec_signals(spec, list(result.signals), result.model.corners)
    base = spec.name or ".".join(filter(None, [spec.metric, spec.signal or None, spec.weighting]))
    unit = metric_unit(spec, signal_units(names[0]))
    values = [np.asarray(result.metric(spec, n), dtype=float) for n in names]
    if len(names) == 1 and spec.signal in result.signals:
        return [(base, values[0], unit)]
    if spec.reduce != "none":
        return [(base, _REDUCE[spec.reduce](np.stack(values), axis=0), unit)]
    return [(f"{base}.{n.rsplit('.', 1)[1]}", v, unit) for n, v in zip(names, values)]
