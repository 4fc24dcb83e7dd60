"""``suspopt analyse transmissibility CONFIG|PARETO.h5``: seat transmissibility, STHT (Eq 2.86).

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

For a Pareto file (``suspopt optimise`` output, Sec 8.4.4, Fig. 8.26), the same for the
Pareto-theory picks of its front (:func:`suspopt.choosing.kepsilon.pareto_picks`, Fig. 8.21): the edges
``best_<objective>`` (the thesis's Edge 1 and Edge 2: in Ch. 8 ``best_X_ST`` and
``best_RC_se``) and the ``knee`` (its Mid), simulated in one batch; with ``pick``
(``--pick``), the designs it names, of any result file (:func:`suspopt.choosing.picks.read_front`:
``analyse transmissibility choice.h5 --pick chosen``). The thesis adds the
passenger and keeps only the seat's 13.6 kg as the seat mass; ``with_`` (``--with FILE.yaml``)
does that: the ``seat.mass`` and ``seat.passenger`` of that file (e.g.
``configs/ch8/<seat>_class_a_passenger.yaml``) replace the stored ones. NSS1-NSS3 keep the
designs' ``X_ST`` (their ``K_v = m g / X_ST`` follows the load), PS and NSS4 keep their
stiffnesses, as in Sec 8.4.3.

The file's layout: :data:`suspopt.formats.TRANSMISSIBILITY` (``/modal/frequency``:
undamped, the floor held still; ``/constraints/<name>``:
:func:`suspopt.seat.seat_constraints`, ``g <= 0`` feasible; ``/weighted_rms/<signal>``: the
ISO 2631-1 Wk r.m.s. of ``seat.acc`` and ``head.acc`` in the simulation).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import plots
from ..choosing.picks import read_front
from ..choosing.selection import ParetoSet
from ..config import Config, ConfigError, load_config
from ..config.loader import require_config
from ..design_ids import front_ids
from ..files import is_hdf5
from ..formats import TRANSMISSIBILITY
from ..io import atomic_h5, put, write_attrs
from ..metrics import coherence, transmissibility, weighted_rms
from ..optimisation import Problem
from ..params import ParamView
from ..seat import (
    CONSTRAINT_UNITS,
    base_transmissibility,
    build_seat,
    linearise,
    natural_frequencies,
    seat_constraints,
)
from ..simulation import simulate
from .pseudo import config_with, read_sections
from .registry import KINDS, Analysis, Kind, Report, analysis

__all__ = [
    "SeatTransmissibility",
    "FrontDesigns",
    "seat_transmissibility",
    "front_designs",
    "with_passenger",
    "write_transmissibility",
    "plot_transmissibility",
    "plot_front_transmissibility",
    "run",
    "LINEAR_FREQUENCIES",
    "SEGMENT",
]

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


@dataclass
class FrontDesigns:
    """Designs picked from a Pareto front: ``rows (P,)`` in the file's ``/pareto``, their
    ``X (P, n)`` physical values and ``F (P, m)`` objectives (names, SI units), and the
    ``picks`` each design is (e.g. ``["best_X_ST"]``, ``["best_RC_se", "knee"]``), and
    ``ids`` their design ids (:mod:`suspopt.design_ids`)."""

    rows: np.ndarray
    picks: list[list[str]]
    X: np.ndarray
    F: np.ndarray
    var_names: list[str]
    var_units: list[str]
    obj_names: list[str]
    obj_units: list[str]
    paths: list[str]
    ids: list[str] = field(default_factory=list)

    def params(self) -> dict[str, np.ndarray]:
        """``simulate``'s ``params`` of the picked designs (dotted path -> (P,))."""
        return {path: self.X[:, j] for j, path in enumerate(self.paths)}


def seat_transmissibility(
    cfg: Config, segment: float = SEGMENT, params: Mapping[str, np.ndarray] | None = None
) -> SeatTransmissibility:
    """Linear and simulated transmissibility of ``cfg``'s seat (see the module docstring),
    for one design or, with ``params`` (dotted path -> (P,)), for P designs in one batch.

    ``segment`` is the Welch segment length [s] of the simulated estimate (at most the run;
    at least 8 samples, else a ValueError: scipy's "nperseg=0" before).
    """
    if require_config(cfg).seat is None:
        raise ConfigError(
            f"{cfg.source or '<config>'}: analyse transmissibility needs a seat: section"
        )
    fs = cfg.simulation.output_rate
    if not segment * fs >= 8 or not np.isfinite(segment):
        raise ValueError(
            f"segment must be a finite time of at least 8 samples ({8 / fs:g} s) [s]; got {segment}"
        )
    seat = build_seat(cfg, ParamView(cfg, params))
    lin = linearise(seat)
    linear = np.abs(base_transmissibility(lin, LINEAR_FREQUENCIES))
    result = simulate(cfg, params)
    nperseg = int(round(segment * fs))
    floor = result.signals["seat.base_acc"]
    outputs = np.stack([result.signals[_acc_signal(name)] for name in seat.dof_names], axis=1)
    f_sim, tr = transmissibility(floor[:, None, :], outputs, fs, nperseg)
    _, coh = coherence(floor[:, None, :], outputs, fs, nperseg)
    rms = {
        name: weighted_rms(result.signals[name], fs, "Wk")
        for name in ("seat.acc", "head.acc")
        if name in result.signals
    }
    return SeatTransmissibility(
        kind=seat.kind,
        dof_names=seat.dof_names,
        linear_frequency=LINEAR_FREQUENCIES,
        linear=linear,
        simulated_frequency=f_sim,
        simulated=np.swapaxes(tr, 1, 2),
        coherence=np.swapaxes(coh, 1, 2),
        static_deflection=seat.static_deflection,
        natural_frequency=natural_frequencies(lin),
        constraints=seat_constraints(cfg, params),
        weighted_rms=rms,
    )


def front_designs(pareto: ParetoSet) -> FrontDesigns:
    """The edges and the knee of ``pareto``'s front (:func:`suspopt.choosing.kepsilon.pareto_picks`),
    each design once, in the order of the picks; of designs picked from a file
    (:func:`suspopt.choosing.picks.read_front`), every one, by the names it was picked by (``design
    ID`` for an id)."""
    cfg = pareto.config()
    problem = Problem.from_config(cfg)
    picks, ids = pareto.marks_by_row(), front_ids(pareto)
    if pareto.source_rows is not None:
        picks = {k: picks.get(k, [f"design {ids[k]}"]) for k in range(len(pareto.source_rows))}
    rows = np.array(list(picks))
    path_of = {v.label: v.path for v in cfg.design_variables}
    if sorted(path_of) != sorted(pareto.var_names):
        raise ConfigError(
            f"{pareto.path}: /pareto/X holds {', '.join(pareto.var_names)}; its "
            f"config varies {', '.join(path_of)}: the designs do not fit its "
            f"design_variables"
        )
    return FrontDesigns(
        rows=rows,
        picks=list(picks.values()),
        X=pareto.X[rows],
        F=pareto.F[rows],
        var_names=pareto.var_names,
        var_units=pareto.var_units,
        obj_names=pareto.obj_names,
        obj_units=problem.obj_units,
        paths=[path_of[name] for name in pareto.var_names],
        ids=[ids[k] for k in rows],
    )


def with_passenger(pareto: ParetoSet, source: str | Path) -> Config:
    """The stored config with the ``seat.mass`` and ``seat.passenger`` of ``source`` (Sec
    8.4.4: the Table 2.3 passenger on the 13.6 kg seat in place of the lumped 95 kg)."""
    source = Path(source)
    seat = read_sections(source, "--with").get("seat")
    if not isinstance(seat, dict) or "passenger" not in seat:
        raise ConfigError(f"--with {source}: the file has no seat.passenger")

    def seat_passenger(data):
        if not isinstance(data.get("seat"), dict):
            raise ConfigError(
                f"{pareto.path}: analyse transmissibility needs a seat, and the "
                f"optimised config has no seat: section"
            )
        data["seat"]["passenger"] = seat["passenger"]
        if "mass" in seat:
            data["seat"]["mass"] = seat["mass"]

    return config_with(pareto, seat_passenger, f"the passenger of {source}")


def _acc_signal(dof: str) -> str:
    """Acceleration signal of a seat DOF (``seat`` -> ``seat.acc``, ``seat.inner`` ->
    ``seat.inner_acc``, ``head`` -> ``head.acc``)."""
    return "seat.inner_acc" if dof == "seat.inner" else f"{dof}.acc"


def write_transmissibility(
    path: str | Path,
    data: SeatTransmissibility,
    cfg: Config,
    command: str | None = None,
    designs: FrontDesigns | None = None,
) -> Path:
    """Write ``data`` with the layout of the module docstring (atomically); ``designs`` when
    they were picked from a front."""
    with atomic_h5(path, cfg, command) as h5:
        h5.attrs["seat_kind"] = data.kind
        T = TRANSMISSIBILITY
        put(T, h5, "design", np.arange(len(data.static_deflection)))
        lin, sim = h5.create_group("linear"), h5.create_group("simulated")
        put(T, lin, "frequency", data.linear_frequency)
        put(T, sim, "frequency", data.simulated_frequency)
        coh = sim.create_group("coherence")
        for j, name in enumerate(data.dof_names):
            put(T, lin, name, data.linear[..., j])
            put(T, sim, name, data.simulated[..., j])
            put(T, coh, name, data.coherence[..., j])
        put(T, h5.create_group("statics"), "static_deflection", data.static_deflection)
        put(T, h5.create_group("modal"), "frequency", data.natural_frequency,
            dof_names=list(data.dof_names))  # fmt: skip
        con = h5.create_group("constraints")
        for name, values in data.constraints.items():
            put(T, con, name, values, CONSTRAINT_UNITS[name])
        rms = h5.create_group("weighted_rms")
        for name, values in data.weighted_rms.items():
            put(T, rms, name, values)
        if designs is not None:
            grp = h5.create_group("designs")
            write_attrs(grp, picks=[", ".join(p) for p in designs.picks])
            put(T, grp, "row", designs.rows)
            put(T, grp, "id", designs.ids)
            put(T, grp, "X", designs.X, list(designs.var_units), names=designs.var_names)
            put(T, grp, "F", designs.F, list(designs.obj_units), names=designs.obj_names)
    return Path(path)


def _curves(data: SeatTransmissibility, curves: Sequence[tuple[int, int, str, str]]):
    """The lines (linearised) and points (simulated, H1, where the coherence is at least
    ``_MIN_COHERENCE``, up to 30 Hz) of ``curves``: (design, DOF index, line label, point
    label) each."""
    f_sim = data.simulated_frequency
    band = (f_sim >= data.linear_frequency[0]) & (f_sim <= 30.0)
    lines, points = [], []
    for design, j, line_label, point_label in curves:
        lines.append((line_label, data.linear_frequency, data.linear[design, :, j]))
        good = band & (data.coherence[design, :, j] >= _MIN_COHERENCE)
        points.append((point_label, f_sim[good], data.simulated[design, good, j]))
    return lines, points


def plot_transmissibility(data: SeatTransmissibility, path: str | Path, design: int = 0) -> Path:
    """Figure of the seat transmissibility and (with a passenger) STHT of one design: linear
    model as lines, simulation (H1) as dots where the coherence is at least 0.8."""
    lines, points = _curves(
        data,
        [
            (
                design,
                data.dof_names.index(name),
                f"{label} (linearised)",
                f"{label} (simulated, H1)",
            )
            for name, label in (("seat", "seat  z̈_seat/z̈_s"), ("head", "STHT  z̈_head/z̈_s"))
            if name in data.dof_names
        ],
    )
    title = (
        f"{data.kind.upper()} seat, X_ST = {1e3 * data.static_deflection[design]:.1f} mm (Eq 2.86)"
    )
    return plots.transmissibilities(
        path, title, lines, points, f_range=(data.linear_frequency[0], 30.0)
    )


def plot_front_transmissibility(
    data: SeatTransmissibility, designs: FrontDesigns, path: str | Path, title: str
) -> Path:
    """STHT (or, without a passenger, the seat transmissibility) of each picked design
    (Fig. 8.26): linearised as lines, simulated (H1) as dots where coherent."""
    name = "head" if "head" in data.dof_names else "seat"
    j = data.dof_names.index(name)
    lines, points = _curves(
        data,
        [
            (
                p,
                j,
                f"{' = '.join(picks)} (design {designs.ids[p]}, X_ST "
                f"{1e3 * data.static_deflection[p]:.1f} mm)",
                f"{' = '.join(picks)} (simulated, H1)",
            )
            for p, picks in enumerate(designs.picks)
        ],
    )
    what = "STHT z̈_head/z̈_s" if name == "head" else "seat TR z̈_seat/z̈_s"
    return plots.transmissibilities(
        path, f"{title}: {what} (Eq 2.86)", lines, points, f_range=(data.linear_frequency[0], 30.0)
    )


def _peak(f: np.ndarray, values: np.ndarray, valid: np.ndarray | None = None):
    """Largest value in the peak band and its frequency, (value, f) for one design's curve."""
    band = (f >= _PEAK_BAND[0]) & (f <= _PEAK_BAND[1])
    if valid is not None:
        band &= valid
    if not band.any():
        return np.nan, np.nan
    i = np.flatnonzero(band)[np.argmax(values[band])]
    return values[i], f[i]


def _run_front(source: Path, with_: Sequence[Path], pick: Sequence[str] | None) -> Analysis:
    """The picks of a Pareto file, or the designs ``pick`` names (module docstring)."""
    if len(with_) > 1:
        raise ConfigError("analyse transmissibility takes one --with FILE.yaml")
    pareto = read_front(source, pick)
    cfg = with_passenger(pareto, with_[0]) if with_ else pareto.config()
    designs = front_designs(pareto)
    try:
        data = seat_transmissibility(cfg, params=designs.params())
    except ConfigError as exc:  # a stored value the config's field cannot take
        if not str(exc).startswith("params:"):
            raise
        raise ConfigError(f"{pareto.path}: /pareto/X: {exc}") from None
    title = f"{data.kind.upper()} front of {pareto.path.name}"
    return analysis(
        "transmissibility",
        title,
        data,
        cfg,
        [pareto.path, *with_],
        lambda path, command: write_transmissibility(path, data, cfg, command, designs),
        lambda path: plot_front_transmissibility(data, designs, path, title),
        lambda: _front_table(data, designs, pareto, title, with_),
    )


def _front_table(
    data: SeatTransmissibility,
    designs: FrontDesigns,
    pareto: ParetoSet,
    title: str,
    with_: Sequence[Path],
) -> Report:
    """The table of a front's designs: their objectives, X_ST, peaks and r.m.s."""
    name = "head" if "head" in data.dof_names else "seat"
    label = "STHT" if name == "head" else "seat TR"
    j = data.dof_names.index(name)
    rows = []
    for p, picks in enumerate(designs.picks):
        lin = _peak(data.linear_frequency, data.linear[p, :, j])
        sim = _peak(
            data.simulated_frequency,
            data.simulated[p, :, j],
            data.coherence[p, :, j] >= _MIN_COHERENCE,
        )
        rms = data.weighted_rms.get(f"{name}.acc")
        rows.append(
            [
                " = ".join(picks),
                designs.ids[p],
                *(f"{f:.4g}" for f in designs.F[p]),
                f"{1e3 * data.static_deflection[p]:.2f}",
                f"{lin[0]:.3f} @ {lin[1]:.2f}",
                f"{sim[0]:.3f} @ {sim[1]:.2f}",
                "-" if rms is None else f"{rms[p]:.4f}",
            ]
        )
    columns = [
        "pick",
        "design",
        *(f"{n} [{u}]" for n, u in zip(designs.obj_names, designs.obj_units)),
        "X_ST simulated [mm]",
        f"{label} peak, linear [- @ Hz]",
        f"{label} peak, simulated [- @ Hz]",
        f"Wk r.m.s. {name}.acc [m/s^2]",
    ]
    shown = pareto.picked_note() or [
        "picks of the front (suspopt.choosing.kepsilon.pareto_picks, Fig. 8.21): the edges "
        "best_<objective> and the knee"
    ]
    notes = [
        f"{shown[0]}; objectives as stored; X_ST, peaks and r.m.s. "
        f"{'with the passenger of ' + str(with_[0]) if with_ else 'as stored'}",
        "TR = |z̈_i / z̈_s| from the floor z_s (Eq 2.86); peaks in 0.5-20 Hz, simulated "
        f"where the coherence is >= {_MIN_COHERENCE}",
    ]
    if name != "head":
        notes.append(
            "no passenger: STHT needs one, e.g. --with "
            "configs/ch8/<seat>_class_a_passenger.yaml (Sec 8.4.4)"
        )
    return Report(title=f"transmissibility - {title}", columns=columns, rows=rows, notes=notes)


def run(source: Path, with_: Sequence[Path] = (), pick: Sequence[str] | None = None) -> Analysis:
    """The ``transmissibility`` analysis of ``source``: a YAML config with a seat, or a Pareto
    file (then ``with_`` may give the passenger, module docstring), or with ``pick`` those
    designs of a result file (:func:`suspopt.choosing.picks.read_front`); nothing written."""
    if is_hdf5(source):
        return _run_front(Path(source), with_, pick)
    for given, option in ((with_, "--with"), (pick, "--pick")):
        if given:
            raise ConfigError(f"analyse transmissibility {source}: {option} is for a result file")
    cfg = load_config(source)
    data = seat_transmissibility(cfg)
    return analysis(
        "transmissibility",
        f"transmissibility - {data.kind.upper()} seat ({Path(source).name})",
        data,
        cfg,
        [Path(source)],
        lambda path, command: write_transmissibility(path, data, cfg, command),
        lambda path: plot_transmissibility(data, path),
        lambda: _config_table(data, Path(source)),
    )


def _config_table(data: SeatTransmissibility, source: Path) -> Report:
    """The table of one config's seat: X_ST, its modes, peaks, r.m.s. and constraints."""
    rows = [
        ["static deflection X_ST", "mm", f"{1e3 * data.static_deflection[0]:.2f}"],
        ["natural frequencies", "Hz", ", ".join(f"{f:.2f}" for f in data.natural_frequency[0])],
    ]
    for name, label in (("seat", "seat TR"), ("head", "STHT")):
        if name not in data.dof_names:
            continue
        j = data.dof_names.index(name)
        tr, f = _peak(data.linear_frequency, data.linear[0, :, j])
        rows.append([f"{label} peak (linear)", "- @ Hz", f"{tr:.3f} @ {f:.2f}"])
        tr, f = _peak(
            data.simulated_frequency,
            data.simulated[0, :, j],
            data.coherence[0, :, j] >= _MIN_COHERENCE,
        )
        rows.append([f"{label} peak (simulated)", "- @ Hz", f"{tr:.3f} @ {f:.2f}"])
    for name, values in data.weighted_rms.items():
        rows.append([f"Wk r.m.s. {name}", "m/s^2", f"{values[0]:.4f}"])
    for name, values in data.constraints.items():
        rows.append([f"g {name}", CONSTRAINT_UNITS[name], f"{values[0]:.4g}"])
    notes = [
        "TR = |z̈_i / z̈_s| from the floor z_s (Eq 2.86); peaks in 0.5-20 Hz, simulated "
        f"where the coherence is >= {_MIN_COHERENCE}; g: constraint values, <= 0 feasible"
    ]
    if "head" not in data.dof_names:
        notes.append("no passenger: STHT needs seat.passenger (e.g. passenger: {})")
    return Report(
        title=f"transmissibility - {data.kind.upper()} seat ({source.name})",
        columns=["quantity", "unit", "value"],
        rows=rows,
        notes=notes,
    )


KINDS["transmissibility"] = Kind(run, options=("with_", "pick"))
