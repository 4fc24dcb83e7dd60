"""``suspopt analyse transmissibility CONFIG``: seat transmissibility and STHT (Eq 2.86).

For a config with a ``seat:`` section, the acceleration transmissibility ``|z̈_i / z̈_s|`` from
the floor under the seat (``z_s``) to every seat DOF ``i`` (``seat``, NSS4's ``seat.inner``, the
passenger's parts), estimated twice:

- ``linear``: the seat linearised about static equilibrium (:func:`suspopt.seat.linearise`,
  from the same force functions the simulator integrates), on a log frequency grid;
- ``simulated``: the H1 estimate (:func:`suspopt.metrics.spectral.transmissibility`) from a
  simulation of the config - its vehicle, road and coupling - with the coherence, which shows
  where the estimate holds (random excitation is needed: on a bump the spectra are mostly
  noise).

STHT, the seat-to-head transmissibility, is the ``head`` entry: Eq 2.86 with i = head and the
floor's acceleration as input, as in Fig. 8.26 (``T = z̈_head / z̈_s``). The seat
transmissibility of Fig. 2.18b is the ``seat`` entry.

HDF5 layout (every dataset has a ``units`` attribute; root attributes as every suspopt file):

- ``/linear/frequency (F,)`` [Hz], ``/linear/<dof> (P, F)`` [-];
- ``/simulated/frequency (F2,)`` [Hz], ``/simulated/<dof> (P, F2)`` [-],
  ``/simulated/coherence/<dof> (P, F2)`` [-];
- ``/statics/static_deflection (P,)`` [m] (X_ST);
- ``/modal/frequency (P, m)`` [Hz]: undamped, floor held still, attr ``dof_names``;
- ``/constraints/<name> (P,)`` (:func:`suspopt.seat.seat_constraints`, ``g <= 0`` feasible).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import plots
from ..config import Config, ConfigError, load_config
from ..io import atomic_h5, write_dataset
from ..metrics import transmissibility, coherence, weighted_rms
from ..seat import (CONSTRAINT_UNITS, base_transmissibility, build_seat, linearise,
                    natural_frequencies, seat_constraints)
from ..simulate import simulate
from . import KINDS, Kind, Report

__all__ = ["SeatTransmissibility", "seat_transmissibility", "write_transmissibility",
           "plot_transmissibility", "run", "LINEAR_FREQUENCIES", "SEGMENT"]

#: Frequency grid of the linear spectra [Hz].
LINEAR_FREQUENCIES = np.geomspace(0.1, 50.0, 500)
#: Band in which the report looks for peaks [Hz] (ride comfort's 0.5-20 Hz and more).
_PEAK_BAND = (0.5, 20.0)
#: Coherence below which a simulated estimate is not used for the reported peak.
_MIN_COHERENCE = 0.8
#: Welch segment of the simulated estimate [s]: 0.125 Hz resolution, fine enough for a seat
#: resonance of ~0.5 Hz bandwidth; a 30 s run still averages 6 segments.
SEGMENT = 8.0


@dataclass
class SeatTransmissibility:
    """Transmissibility spectra of one config's seat, ``(P, F, m)`` magnitudes [-] over
    ``dof_names``; ``static_deflection (P,)`` [m]; ``natural_frequency (P, m)`` [Hz];
    ``constraints`` by name, (P,) each; ``weighted_rms`` the ISO 2631-1 Wk r.m.s. of the
    simulated ``seat.acc`` and (with a passenger) ``head.acc``, (P,) each [m/s^2]."""

    kind: str
    dof_names: tuple[str, ...]
    linear_frequency: np.ndarray
    linear: np.ndarray
    simulated_frequency: np.ndarray
    simulated: np.ndarray
    coherence: np.ndarray
    static_deflection: np.ndarray
    natural_frequency: np.ndarray
    constraints: dict[str, np.ndarray]
    weighted_rms: dict[str, np.ndarray]


def seat_transmissibility(cfg: Config, segment: float = SEGMENT) -> SeatTransmissibility:
    """Linear and simulated transmissibility of ``cfg``'s seat (see the module docstring).

    ``segment`` is the Welch segment length [s] of the simulated estimate (at most the run).
    """
    if cfg.seat is None:
        raise ConfigError(f"{cfg.source or '<config>'}: analyse transmissibility needs a seat: "
                          f"section")
    seat = build_seat(cfg)
    lin = linearise(seat)
    linear = np.abs(base_transmissibility(lin, LINEAR_FREQUENCIES))
    result = simulate(cfg)
    fs = cfg.simulation.output_rate
    nperseg = int(round(segment * fs))
    floor = result.signals["seat.base_acc"]
    outputs = np.stack([result.signals[_acc_signal(name)] for name in seat.dof_names], axis=1)
    f_sim, tr = transmissibility(floor[:, None, :], outputs, fs, nperseg)
    _, coh = coherence(floor[:, None, :], outputs, fs, nperseg)
    rms = {name: weighted_rms(result.signals[name], fs, "Wk")
           for name in ("seat.acc", "head.acc") if name in result.signals}
    return SeatTransmissibility(
        kind=seat.kind, dof_names=seat.dof_names, linear_frequency=LINEAR_FREQUENCIES,
        linear=linear, simulated_frequency=f_sim, simulated=np.swapaxes(tr, 1, 2),
        coherence=np.swapaxes(coh, 1, 2), static_deflection=seat.static_deflection,
        natural_frequency=natural_frequencies(lin), constraints=seat_constraints(cfg),
        weighted_rms=rms)


def _acc_signal(dof: str) -> str:
    """Acceleration signal of a seat DOF (``seat`` -> ``seat.acc``, ``seat.inner`` ->
    ``seat.inner_acc``, ``head`` -> ``head.acc``)."""
    return "seat.inner_acc" if dof == "seat.inner" else f"{dof}.acc"


def write_transmissibility(path: str | Path, data: SeatTransmissibility, cfg: Config,
                           command: str | None = None) -> Path:
    """Write ``data`` with the layout of the module docstring (atomically)."""
    with atomic_h5(path, cfg, command) as h5:
        h5.attrs["seat_kind"] = data.kind
        lin, sim = h5.create_group("linear"), h5.create_group("simulated")
        write_dataset(lin, "frequency", data.linear_frequency, "Hz")
        write_dataset(sim, "frequency", data.simulated_frequency, "Hz")
        coh = sim.create_group("coherence")
        for j, name in enumerate(data.dof_names):
            write_dataset(lin, name, data.linear[..., j], "-")
            write_dataset(sim, name, data.simulated[..., j], "-")
            write_dataset(coh, name, data.coherence[..., j], "-")
        write_dataset(h5.create_group("statics"), "static_deflection", data.static_deflection, "m")
        write_dataset(h5.create_group("modal"), "frequency", data.natural_frequency, "Hz",
                      dof_names=np.array(data.dof_names, dtype="S"))
        con = h5.create_group("constraints")
        for name, values in data.constraints.items():
            write_dataset(con, name, values, CONSTRAINT_UNITS[name])
    return Path(path)


def plot_transmissibility(data: SeatTransmissibility, path: str | Path,
                          design: int = 0) -> Path:
    """Figure of the seat transmissibility and (with a passenger) STHT of one design: linear
    model as lines, simulation (H1) as dots where the coherence is at least 0.8."""
    f_sim = data.simulated_frequency
    band = (f_sim >= data.linear_frequency[0]) & (f_sim <= 30.0)
    lines, points = [], []
    for name, label in (("seat", "seat  z̈_seat/z̈_s"), ("head", "STHT  z̈_head/z̈_s")):
        if name not in data.dof_names:
            continue
        j = data.dof_names.index(name)
        lines.append((f"{label} (linearised)", data.linear_frequency,
                      data.linear[design, :, j]))
        good = band & (data.coherence[design, :, j] >= _MIN_COHERENCE)
        points.append((f"{label} (simulated, H1)", f_sim[good], data.simulated[design, good, j]))
    title = (f"{data.kind.upper()} seat, X_ST = {1e3 * data.static_deflection[design]:.1f} mm "
             f"(Eq 2.86)")
    return plots.transmissibilities(path, title, lines, points,
                                    f_range=(data.linear_frequency[0], 30.0))


def _peak(f: np.ndarray, values: np.ndarray, valid: np.ndarray | None = None):
    """Largest value in the peak band and its frequency, (value, f) for one design's curve."""
    band = (f >= _PEAK_BAND[0]) & (f <= _PEAK_BAND[1])
    if valid is not None:
        band &= valid
    if not band.any():
        return np.nan, np.nan
    i = np.flatnonzero(band)[np.argmax(values[band])]
    return values[i], f[i]


def run(source: Path, output: Path | None = None, plot: Path | None = None) -> Report:
    """The ``transmissibility`` analysis of ``source`` (a YAML config with a seat)."""
    if plot is not None:
        plots.check_path(plot)
    cfg = load_config(source)
    data = seat_transmissibility(cfg)
    if output is not None:
        write_transmissibility(output, data, cfg)
    if plot is not None:
        plot_transmissibility(data, plot)
    rows = [["static deflection X_ST", "mm", f"{1e3 * data.static_deflection[0]:.2f}"],
            ["natural frequencies", "Hz",
             ", ".join(f"{f:.2f}" for f in data.natural_frequency[0])]]
    for name, label in (("seat", "seat TR"), ("head", "STHT")):
        if name not in data.dof_names:
            continue
        j = data.dof_names.index(name)
        tr, f = _peak(data.linear_frequency, data.linear[0, :, j])
        rows.append([f"{label} peak (linear)", "- @ Hz", f"{tr:.3f} @ {f:.2f}"])
        tr, f = _peak(data.simulated_frequency, data.simulated[0, :, j],
                      data.coherence[0, :, j] >= _MIN_COHERENCE)
        rows.append([f"{label} peak (simulated)", "- @ Hz", f"{tr:.3f} @ {f:.2f}"])
    for name, values in data.weighted_rms.items():
        rows.append([f"Wk r.m.s. {name}", "m/s^2", f"{values[0]:.4f}"])
    for name, values in data.constraints.items():
        rows.append([f"g {name}", CONSTRAINT_UNITS[name], f"{values[0]:.4g}"])
    notes = ["TR = |z̈_i / z̈_s| from the floor z_s (Eq 2.86); peaks in 0.5-20 Hz, simulated "
             f"where the coherence is >= {_MIN_COHERENCE}; g: constraint values, <= 0 feasible"]
    if "head" not in data.dof_names:
        notes.append("no passenger: STHT needs seat.passenger (e.g. passenger: {})")
    return Report(title=f"transmissibility - {data.kind.upper()} seat ({Path(source).name})",
                  columns=["quantity", "unit", "value"], rows=rows, notes=notes)


KINDS["transmissibility"] = Kind(run)
