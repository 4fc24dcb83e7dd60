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

import difflib
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


__all__ = ["METRICS", "MetricDef", "evaluate_spec", "spec_signals", "metric_unit"]


@dataclass(frozen=True)
class MetricDef:
    """A metric: ``kind`` says what it is computed from; ``unit`` maps the signal's unit."""

    kind: str                    # statistic | iso2631 | transient | switches | derived
    unit: Callable[[str], str]
    description: str


def _same(u: str) -> str:
    return u


def _square(u: str) -> str:
    return f"({u})^2" if " " in u or "/" in u else f"{u}^2"


def _fixed(unit: str) -> Callable[[str], str]:
    return lambda _u: unit


METRICS: dict[str, MetricDef] = {
    "var": MetricDef("statistic", _square, "variance (Eq 2.87, 2.89, 2.91, 5.4)"),
    "std": MetricDef("statistic", _same, "standard deviation"),
    "rms": MetricDef("statistic", _same, "root mean square"),
    "max": MetricDef("statistic", _same, "maximum (Eq 2.88, 2.90)"),
    "min": MetricDef("statistic", _same, "minimum"),
    "max_abs": MetricDef("statistic", _same, "maximum absolute value"),
    "mean": MetricDef("statistic", _same, "mean"),
    "peak_to_peak": MetricDef("statistic", _same, "maximum minus minimum"),
    "rms_weighted": MetricDef("iso2631", _same, "ISO 2631-1 weighted r.m.s., RC (Eq 2.78)"),
    "vdv": MetricDef("iso2631", lambda u: f"{u} s^0.25" if u != "m/s^2" else "m/s^1.75",
                     "vibration dose value (Eq 2.82)"),
    "mtvv": MetricDef("iso2631", _same, "maximum transient vibration value (Eq 2.81)"),
    "crest_factor": MetricDef("iso2631", _fixed("1"), "crest factor (Eq 2.83)"),
    "peak": MetricDef("transient", _same, "transient peak M_p (Sec 2.4.1)"),
    "peak_time": MetricDef("transient", _fixed("s"), "time of the peak t_p (Sec 2.4.1)"),
    "rise_time": MetricDef("transient", _fixed("s"), "10-90 % rise time t_r (Sec 2.4.1)"),
    "settling_time": MetricDef("transient", _fixed("s"), "settling time t_s (Sec 2.4.1)"),
    "overshoot": MetricDef("transient", _fixed("%"), "overshoot M_ov (Sec 2.4.1)"),
    "steady_state": MetricDef("transient", _same, "steady state SST (Sec 2.4.1)"),
    "switches": MetricDef("switches", _fixed("1"), "number of state changes SW (Sec 2.4.6)"),
    "dissipated_power": MetricDef("derived", _fixed("W"), "mean damper power DE (Eq 2.92)"),
    "spring_usage": MetricDef("derived", _fixed("1"), "non-linear spring usage (Eq 5.3)"),
    "dynamic_tyre_load": MetricDef("derived", _fixed("1"),
                                   "std of dynamic tyre load over static load"),
}

#: The statistics by metric name: functions of :mod:`suspopt.metrics.stats`.
_STAT = {"var": "var", "std": "std", "rms": "rms", "max": "maximum", "min": "minimum",
         "max_abs": "max_abs", "mean": "mean", "peak_to_peak": "peak_to_peak"}
_REDUCE = {"mean": np.mean, "max": np.max, "min": np.min, "sum": np.sum}


def spec_signals(spec, available: list[str], corners: tuple[str, ...]) -> list[str]:
    """Signal names a spec reads, one per corner for a family; raise ValueError if unknown."""
    kind = METRICS[spec.metric].kind
    if kind == "derived":
        if spec.signal is not None:
            raise ValueError(f"metric {spec.metric!r} takes no signal (it uses each corner's own)")
        family = {"dissipated_power": "travel_vel", "spring_usage": "travel",
                  "dynamic_tyre_load": "tyre_force"}[spec.metric]
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
        close = difflib.get_close_matches(bad, families + available, n=3)
        raise ValueError(f"unknown signal {bad!r}" +
                         (f"; did you mean {', '.join(close)}?" if close else ""))
    return names


def metric_unit(spec, signal_unit: str) -> str:
    return METRICS[spec.metric].unit(signal_unit)


def _one(spec, result, name: str) -> np.ndarray:
    """The metric of one signal, (P,)."""
    # the metrics (scipy) load when a metric is first computed, not when a config is read
    from .metrics import energy, iso2631, springs, stats, transient

    kind = METRICS[spec.metric].kind
    if kind == "derived":
        corner = name.rsplit(".", 1)[1]
        c = result.model.corners.index(corner)
        if spec.metric == "dissipated_power":
            return energy.mean_dissipated_power(result.signals[f"damper_force.{corner}"],
                                                result.signals[name], result.time)
        if spec.metric == "spring_usage":
            return springs.nonlinear_spring_usage(result.signals[name],
                                                  result.model.spring_linear[:, 0, c],
                                                  result.model.spring_cubic[:, 0, c])
        return stats.dynamic_tyre_load_ratio(result.signals[name],
                                             result.model.static_tyre_load[:, 0, c])
    x = result.signals[name]
    if kind == "statistic":
        return getattr(stats, _STAT[spec.metric])(x)
    fs = 1.0 / (result.time[1] - result.time[0])
    if kind == "iso2631":
        if spec.metric == "mtvv":
            return iso2631.mtvv(x, fs, spec.weighting, tau=spec.tau)
        return {"rms_weighted": iso2631.weighted_rms, "vdv": iso2631.vdv,
                "crest_factor": iso2631.crest_factor}[spec.metric](x, fs, spec.weighting)
    if kind == "transient":
        start = getattr(result.config.road, "start", None)
        values = transient.transient_metrics(result.time, x, band=spec.band, start=start)
        return values[spec.metric]
    return energy.damper_switches(x)


def evaluate_spec(spec, result, signal_units: Callable[[str], str]
                  ) -> list[tuple[str, np.ndarray, str]]:
    """``[(name, values (P,), unit), ...]`` of one spec on a Result."""
    names = spec_signals(spec, list(result.signals), result.model.corners)
    base = spec.name or ".".join(filter(None, [spec.metric, spec.signal or None,
                                               spec.weighting]))
    unit = metric_unit(spec, signal_units(names[0]))
    values = [np.asarray(_one(spec, result, n), dtype=float) for n in names]
    if len(names) == 1 and spec.signal in result.signals:
        return [(base, values[0], unit)]
    if spec.reduce != "none":
        return [(base, _REDUCE[spec.reduce](np.stack(values), axis=0), unit)]
    return [(f"{base}.{n.rsplit('.', 1)[1]}", v, unit) for n, v in zip(names, values)]
