"""Pseudo Pareto fronts: the designs of a stored front re-simulated under a change.

The thesis re-simulates the optimal designs of a Pareto front under conditions other than the
ones they were optimised for and compares the objectives ("pseudo" Pareto fronts):

- ``roads`` (Sec 8.4.2, Fig. 8.23, Table 8.12): other road profiles. ``--road B`` keeps the
  stored road and changes its ISO 8608 class only (same seed, speed and length: the same
  realisation scaled); ``--road CONFIG.yaml`` takes that config's ``road`` and ``simulation``
  sections (e.g. ``configs/ch8/ps_class_b.yaml``: class B at 85 km/h over 1000 m, as the thesis
  drives each class at its own speed).
- ``masses`` (Sec 8.4.3, Fig. 8.24, Table 8.13): another passenger, the whole load on the
  isolator ``m ± 20 kg``, seated by :func:`suspopt.seat.passenger_mass_change` (NSS1-NSS3 keep
  ``X_ST``, their ``K_v`` follows the load and ``K_h`` stays as built; PS and NSS4 keep their
  stiffnesses and their ``X_ST`` follows the load). The new masses are written into the
  changed config; where the stiffness ratio ``α`` is itself a design variable, each design's
  ``α`` takes the same factor ``m_old/m_new`` (the changed designs are written too).
- ``controllers`` (Sec 7.3, Fig. 7.4b): another controller. ``--with FILE.yaml`` (a config or
  a fragment) supplies a ``control:`` section and/or dampers (``vehicle.corner_defaults.damper``,
  ``vehicle.corners.<c>.damper``), which replace the stored config's; the designs' own values
  (e.g. ``c_min``, ``c_max``) are then applied on top. ``configs/ch7/sh_2_cdf.yaml`` and
  ``sh_add_2_cdf.yaml`` give SH-2-CDF and SH-ADD-2-CDF from the SH-2 and SH-ADD-2 fronts.

The Pareto file is read and its designs evaluated by :mod:`suspopt.choosing.selection` (the code
``suspopt kesort`` uses): each change is ONE batched simulation of all N designs
(:func:`~suspopt.choosing.selection.evaluate_pareto`). The change of each objective is
``100 (f_changed - f_stored) / f_stored`` in % (Tables 8.12-8.13: positive when the objective
grows). A design whose simulation fails under the change gets NaN objectives and
``failed = 1`` (the optimiser's penalty values are not reported). A change that cannot be
computed is NaN in the file and ``n/a`` in the table, with a note: the stored value is 0, or
the change is beyond the floating-point range (a damaged file's 1e-308), or the stored design
failed (the file holds the optimiser's penalty values for it, ``1e10`` or more: its stored
values show as ``failed``). Nothing is computed with a floating-point warning. The file holds
no supplementary objectives (Eq 7.7-7.10 in Ch. 7), so when the config has some, the stored
designs are simulated once more with the stored config for theirs, to compare them too.

The file's layout is declared once, in :data:`suspopt.formats.PSEUDO` (its ``/pareto``, the
front analysed, is that of every analysis of a front).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from .. import plots
from ..choosing.picks import read_front
from ..choosing.selection import DesignSet, ParetoSet, evaluate_pareto
from ..config import Config, ConfigError
from ..config.loader import edit_config, line_of, set_path
from ..design_ids import front_ids, id_marks
from ..files import Unreadable, listed, status
from ..formats import PSEUDO, FileFormat
from ..io import atomic_h5, put, write_attrs
from ..plots.runs import evenly_spaced
from ..seat import build_seat, passenger_mass_change
from . import cells
from .registry import KINDS, Analysis, Kind, Report, analysis, relative_change

__all__ = [
    "Variant",
    "PseudoFronts",
    "config_with",
    "read_sections",
    "road_variants",
    "mass_variants",
    "controller_variants",
    "pseudo_fronts",
    "write_pseudo_fronts",
    "plot_pseudo_fronts",
    "MASS_CHANGES",
    "run_roads",
    "run_masses",
    "run_controllers",
    "run_variants",
]

#: Passenger changes of Sec 8.4.3 [kg]: 20 kg lighter and heavier.
MASS_CHANGES = (-20.0, 20.0)
#: Rows of the printed table: designs spread along the front.
_TABLE_ROWS = 12
_ROAD_CLASSES = ("A", "B", "C", "D", "E")


@dataclass
class Variant:
    """One change of a stored front: ``config`` to simulate with, ``X (N, n)`` the designs'
    physical values under the change (None: the stored ones), ``attrs`` that describe it."""

    label: str
    config: Config
    X: np.ndarray | None = None
    attrs: dict = field(default_factory=dict)


@dataclass
class PseudoFronts:
    """A stored front and its pseudo-fronts. ``stored`` and ``sets[i]`` (under
    ``variants[i]``) hold main then supplementary objectives (``names``, ``units``; the first
    ``m`` are the main ones); :meth:`values` reads them with NaN for failed designs."""

    kind: str
    pareto: ParetoSet
    stored: DesignSet
    variants: list[Variant]
    sets: list[DesignSet]

    @property
    def m(self) -> int:
        return self.pareto.F.shape[1]

    @property
    def picks(self) -> dict[str, int]:
        """The edges and knee of the stored front (:func:`suspopt.choosing.kepsilon.pareto_picks`,
        Fig. 8.21; Tables 8.12-8.13 report the edges), or the picks given (``--pick``)."""
        return self.pareto.marks()

    @property
    def reference(self) -> np.ndarray:
        """(N, m + s): the file's main objectives, then the re-simulated supplementary ones;
        NaN for a design that failed (:func:`.cells.stored_reference`)."""
        return cells.stored_reference(self.pareto.F, self.stored)

    @property
    def stored_failed(self) -> np.ndarray:
        """(N,) the stored designs that failed (the file's penalty values, or their
        re-simulation): their changes cannot be computed."""
        return cells.stored_failed(self.pareto.F, self.stored)

    def values(self, i: int) -> np.ndarray:
        """(N, m + s) objectives under variant ``i`` (NaN where the simulation failed)."""
        s = self.sets[i]
        return np.where(s.failed[:, None], np.nan, s.F)

    def change(self, i: int) -> np.ndarray:
        """(N, m + s) change of each objective under variant ``i`` [%]."""
        return relative_change(self.values(i), self.reference)


def read_sections(path: Path, option: str, with_node: bool = False):
    """The YAML mapping of config sections in ``path`` (and, ``with_node``, its composed node
    tree, for :func:`mapping_at`); ConfigError naming ``option``."""
    from ..config.yamlio import YamlError, parse_yaml, read_text

    try:
        data, node = parse_yaml(read_text(path))
    except FileNotFoundError:
        raise ConfigError(f"{option} {path}: no such file") from None
    except YamlError as exc:
        raise ConfigError(f"{option} {path}{f':{exc.line}' if exc.line else ''}: {exc}") from None
    if not isinstance(data, dict):
        raise ConfigError(f"{option} {path}: must be a YAML mapping of config sections")
    return (data, node) if with_node else data


def mapping_at(data: dict, node, keys: tuple[str, ...], where: str) -> dict:
    """The mapping at ``keys`` of the sections ``data`` (``node``: their YAML tree), {} where
    it is absent or null; ConfigError naming ``where``, the line and the keys where it is
    anything else (a list, a number: an AttributeError traceback before)."""
    value: object = data
    for key in keys:
        value = value.get(key) if isinstance(value, dict) else None
    if value is None:
        return {}
    if isinstance(value, dict):
        return value
    line = line_of(node, keys) or "?"
    raise ConfigError(
        f"{where}:{line}: {'.'.join(keys)}: must be a mapping, not {type(value).__name__}"
    )


# --- changes -------------------------------------------------------------------------------


def config_with(pareto: ParetoSet, edit: Callable[[dict], None], what: str) -> Config:
    """The stored config with ``edit`` applied to its YAML data
    (:func:`suspopt.config.loader.edit_config`); errors refer to the lines of the edited
    text, written to the analysis's HDF5 as ``config``."""
    return edit_config(
        pareto.config_text,
        edit,
        pareto.path.with_name(pareto.path.name + ":config"),
        f"{what}; the config of {pareto.path.name}",
    )


def road_variants(pareto: ParetoSet, roads: Sequence[str] = ()) -> list[Variant]:
    """One variant per road: an ISO 8608 class letter (A-E: the stored road with that class)
    or a config file whose ``road`` and ``simulation`` sections replace the stored ones."""
    roads = [str(road) for road in listed(roads)]
    if not roads:
        raise ConfigError(
            "analyse roads: give at least one --road CLASS (A-E) or --road CONFIG.yaml"
        )
    variants = []
    for road in roads:
        if road.upper() in _ROAD_CLASSES:
            letter = road.upper()
            kind = pareto.config().road.kind
            if kind != "iso8608":
                raise ConfigError(
                    f"--road {road}: a road class needs an ISO 8608 road; the "
                    f"road of {pareto.path.name} is {kind} (give a config file "
                    f"instead)"
                )

            def set_class(data, letter=letter):
                data["road"]["road_class"] = letter
                data["road"].pop("level", None)  # a level would override the class

            cfg = config_with(pareto, set_class, f"road class {letter}")
            variants.append(Variant(f"class {letter}", cfg, attrs={"road_class": letter}))
            continue
        path = Path(road)
        try:
            missing = status(path) is None
        except Unreadable as exc:
            raise ConfigError(f"--road {road}: {exc}") from None
        if missing:
            raise ConfigError(f"--road {road}: neither a road class (A-E) nor a file")
        other = read_sections(path, "--road")
        if not isinstance(other.get("road"), dict):
            raise ConfigError(f"--road {road}: the file has no road: section")
        section = dict(other["road"])
        if section.get("kind") == "file" and not Path(section.get("path", "")).is_absolute():
            section["path"] = str((path.parent / section["path"]).resolve())

        def set_road(data, section=section, simulation=other.get("simulation")):
            data["road"] = section
            if simulation is not None:
                data["simulation"] = simulation

        cfg = config_with(pareto, set_road, f"the road of {path}")
        variants.append(Variant(path.stem, cfg, attrs={"road_source": str(path)}))
    return variants


def mass_variants(pareto: ParetoSet, changes: Sequence[float] = MASS_CHANGES) -> list[Variant]:
    """One variant per change of the whole load on the isolator [kg] (Sec 8.4.3: ±20 kg).

    The rule is :func:`passenger_mass_change`'s; its new masses go into the config. It scales
    ``seat.stiffness_ratio`` from the config's value, so where that ratio is a design variable
    each design's own takes the factor the rule gives a ratio of 1."""
    changes = listed(changes)  # (one change: "20" or 20.0)
    cfg = pareto.config()
    if cfg.seat is None:
        raise ConfigError(
            f"{pareto.path}: analyse masses needs a seat, and the optimised "
            f"config has no seat: section"
        )
    paths = {v.label: v.path for v in cfg.design_variables}
    for path in paths.values():
        if path == "seat.mass" or path.startswith("seat.passenger."):
            raise ConfigError(
                f"{pareto.path}: analyse masses changes the passenger, and "
                f"{path} is a design variable"
            )
    if not changes:
        raise ConfigError("analyse masses: give at least one --mass-change KG")
    load = float(build_seat(cfg).isolator["load_mass"][0])
    lowest = cfg.seat.mass if cfg.seat.passenger is not None else 0.0
    ratio = "seat.stiffness_ratio"
    designed = [j for j, name in enumerate(pareto.var_names) if paths.get(name) == ratio]
    variants = []
    for delta in changes:
        new = load + float(delta)
        if not (new > lowest and math.isfinite(new)):
            floor = f"the seat mass ({lowest:g} kg)" if lowest else "0 kg"
            raise ConfigError(
                f"--mass-change {delta:g}: the load would be {new:g} kg; give a change "
                f"that leaves a finite load above {floor}"
            )
        changed = {path: float(value[0]) for path, value in passenger_mass_change(cfg, new).items()}
        X = None
        if ratio in changed and designed:
            unit = cfg.model_copy(
                update={"seat": cfg.seat.model_copy(update={"stiffness_ratio": 1.0})}
            )
            X = pareto.X.copy()
            X[:, designed] *= passenger_mass_change(unit, new)[ratio][0]

        def seat_passenger(data, changed=changed):
            for path, value in changed.items():
                set_path(data, path, value)

        variants.append(
            Variant(
                f"{new:g} kg",
                config_with(pareto, seat_passenger, f"a {new:g} kg load"),
                X,
                attrs={"load_mass": new, "mass_change": float(delta)},
            )
        )
    return variants


def controller_variants(pareto: ParetoSet, sources: Sequence[Path] = ()) -> list[Variant]:
    """One variant per file whose ``control:`` section and dampers replace the stored ones
    (a damper in ``vehicle.corner_defaults`` replaces every corner's, one under
    ``vehicle.corners.<c>`` that corner's)."""
    sources = listed(sources)
    if not sources:
        raise ConfigError("analyse controllers: give at least one --with FILE.yaml")
    corners = set(pareto.config().vehicle.corners)
    variants = []
    for source in sources:
        source = Path(source)
        other, node = read_sections(source, "--with", with_node=True)
        where = f"--with {source}"
        control = other.get("control")
        mapping_at(other, node, ("vehicle",), where)
        default = mapping_at(other, node, ("vehicle", "corner_defaults"), where).get("damper")
        own = {
            c: v["damper"]
            for c, v in mapping_at(other, node, ("vehicle", "corners"), where).items()
            if isinstance(v, dict) and "damper" in v
        }
        if control is None and default is None and not own:
            raise ConfigError(
                f"--with {source}: the file has no control: section and no "
                f"damper (vehicle.corner_defaults.damper or "
                f"vehicle.corners.<corner>.damper)"
            )
        unknown = sorted(set(own) - corners)
        if unknown:
            raise ConfigError(
                f"--with {source}: corner(s) {', '.join(unknown)} are not in "
                f"{pareto.path.name} (it has {', '.join(sorted(corners))})"
            )

        def controller(data, control=control, default=default, own=own):
            if control is not None:
                data["control"] = control
            veh = data["vehicle"]
            if default is not None:
                veh.setdefault("corner_defaults", {})["damper"] = default
                for corner in (veh.get("corners") or {}).values():
                    if isinstance(corner, dict):
                        corner.pop("damper", None)
            for name, damper in own.items():
                veh.setdefault("corners", {})
                if not isinstance(veh["corners"].get(name), dict):
                    veh["corners"][name] = {}
                veh["corners"][name]["damper"] = damper

        cfg = config_with(pareto, controller, f"the controller of {source}")
        variants.append(Variant(source.stem, cfg, attrs={"controller_source": str(source)}))
    return variants


# --- evaluation, output ----------------------------------------------------------------------


#: The changes a pseudo front is evaluated under (``analyse roads``, ``masses``,
#: ``controllers``, and ``tolerances``: :mod:`.tolerances`).
PSEUDO_KINDS = ("roads", "masses", "controllers", "tolerances")


def pseudo_fronts(kind: str, pareto: ParetoSet, variants: Sequence[Variant]) -> PseudoFronts:
    """Evaluate the stored designs under every variant, one batch each; the stored designs
    are simulated too when the config has supplementary objectives (the file has none)."""
    if kind not in PSEUDO_KINDS:
        raise ConfigError(f"{kind!r}: not a kind of pseudo front ({', '.join(PSEUDO_KINDS)})")
    if not variants:
        raise ConfigError(f"analyse {kind}: no changes to evaluate the designs under")
    labels = [v.label for v in variants]
    if len(set(labels)) != len(labels):
        raise ConfigError(f"analyse {kind}: the changes must differ (got {', '.join(labels)})")
    stored = evaluate_pareto(pareto)
    sets = [
        evaluate_pareto(pareto if v.X is None else replace(pareto, X=v.X), v.config, v.label)
        for v in variants
    ]
    for v, s in zip(variants, sets):
        if s.names != stored.names:
            raise ConfigError(
                f"{pareto.path}: with {v.label} the objectives are "
                f"{', '.join(s.names)}, not {', '.join(stored.names)}"
            )
    return PseudoFronts(kind=kind, pareto=pareto, stored=stored, variants=list(variants), sets=sets)


def write_stored_front(
    h5, fmt: FileFormat, kind: str, pareto: ParetoSet, stored: DesignSet
) -> None:
    """The root attributes ``analysis`` and ``source`` and the group ``/pareto`` of an
    analysis of the front ``pareto`` (``fmt``: the file's format), ``stored`` its designs
    evaluated under the stored config."""
    m, names, units = pareto.F.shape[1], stored.names, stored.units
    h5.attrs["analysis"] = kind
    h5.attrs["source"] = str(pareto.path)
    grp = h5.create_group("pareto")
    put(fmt, grp, "X", pareto.X, list(pareto.var_units), names=pareto.var_names)
    put(fmt, grp, "F", pareto.F, list(units[:m]), names=names[:m])
    put(fmt, grp, "feasible", stored.feasible.astype(np.int8))
    picks = grp.create_group("picks")
    for key, row in pareto.marks().items():
        put(fmt, picks, key, row)
    if pareto.source_rows is not None:  # (designs picked from the file)
        put(fmt, grp, "source_row", pareto.source_rows)
    put(fmt, grp, "id", front_ids(pareto))
    if len(names) > m:
        put(fmt, grp, "S", stored.F[:, m:], list(units[m:]), names=names[m:])


def write_pseudo_fronts(path: str | Path, fronts: PseudoFronts, command: str | None = None) -> Path:
    """Write ``fronts`` as :data:`suspopt.formats.PSEUDO` declares it (atomically)."""
    p, m = fronts.pareto, fronts.m
    names, units = fronts.stored.names, fronts.stored.units
    with atomic_h5(path, p.config(), command, inputs=[("the input", p.path)]) as h5:
        write_stored_front(h5, PSEUDO, fronts.kind, p, fronts.stored)
        pseudo = h5.create_group("pseudo")
        write_attrs(pseudo, labels=[v.label for v in fronts.variants])
        for i, (variant, s) in enumerate(zip(fronts.variants, fronts.sets)):
            g = pseudo.create_group(variant.label.replace("/", "_"))
            write_attrs(g, label=variant.label, config=variant.config.text, **variant.attrs)
            values, change = fronts.values(i), fronts.change(i)
            put(PSEUDO, g, "F", values[:, :m], list(units[:m]), names=names[:m])
            put(PSEUDO, g, "change", change[:, :m], ["%"] * m, names=names[:m])
            if len(names) > m:
                put(PSEUDO, g, "S", values[:, m:], list(units[m:]), names=names[m:])
                put(PSEUDO, g, "S_change", change[:, m:], ["%"] * (len(names) - m), names=names[m:])
            if variant.X is not None:
                put(PSEUDO, g, "X", variant.X, list(p.var_units), names=p.var_names)
            put(PSEUDO, g, "feasible", s.feasible.astype(np.int8))
            put(PSEUDO, g, "failed", s.failed.astype(np.int8))
    return Path(path)


def is_comfort(cfg: Config) -> list[bool]:
    """Which main objectives are ISO 2631-1 weighted r.m.s. accelerations (their comfort
    levels are drawn)."""
    objectives = cfg.objectives
    return [spec.metric == "rms_weighted" for spec in objectives.main] if objectives else []


def plot_pseudo_fronts(
    fronts: PseudoFronts, path: str | Path, title: str, marks: Mapping[str, int] | None = None
) -> Path:
    """The stored front and its pseudo-fronts, and the design variables along the stored
    front (:func:`suspopt.plots.pareto_fronts`); ``marks`` (name -> design, default the
    picks) are starred."""
    p, m = fronts.pareto, fronts.m
    stored = np.where(fronts.stored_failed[:, None], np.nan, p.F)  # (not the penalty values)
    curves = [(f"optimised ({p.path.name})", stored)]
    curves += [(v.label, fronts.values(i)[:, :m]) for i, v in enumerate(fronts.variants)]
    variables = [
        (name, unit, p.X[:, j]) for j, (name, unit) in enumerate(zip(p.var_names, p.var_units))
    ]
    objectives = list(zip(fronts.stored.names[:m], fronts.stored.units[:m]))
    return plots.pareto_fronts(
        path,
        title,
        objectives,
        curves,
        variables,
        marks=id_marks(p, fronts.picks if marks is None else marks),
        comfort=is_comfort(p.config()),
    )


def table_designs(N: int, picked: Mapping[int, list[str]]) -> list[tuple[int, str]]:
    """The rows of a table of a front of ``N`` designs: at most :data:`_TABLE_ROWS` evenly
    spaced, and every design ``picked`` names (row -> its picks:
    :meth:`~suspopt.choosing.selection.ParetoSet.marks_by_row`); (row, the names of its picks), in
    order."""
    rows = sorted(set(evenly_spaced(N, _TABLE_ROWS)) | set(picked))
    return [(k, ", ".join(picked.get(k, []))) for k in rows]


def _report(fronts: PseudoFronts, title: str) -> Report:
    p, m = fronts.pareto, fronts.m
    names, units = fronts.stored.names, fronts.stored.units
    columns = ["design", "pick"] + [f"{n} [{u}]" for n, u in zip(names[:m], units[:m])]
    for v in fronts.variants:
        columns += [f"{v.label}: {n} (change)" for n in names[:m]]
    values = [fronts.values(i) for i in range(len(fronts.sets))]
    changes = [fronts.change(i) for i in range(len(fronts.sets))]
    rows = []
    lost, ids = fronts.stored_failed, front_ids(p)
    shown_na = False
    for k, picks in table_designs(len(p.X), p.marks_by_row()):
        row = [ids[k], picks] + cells.stored_cells(p.F[k], lost[k])
        for s, value, change in zip(fronts.sets, values, changes):
            row += [
                "failed" if s.failed[k] else f"{f:.4g} ({cells.percent(c, '.0f')})"
                for f, c in zip(value[k, :m], change[k, :m])
            ]
            shown_na |= not s.failed[k] and bool(np.isnan(change[k, :m]).any())
        rows.append(row)
    shown = p.picked_note() or [
        f"{len(rows)} of {len(p.X)} designs of {p.path.name}, sorted by {names[0]}, with "
        f"the edges and knee of the front (suspopt.choosing.kepsilon.pareto_picks, Fig. 8.21)"
    ]
    notes = [
        f"{shown[0]}; change = (f - f_stored)/f_stored (Tables 8.12-8.13)",
        *fronts.stored.notes,
    ]
    if lost.any():
        notes.append(cells.failed_stored_note(lost, ids))
    if shown_na:
        notes.append(cells.NOT_COMPUTED_NOTE)
    for v, s, change in zip(fronts.variants, fronts.sets, changes):
        change = change[~s.failed]
        spans = [cells.change_span(name, c) for name, c in zip(names, change.T) if c.size]
        notes.append(
            f"{v.label}: {int(s.feasible.sum())} of {len(p.X)} designs feasible, "
            f"{int(s.failed.sum())} failed; " + "; ".join(spans)
        )
    return Report(title=title, columns=columns, rows=rows, notes=notes)


def run_variants(
    kind: str,
    source: Path,
    variants: Callable[[ParetoSet], list[Variant]],
    what: str,
    pick: Sequence[str] | None = None,
) -> Analysis:
    """The analysis ``kind`` of the Pareto file ``source`` (or of its designs ``pick``:
    :func:`suspopt.choosing.picks.read_front`) under the ``variants`` made of it
    (:func:`pseudo_fronts`); nothing written."""
    pareto = read_front(source, pick)
    fronts = pseudo_fronts(kind, pareto, variants(pareto))
    title = f"{kind}: {pareto.path.name} {what}"
    return analysis(
        kind,
        title,
        fronts,
        pareto.config(),
        [pareto.path],
        lambda path, command: write_pseudo_fronts(path, fronts, command),
        lambda path: plot_pseudo_fronts(fronts, path, title),
        lambda: _report(fronts, title),
    )


def _pseudo_kind(
    kind: str, make: Callable[..., list[Variant]], option: str, keyword: str, what: str
) -> Kind:
    """The analysis ``kind``: the front (or its designs ``--pick`` names) under the variants
    ``make`` gives, the command-line option ``option`` passed to it as ``keyword``
    (:func:`run_variants`)."""

    def run(source: Path, pick: Sequence[str] | None = None, **given: Any) -> Analysis:
        chosen = {keyword: given[option]} if option in given else {}
        return run_variants(kind, source, partial(make, **chosen), what, pick)

    run.__name__ = run.__qualname__ = f"run_{kind}"
    run.__doc__ = (
        f"``suspopt analyse {kind} PARETO.h5 [--{option.strip('_').replace('_', '-')} ...] "
        f"[--pick NAMES]``: the front {what} (:func:`{make.__name__}`)."
    )
    return Kind(run, options=(option, "pick"))


# Sec 8.4.2 and Table 8.12; Sec 8.4.3 and Table 8.13; Sec 7.3 and Fig. 7.4b
KINDS["roads"] = _pseudo_kind("roads", road_variants, "road", "roads", "on other roads (Sec 8.4.2)")
KINDS["masses"] = _pseudo_kind(
    "masses", mass_variants, "mass_change", "changes", "with other passengers (Sec 8.4.3)"
)
KINDS["controllers"] = _pseudo_kind(
    "controllers", controller_variants, "with_", "sources", "with other controllers (Fig. 7.4b)"
)
run_roads, run_masses, run_controllers = (KINDS[k].run for k in ("roads", "masses", "controllers"))
