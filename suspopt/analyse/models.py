"""``suspopt analyse models A.yaml B.yaml ... [--reference A.yaml]``: models side by side (Ch. 3).

Chapter 3 compares the QC, HC1, HC2 and FC models (Part 1), and a model with and without an
anti-roll bar or a tyre damper (Part 2), on one road. Each config is simulated (one design);
the analysis gathers, per model:

- time responses of the sprung mass ``z_s``, ``z̈_s``, the roll ``φ`` where the model has one,
  and the front right wheel ``z_u``, ``z̈_u`` (Figs. 3.2-3.5, 3.9-3.12, 3.17-3.19);
- on a bump (``bump_step``, ``bump_half_sine``), the transient metrics of Sec 2.4.1 of ``z̈_s``,
  ``z_s`` and (when every model has it) ``φ``: peak M_p, t_p, rise time, settling time (2 %),
  overshoot and steady state (Tables 3.3-3.4, 3.8-3.9, 3.12-3.14, 3.18-3.19), from
  :func:`suspopt.metrics.transient_metrics` with the road's ``start`` as the step time;
- on a random road, the ride metrics RC (Wk-weighted r.m.s. of ``z̈_s``, Eq 2.78) and
  max|z̈_s|, and per corner VST, MST, VTD, MTD (Eq 2.87-2.90) (Tables 3.6-3.7, 3.10-3.11,
  3.16-3.17, 3.20-3.21), plus the variance and maximum of ``φ`` when every model rolls;
- the undamped natural frequencies (:func:`suspopt.modal_analysis`, Tables 3.5, 3.15): each
  body mode by its dominant DOF, and the lowest wheel-hop mode;
- the Welch PSD of ``z̈_s`` and, where the model rolls, of ``φ̈`` (Figs. 3.8, 3.15, 3.21, 3.24;
  8 s Hann segments, 0.125 Hz resolution).

Every metric is compared with the reference model (default the first config) as
``difference = 100 (X - X_ref) / X_ref`` %, the formula Sec 3.2.1 writes. Deviation: the
tables themselves print the opposite sign, ``(X_ref - X) / X_ref`` (Table 3.3: FC's peak 3.97
against QC's 7.92 is printed +50 %). A per-corner metric of a corner the reference lacks is
compared with the reference's only corner when the reference is a quarter car (it stands for
every wheel, as the thesis compares HC2's and FC's rear travel with QC's), else not at all.

The file's layout: :data:`suspopt.formats.MODELS`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import plots
from ..config import Config, ConfigError, load_config
from ..config.metrics import MetricSpec
from ..files import listed
from ..formats import MODELS
from ..io import atomic_h5, put, write_attrs
from ..metrics.spectral import PSD_SEGMENT, record_psd
from ..simulation import Result, simulate
from ..specs import METRICS, evaluate_spec
from ..vehicle import modal_analysis
from .cells import NOT_COMPUTED_NOTE, percent
from .registry import KINDS, Analysis, Kind, Report, analysis, relative_change

__all__ = [
    "ModelResponse",
    "ModelComparison",
    "compare_models",
    "write_models",
    "plot_models",
    "run",
    "TIME_SIGNALS",
    "PSD_SIGNALS",
    "PSD_SEGMENT",
]

#: Signals kept for the time-response figures and the HDF5 file, where the model has them.
TIME_SIGNALS = ("body.heave_acc", "body.heave", "body.roll", "wheel.F1.heave_acc", "wheel.F1.heave")
#: Signals whose Welch PSD is computed, where the model has them.
PSD_SIGNALS = ("body.heave_acc", "body.roll_acc")
_BUMPS = ("bump_step", "bump_half_sine")
_CORNERS = ("F1", "F2", "R1", "R2")
#: Transient metrics (Sec 2.4.1) of an acceleration, which returns to 0 (no overshoot or new
#: steady state to speak of), and of a displacement or angle.
_TRANSIENT_ACC = ("peak", "peak_time", "rise_time", "settling_time")
_TRANSIENT = _TRANSIENT_ACC + ("overshoot", "steady_state")
_NATURAL = ("body.heave", "body.roll", "body.pitch", "wheel_hop")
_RIDE = (
    {"name": "RC", "metric": "rms_weighted", "signal": "body.heave_acc", "weighting": "Wk"},
    {"name": "max_body_acc", "metric": "max_abs", "signal": "body.heave_acc"},
    {"name": "VST", "metric": "var", "signal": "travel"},
    {"name": "MST", "metric": "max", "signal": "travel"},
    {"name": "VTD", "metric": "var", "signal": "tyre_deflection"},
    {"name": "MTD", "metric": "max", "signal": "tyre_deflection"},
)
_RIDE_ROLL = (
    {"metric": "var", "signal": "body.roll"},
    {"metric": "max_abs", "signal": "body.roll"},
)


@dataclass
class ModelResponse:
    """One model's run: ``time (T,)`` [s], ``signals`` (name -> (T,)), ``psd`` (name ->
    (F,)) over ``psd_frequency`` [Hz], ``metrics`` (name -> value), ``natural_frequency (n,)``
    [Hz] with each mode's ``dominant`` DOF and ``mode_label`` (what the mode is,
    :class:`suspopt.vehicle.ModalResult`); ``units`` of every signal, PSD and metric."""

    label: str
    source: Path
    config: Config
    time: np.ndarray
    signals: dict[str, np.ndarray]
    psd_frequency: np.ndarray
    psd: dict[str, np.ndarray]
    metrics: dict[str, float]
    natural_frequency: np.ndarray
    dominant: list[str]
    mode_label: list[str]
    units: dict[str, str]
    diverged: bool
    corners: tuple[str, ...]
    order: dict[str, tuple[int, int]]  # table position: (spec, corner)


@dataclass
class ModelComparison:
    """Several models, the reference's index, and per metric (in table order) the values
    ``(M,)`` and differences from the reference ``(M,)`` [%]."""

    models: list[ModelResponse]
    reference: int
    metric_names: list[str]
    metric_units: dict[str, str]
    value: dict[str, np.ndarray] = field(default_factory=dict)
    difference: dict[str, np.ndarray] = field(default_factory=dict)


def _labels(sources: Sequence[Path]) -> list[str]:
    stems = [Path(s).stem for s in sources]
    if len(set(stems)) == len(stems):
        return stems
    return [str(s) for s in sources]


def _specs(configs: Sequence[Config], all_roll: bool) -> list[MetricSpec]:
    """The metric set of the road kind the configs share (module docstring)."""
    kinds = {cfg.road.kind for cfg in configs}
    bump = kinds <= set(_BUMPS)
    if not bump and kinds & set(_BUMPS):
        names = ", ".join(
            f"{cfg.source.name if cfg.source else '?'} ({cfg.road.kind})" for cfg in configs
        )
        raise ConfigError(
            f"analyse models compares models on one kind of road, bumps or "
            f"random roads, not both: {names}"
        )
    if bump:
        signals = ["body.heave_acc", "body.heave"] + (["body.roll"] if all_roll else [])
        return [
            MetricSpec(metric=m, signal=s)
            for s in signals
            for m in (_TRANSIENT_ACC if s.endswith("_acc") else _TRANSIENT)
        ]
    return [MetricSpec.model_validate(d) for d in _RIDE + (_RIDE_ROLL if all_roll else ())]


def _response(
    label: str, source: Path, cfg: Config, result: Result, specs: Sequence[MetricSpec]
) -> ModelResponse:
    sig = result.signals
    fs = cfg.simulation.output_rate
    units = {name: result.signal_unit(name) for name in TIME_SIGNALS + PSD_SIGNALS if name in sig}
    spectra = {}
    frequency = np.empty(0)
    for name in PSD_SIGNALS:
        if name in sig:
            frequency, spectra[name] = record_psd(sig[name][0], fs)
            units[f"PSD of {name}"] = METRICS["var"].unit(units[name]) + "/Hz"
    metrics, order = {}, {}
    for j, spec in enumerate(specs):
        with np.errstate(invalid="ignore", divide="ignore"):
            for name, values, unit in evaluate_spec(spec, result, result.signal_unit):
                metrics[name] = float(values[0])
                units[name] = unit
                corner = name.rpartition(".")[2]
                order[name] = (j, _CORNERS.index(corner) if corner in _CORNERS else -1)
    modes = modal_analysis(result.model)
    dominant = [str(d) for d in modes.dominant[0]]
    wheels = [f for f, d in zip(modes.frequency[0], dominant) if d.startswith("wheel.")]
    natural = {dof: modes.frequency[0, dominant.index(dof)] for dof in _NATURAL if dof in dominant}
    natural["wheel_hop"] = min(wheels)
    for k, dof in enumerate(_NATURAL):
        if dof in natural:
            name = f"natural_frequency.{dof}"
            metrics[name] = float(natural[dof])
            units[name] = "Hz"
            order[name] = (len(specs) + k, -1)
    return ModelResponse(
        label=label,
        source=source,
        config=cfg,
        time=result.time,
        signals={n: sig[n][0] for n in TIME_SIGNALS if n in sig},
        psd_frequency=frequency,
        psd=spectra,
        metrics=metrics,
        natural_frequency=modes.frequency[0],
        dominant=dominant,
        mode_label=[str(x) for x in modes.label[0]],
        units=units,
        diverged=bool(result.diverged[0]),
        corners=result.model.corners,
        order=order,
    )


def _reference_value(ref: ModelResponse, name: str) -> float:
    """The reference's value of metric ``name``; a quarter car's only corner stands for a
    corner it lacks."""
    if name in ref.metrics:
        return ref.metrics[name]
    base, _, corner = name.rpartition(".")
    if len(ref.corners) == 1 and corner in _CORNERS and base:
        return ref.metrics.get(f"{base}.{ref.corners[0]}", np.nan)
    return np.nan


def compare_models(
    sources: Sequence[str | Path], reference: str | Path | None = None
) -> ModelComparison:
    """Simulate every config of ``sources`` and compare them with ``reference`` (one of
    them; default the first), as the module docstring says."""
    paths = [Path(s) for s in listed(sources)]
    if len(paths) < 2:
        raise ConfigError("analyse models compares at least two configs")
    resolved = [s.resolve() for s in paths]
    if len(set(resolved)) != len(resolved):
        raise ConfigError("analyse models: a config is given twice")
    ref = 0
    if reference is not None:
        if Path(reference).resolve() not in resolved:
            raise ConfigError(f"--reference {reference}: not one of the configs compared")
        ref = resolved.index(Path(reference).resolve())
    configs = [load_config(s) for s in paths]
    results = [simulate(cfg) for cfg in configs]
    all_roll = all("body.roll" in r.signals for r in results)
    specs = _specs(configs, all_roll)
    models = [
        _response(label, s, cfg, r, specs)
        for label, s, cfg, r in zip(_labels(paths), paths, configs, results)
    ]
    order: dict[str, tuple[int, int]] = {}
    units: dict[str, str] = {}
    for model in models:
        for name in model.metrics:
            order.setdefault(name, model.order[name])
            units.setdefault(name, model.units[name])
    names = sorted(order, key=lambda name: order[name])
    comparison = ModelComparison(
        models=models, reference=ref, metric_names=names, metric_units=units
    )
    for name in names:
        value = np.array([m.metrics.get(name, np.nan) for m in models])
        comparison.value[name] = value
        comparison.difference[name] = relative_change(value, _reference_value(models[ref], name))
    return comparison


def write_models(path: str | Path, comparison: ModelComparison, command: str | None = None) -> Path:
    """Write ``comparison`` with the layout of the module docstring (atomically)."""
    models = comparison.models
    ref = models[comparison.reference]
    labels = [m.label for m in models]
    with atomic_h5(path, ref.config, command) as h5:
        write_attrs(h5, analysis="models", models=labels, reference=ref.label)
        top = h5.create_group("models")
        for m in models:
            g = top.create_group(m.label.replace("/", "_"))
            write_attrs(
                g,
                source=str(m.source),
                config=m.config.text,
                preset=m.config.vehicle.preset,
                road=m.config.road.kind,
            )
            put(MODELS, g, "time", m.time)
            sig = g.create_group("signals")
            for name, values in m.signals.items():
                put(MODELS, sig, name, values, m.units[name])
            spectra = g.create_group("psd")
            put(MODELS, spectra, "frequency", m.psd_frequency)
            for name, values in m.psd.items():
                put(MODELS, spectra, name, values, m.units[f"PSD of {name}"])
            modal = g.create_group("modal")
            put(MODELS, modal, "frequency", m.natural_frequency, dominant=list(m.dominant),
                label=list(m.mode_label))  # fmt: skip
        comparison_group = h5.create_group("comparison")
        put(MODELS, comparison_group, "model", labels)
        value = comparison_group.create_group("value")
        difference = comparison_group.create_group("difference")
        for name in comparison.metric_names:
            unit = comparison.metric_units[name]
            put(MODELS, value, name, comparison.value[name], unit, models=labels)
            put(MODELS, difference, name, comparison.difference[name], models=labels)
    return Path(path)


def plot_models(comparison: ModelComparison, path: str | Path, title: str) -> Path:
    """Time responses of every signal all models have, and their PSDs
    (:func:`suspopt.plots.model_comparison`)."""
    models = comparison.models
    units = models[comparison.reference].units
    time_series = {
        name: [(m.label, m.time, m.signals[name]) for m in models]
        for name in TIME_SIGNALS
        if all(name in m.signals for m in models)
    }
    spectra = {
        name: [(m.label, m.psd_frequency, m.psd[name]) for m in models]
        for name in PSD_SIGNALS
        if all(name in m.psd for m in models)
    }
    return plots.model_comparison(path, title, time_series, spectra, units)


def _cell(value: float) -> str:
    return "-" if np.isnan(value) else f"{value:.4g}"


def run(sources: Sequence[Path], reference: Path | None = None) -> Analysis:
    """``suspopt analyse models A.yaml B.yaml ... [--reference A.yaml]``: the configs
    compared (:func:`compare_models`); nothing written."""
    comparison = compare_models(sources, reference)
    models, ref = comparison.models, comparison.models[comparison.reference]
    title = f"models: {', '.join(m.label for m in models)} (reference {ref.label})"
    return analysis(
        "models",
        title,
        comparison,
        ref.config,
        [m.source for m in models],
        lambda path, command: write_models(path, comparison, command),
        lambda path: plot_models(comparison, path, title),
        lambda: _table(comparison, title),
    )


def _table(comparison: ModelComparison, title: str) -> Report:
    """The table of ``comparison``: each metric of each model and its change."""
    models, ref = comparison.models, comparison.models[comparison.reference]
    columns = ["metric", "unit"] + [f"{m.label} (Δ %)" for m in models]
    rows, shown_na = [], False
    for name in comparison.metric_names:
        row = [name, comparison.metric_units[name]]
        known = not np.isnan(_reference_value(models[comparison.reference], name))
        for i, value in enumerate(comparison.value[name]):
            d = comparison.difference[name][i]
            if np.isnan(value):
                after = ""
            elif i == comparison.reference:
                after = " (ref)"
            elif np.isnan(d) and not known:  # (the reference has no such metric)
                after = ""
            else:  # (n/a: a reference of 0, or a change beyond the floating-point range)
                after = f" ({percent(d, suffix='')})"
                shown_na |= bool(np.isnan(d))
            row.append(_cell(value) + after)
        rows.append(row)
    notes = [
        f"Δ = (X - X_ref)/X_ref · 100 % against {ref.label} (Sec 3.2.1; Tables 3.3-3.21 "
        f"print the opposite sign); a quarter car's only corner stands for every corner",
        "times are absolute (t_p, t_s); settling band 2 %; natural frequencies undamped; SI units",
    ]
    if shown_na:
        notes.append(NOT_COMPUTED_NOTE)
    diverged = [m.label for m in models if m.diverged]
    if diverged:
        notes.append(f"diverged (NaN samples; try a smaller simulation.dt): {', '.join(diverged)}")
    return Report(title=title, columns=columns, rows=rows, notes=notes)


KINDS["models"] = Kind(run, many=True, options=("reference",))
