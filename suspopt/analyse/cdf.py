"""``suspopt analyse cdf-sensitivity CONFIG``: the CDF strategy's threshold sweep (Figs. 4.7, 4.10).

The config's semi-active dampers run with an adaptive threshold (``control.threshold.mode:
adaptive``). The sweep asks for C_max shares of 20 to 70 % in steps of 5 % and compares each
with the base law (threshold 0), in ONE batched simulation: the share is the design parameter
``control.threshold.c_max_share``, and design 0 runs the base law because its
``control.threshold.learn_time`` lies beyond the end of the run, so its threshold never leaves 0.

Metrics (Sec 2.4, as Tables 4.2-4.3): SW the damper state changes (Sec 2.4.6, summed over the
semi-active corners), RC the ISO 2631-1 Wk-weighted r.m.s. of the body heave acceleration
(Eq 2.78), ST and TD the r.m.s. suspension travel and tyre deflection (mean over corners), DE
the mean power the dampers dissipate (Eq 2.92, summed over corners). Each is reported as the
thesis's reduction ``(X_base - X_CDF) / X_base * 100 %`` (Sec 4.3): positive means smaller
with the CDF strategy. The share achieved is counted after the first fit (``t >= learn_time``).

The file's layout: :data:`suspopt.formats.CDF_SENSITIVITY`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import plots
from ..config import Config, load_config
from ..errors import require_like
from ..formats import CDF_SENSITIVITY
from ..io import atomic_h5, put
from ..metrics import damper_switches, mean_dissipated_power, rms, weighted_rms
from ..simulation import simulate
from .cells import NOT_COMPUTED, NOT_COMPUTED_NOTE, percent
from .registry import KINDS, Analysis, Kind, Report, analysis, relative_change

__all__ = [
    "SHARES",
    "METRIC_UNITS",
    "CdfSensitivity",
    "c_max_share",
    "semi_active_metrics",
    "run",
]

#: C_max shares of the sweep (the thesis's 20-70 %, Sec 4.3 item 4).
SHARES = np.round(np.arange(0.20, 0.7001, 0.05), 2)
#: Units of :func:`semi_active_metrics`.
METRIC_UNITS = {"SW": "1", "RC": "m/s^2", "ST": "m", "TD": "m", "DE": "W"}


def _a_result(result) -> None:
    """TypeError unless ``result`` holds what a simulation's ``suspopt.Result`` does (a run
    read back from its file, as ``examples/ch4_tables.py`` makes, is one too)."""
    require_like(result, "Result", ("config", "signals", "time", "model"), "result",
                 "from suspopt.simulate(cfg)")  # fmt: skip


def c_max_share(result, share_after: float = 0.0) -> np.ndarray:
    """The mean damper state (the C_max share of the on-off laws) over the samples at
    ``t >= share_after``, averaged over the semi-active corners, (P,)."""
    _a_result(result)
    cfg, sig = result.config, result.signals
    active = [
        c for c in result.model.corners if cfg.vehicle.corners[c].damper.kind == "semi_active"
    ]
    duration = cfg.simulation.duration
    if not active or not 0.0 <= share_after < duration:  # (NaN and an empty mean before)
        raise ValueError(
            "c_max_share: the result has no semi-active damper"
            if not active
            else f"share_after must be a time [s] in [0, {duration:g}) (the run's); "
            f"got {share_after}"
        )
    late = result.time >= share_after - 0.5 * cfg.simulation.dt
    return np.mean([np.mean(sig[f"damper_state.{c}"][:, late], axis=-1) for c in active], axis=0)


def semi_active_metrics(result, share_after: float = 0.0) -> dict[str, np.ndarray]:
    """Ch. 4 metrics of a result with semi-active dampers, (P,) each (units METRIC_UNITS),
    plus ``share``: the mean damper state (the C_max share of the on-off laws) over the samples
    at ``t >= share_after``, averaged over the semi-active corners.

    SW counts state changes between output samples, so ``simulation.output_dt`` must not exceed
    ``control.sample_time`` (every sample seen)."""
    _a_result(result)
    cfg, sig, t = result.config, result.signals, result.time
    corners = result.model.corners
    active = [c for c in corners if cfg.vehicle.corners[c].damper.kind == "semi_active"]
    return {
        "SW": np.sum([damper_switches(sig[f"damper_state.{c}"]) for c in active], axis=0),
        "RC": weighted_rms(sig["body.heave_acc"], cfg.simulation.output_rate, "Wk"),
        "ST": np.mean([rms(sig[f"travel.{c}"]) for c in corners], axis=0),
        "TD": np.mean([rms(sig[f"tyre_deflection.{c}"]) for c in corners], axis=0),
        "DE": np.sum(
            [
                mean_dissipated_power(sig[f"damper_force.{c}"], sig[f"travel_vel.{c}"], t)
                for c in corners
            ],
            axis=0,
        ),
        "share": c_max_share(result, share_after),
    }


def _check(cfg) -> None:
    spec = cfg.control.threshold if cfg.control is not None else None
    if spec is None or spec.mode != "adaptive":
        raise cfg.error(
            ("control", "threshold"),
            "cdf-sensitivity needs an adaptive threshold "
            "(control.threshold.mode: adaptive, with c_max_share)",
        )
    if not any(cfg.vehicle.corners[c].damper.kind == "semi_active" for c in cfg.vehicle.corners):
        raise cfg.error(("vehicle", "corners"), "cdf-sensitivity needs a semi-active damper")
    sim = cfg.simulation
    if sim.dt * sim.output_every > cfg.control.sample_time * (1 + 1e-9):
        raise cfg.error(
            ("simulation", "output_dt"),
            "must not exceed control.sample_time, or the switch count SW misses switches",
        )
    if spec.learn_time >= sim.duration:
        raise cfg.error(
            ("control", "threshold", "learn_time"),
            "must be shorter than simulation.duration: the threshold is never fitted",
        )


@dataclass
class CdfSensitivity:
    """The sweep of :func:`run`: the config's adaptive threshold at each C_max share of
    :data:`SHARES` against the base law. ``base`` (metric -> value, with ``share``), ``cdf``
    (metric -> one value per share, with ``share``: the share achieved), ``reduction``
    (metric -> [%] per share), units :data:`METRIC_UNITS`; ``threshold (shares, corners)``
    each semi-active corner's final threshold in ``unit``, ``active`` those corners,
    ``laws`` their laws."""

    source: Path
    config: Config
    base: dict[str, float]
    cdf: dict[str, np.ndarray]
    reduction: dict[str, np.ndarray]
    threshold: np.ndarray
    unit: str
    active: list[str]
    laws: list[str]

    @property
    def title(self) -> str:
        spec = self.config.control.threshold  # type: ignore[union-attr]
        assert spec is not None  # (run checks it)
        return (
            f"CDF sensitivity: {' / '.join(self.laws)} on {self.source.name} "
            f"({spec.distribution} fit, T_learn {spec.learn_time:g} s)"
        )


def _write(output: Path, d: CdfSensitivity, command: str | None) -> Path:
    """``/cdf_sensitivity`` (:data:`suspopt.formats.CDF_SENSITIVITY`): the shares asked for
    and achieved, the final thresholds (in the laws' condition unit) and the metrics of the
    base law, with the CDF threshold and their reduction [%]."""
    cfg = d.config
    with atomic_h5(output, cfg, command) as h5:
        grp = h5.create_group("cdf_sensitivity")
        grp.attrs["laws"] = ",".join(d.laws)
        grp.attrs["distribution"] = cfg.control.threshold.distribution  # type: ignore[union-attr]
        grp.attrs["corners"] = ",".join(d.active)
        put(CDF_SENSITIVITY, grp, "c_max_share", SHARES)
        put(CDF_SENSITIVITY, grp, "achieved_share", d.cdf["share"])
        put(CDF_SENSITIVITY, grp, "base_share", d.base["share"])
        put(CDF_SENSITIVITY, grp, "final_threshold", d.threshold, d.unit,
            coords={"corner": d.active})  # fmt: skip
        for key, values in (("base", d.base), ("cdf", d.cdf), ("reduction", d.reduction)):
            group = grp.create_group(key)
            for name, m_unit in METRIC_UNITS.items():
                unit = None if key == "reduction" else m_unit
                put(CDF_SENSITIVITY, group, name, values[name], unit)
    return output


def run(source: Path) -> Analysis:
    """Sweep the C_max share 20-70 % against the base law (module docstring); nothing
    written."""
    cfg = load_config(source)
    _check(cfg)
    assert cfg.control is not None and cfg.control.threshold is not None  # (_check)
    spec = cfg.control.threshold
    base_learn = 2.0 * cfg.simulation.duration + spec.learn_time
    path = "control.threshold."
    learn = np.concatenate((np.array([base_learn]), np.full(SHARES.size, spec.learn_time)))
    shares = np.concatenate(([SHARES[0]], SHARES))
    result = simulate(cfg, params={path + "c_max_share": shares, path + "learn_time": learn})
    values = semi_active_metrics(result, share_after=spec.learn_time)
    base = {k: v[0] for k, v in values.items()}
    corners = result.model.corners
    active = [c for c in corners if cfg.vehicle.corners[c].damper.kind == "semi_active"]
    d = CdfSensitivity(
        source=Path(source),
        config=cfg,
        base=base,
        cdf={k: v[1:] for k, v in values.items()},
        reduction={k: 0.0 - relative_change(values[k][1:], base[k]) for k in METRIC_UNITS},
        threshold=np.stack(
            [result.signals[f"control_threshold.{c}"][1:, -1] for c in active], axis=1
        ),
        unit=result.signal_unit(f"control_threshold.{active[0]}"),
        active=active,
        laws=sorted({getattr(cfg.vehicle.corners[c].damper, "law", "") for c in active}),
    )
    return analysis(
        "cdf-sensitivity",
        d.title,
        d,
        cfg,
        [Path(source)],
        lambda out, command: _write(out, d, command),
        lambda out: _plot(d, out),
        lambda: _table(d),
    )


def _plot(d: CdfSensitivity, path: Path) -> Path:
    """The reduction of SW, and of RC, ST, TD and DE, against the share asked for."""
    return plots.sensitivity(
        path,
        d.title,
        100 * SHARES,
        "C_max share requested (1 - N) [%]",
        [{"SW": d.reduction["SW"]}, {k: d.reduction[k] for k in ("RC", "ST", "TD", "DE")}],
        "reduction vs base law [%]",
        marker=100 * d.base["share"],
        marker_label="base law's share",
    )


def _table(d: CdfSensitivity) -> Report:
    """Each share asked for: achieved, the final thresholds and the reductions."""
    base, laws = d.base, d.laws
    rows = [
        [
            f"{100 * s:.0f}",
            f"{100 * a:.1f}",
            " ".join(f"{x:.3g}" for x in thr),
            *(percent(d.reduction[k][i], suffix="") for k in METRIC_UNITS),
        ]
        for i, (s, a, thr) in enumerate(zip(SHARES, d.cdf["share"], d.threshold))
    ]
    notes = [
        f"base law ({' / '.join(laws)}): C_max share {100 * base['share']:.1f} %, "
        f"SW {base['SW']:.0f}, RC {base['RC']:.4g} m/s^2, ST {1e3 * base['ST']:.4g} mm, "
        f"TD {1e3 * base['TD']:.4g} mm, DE {base['DE']:.4g} W",
        "reduction = (X_base - X_CDF) / X_base * 100 % (thesis Sec 4.3): positive = smaller "
        "with the CDF threshold; shares counted after the first fit",
    ]
    if any(NOT_COMPUTED in row for row in rows):
        notes.append(NOT_COMPUTED_NOTE)
    return Report(
        title=d.title,
        columns=[
            "C_max share [%]",
            "achieved [%]",
            f"final T [{d.unit}]",
            *(f"{k} [%]" for k in METRIC_UNITS),
        ],
        rows=rows,
        notes=notes,
    )


KINDS["cdf-sensitivity"] = Kind(run)
