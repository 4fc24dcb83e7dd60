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

HDF5 (``output``): ``/cdf_sensitivity/c_max_share (S,)`` (the dimension scale of the sweep),
``achieved_share``, ``base_share``, ``final_threshold (c_max_share, corner)`` (scale
``corner``: the semi-active corners), ``base/<M>`` (one value), ``cdf/<M>`` and
``reduction/<M>`` [%] over ``c_max_share``; every dataset with ``units``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import plots
from ..config import load_config
from ..errors import require
from ..io import atomic_h5, write_dataset
from ..metrics import damper_switches, mean_dissipated_power, weighted_rms
from ..result import Result
from ..simulation import simulate
from .cells import NOT_COMPUTED, NOT_COMPUTED_NOTE, percent
from .registry import KINDS, Kind, Report, relative_change

__all__ = ["SHARES", "METRIC_UNITS", "c_max_share", "semi_active_metrics", "run"]

#: C_max shares of the sweep (the thesis's 20-70 %, Sec 4.3 item 4).
SHARES = np.round(np.arange(0.20, 0.7001, 0.05), 2)
#: Units of :func:`semi_active_metrics`.
METRIC_UNITS = {"SW": "1", "RC": "m/s^2", "ST": "m", "TD": "m", "DE": "W"}


def c_max_share(result, share_after: float = 0.0) -> np.ndarray:
    """The mean damper state (the C_max share of the on-off laws) over the samples at
    ``t >= share_after``, averaged over the semi-active corners, (P,)."""
    require(result, Result, "result", "from suspopt.simulate(cfg)")
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
    require(result, Result, "result", "from suspopt.simulate(cfg)")
    cfg, sig, t = result.config, result.signals, result.time
    corners = result.model.corners
    active = [c for c in corners if cfg.vehicle.corners[c].damper.kind == "semi_active"]
    return {
        "SW": np.sum([damper_switches(sig[f"damper_state.{c}"]) for c in active], axis=0),
        "RC": weighted_rms(sig["body.heave_acc"], cfg.simulation.output_rate, "Wk"),
        "ST": np.mean(
            [np.sqrt(np.mean(sig[f"travel.{c}"] ** 2, axis=-1)) for c in corners], axis=0
        ),
        "TD": np.mean(
            [np.sqrt(np.mean(sig[f"tyre_deflection.{c}"] ** 2, axis=-1)) for c in corners], axis=0
        ),
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


def _write(
    output: Path, cfg, active: list[str], laws: list[str], tables: dict, threshold, unit: str
) -> None:
    """``/cdf_sensitivity``: the shares asked for and achieved, the final thresholds (in the
    laws' condition unit) and the metrics of the base law, with the CDF threshold and their
    reduction [%] (layout: docs/guide/analyses.md)."""
    with atomic_h5(output, cfg) as h5:
        grp = h5.create_group("cdf_sensitivity")
        grp.attrs["laws"] = ",".join(laws)
        grp.attrs["distribution"] = cfg.control.threshold.distribution
        grp.attrs["corners"] = ",".join(active)
        share = ("c_max_share",)
        write_dataset(grp, "c_max_share", SHARES, "1", dims=share)
        write_dataset(grp, "achieved_share", tables["cdf"]["share"], "1", dims=share)
        write_dataset(grp, "base_share", tables["base"]["share"], "1")
        dims = ("c_max_share", "corner")
        write_dataset(grp, "final_threshold", threshold, unit, dims=dims, coords={"corner": active})
        for key, values in tables.items():
            group = grp.create_group(key)
            for name, m_unit in METRIC_UNITS.items():
                units = "%" if key == "reduction" else m_unit
                write_dataset(group, name, values[name], units, dims=() if key == "base" else share)


def run(source: Path, output: Path | None = None, plot: Path | None = None) -> Report:
    """Sweep the C_max share 20-70 % against the base law (module docstring)."""
    if plot is not None:
        plots.check_path(plot)
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
    reduction = {k: 0.0 - relative_change(values[k][1:], base[k]) for k in METRIC_UNITS}
    corners = result.model.corners
    active = [c for c in corners if cfg.vehicle.corners[c].damper.kind == "semi_active"]
    laws = sorted({getattr(cfg.vehicle.corners[c].damper, "law", "") for c in active})
    threshold = np.stack([result.signals[f"control_threshold.{c}"][1:, -1] for c in active], axis=1)
    unit = result.signal_unit(f"control_threshold.{active[0]}")
    title = (
        f"CDF sensitivity: {' / '.join(laws)} on {source.name} "
        f"({spec.distribution} fit, T_learn {spec.learn_time:g} s)"
    )

    if output is not None:
        tables = {
            "base": base,
            "cdf": {k: v[1:] for k, v in values.items()},
            "reduction": reduction,
        }
        _write(output, cfg, active, laws, tables, threshold, unit)
    if plot is not None:
        plots.sensitivity(
            plot,
            title,
            100 * SHARES,
            "C_max share requested (1 - N) [%]",
            [{"SW": reduction["SW"]}, {k: reduction[k] for k in ("RC", "ST", "TD", "DE")}],
            "reduction vs base law [%]",
            marker=100 * base["share"],
            marker_label="base law's share",
        )

    rows = [
        [
            f"{100 * s:.0f}",
            f"{100 * a:.1f}",
            " ".join(f"{x:.3g}" for x in thr),
            *(percent(reduction[k][i], suffix="") for k in METRIC_UNITS),
        ]
        for i, (s, a, thr) in enumerate(zip(SHARES, values["share"][1:], threshold))
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
        title=title,
        columns=[
            "C_max share [%]",
            "achieved [%]",
            f"final T [{unit}]",
            *(f"{k} [%]" for k in METRIC_UNITS),
        ],
        rows=rows,
        notes=notes,
    )


KINDS["cdf-sensitivity"] = Kind(run)
