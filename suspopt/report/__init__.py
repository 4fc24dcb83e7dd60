"""``suspopt report FILE.h5 ... -o study.html``: an interactive Pareto explorer in one file.

:func:`build_report` reads the result files of ``suspopt optimise``, ``kesort``, ``analyse
roads|masses|controllers|tolerances`` and ``analyse transmissibility`` of a Pareto file, the files that
hold a design table (:func:`suspopt.choosing.picks.read_table`; each a *study*: :func:`collect`), and writes
one self-contained HTML page (:mod:`.page`): every script and style inline, plotly.js
included (plotly, a dependency), so it opens offline in any
browser and makes no network request. Per study:

- the front as a scatter of any two columns (objectives or design variables) chosen from
  drop-downs, in 3D for three objectives; colour by feasibility, k-ε level (kesort), case,
  or any objective or variable (the colour bar titled with its unit); the picks (edges,
  knee, the k-ε optimum) marked, and the config's own design (``/baseline`` of an optimise
  file) where the file has it, each marked point with one label naming its picks, placed
  where it overlaps no other label (:mod:`.charts`);
- a parallel-coordinates view of the objectives and variables, coloured as the front, each
  variable's axis spanning its search range (:func:`_search_bounds`);
  brushing ranges along its axes selects the designs inside all of them in the front,
  counts them and shows the ``suspopt simulate`` of them (up to 100). It is drawn when it comes on screen, at most three at a time (a browser
  keeps about 16 WebGL contexts per page and each takes three: ``assets/page.js``);
- hover and click on a design: its row, objectives with units, variables (those at a
  bound marked), constraint margins, in the panel beside the plot, and the ``suspopt export`` and ``simulate``
  commands that take it on (the file's path as given, quoted for a POSIX shell);
- every design named by its id (``ids`` in the page's data, :mod:`suspopt.design_ids`: its
  row in the front it came from), in the panel, the hover texts, the legends and the
  commands, as ``--pick`` takes it;
- the picks' (and ``with_signals`` rows') time histories and power spectral densities
  [unit²/Hz], simulated when the report is built (from each design's own config, in one
  batch per config), each history thinned to at most about :data:`MAX_SAMPLES` samples with
  its peaks kept (:func:`_envelope`; the page says when), each spectrum the one the
  ``--plot`` figure draws (:func:`suspopt.metrics.spectral.record_psd`, 0.1-30 Hz, its
  axis at most :data:`suspopt.plots.style.PSD_DECADES` decades deep); curves the same to
  1e-12 drawn as one (:mod:`.charts`); where there is a seat, their transmissibility from the floor to the seat and
  to the head (STHT, Eq 2.86) of the seat linearised about its static equilibrium;
- pseudo-fronts (``analyse roads|masses|controllers|tolerances``): each changed front over the stored
  one, with a line from each design to its moved point;
- the history per generation, one panel per series on its own titled axis (best value of
  each objective, hypervolume, feasible share: :mod:`.charts`), and the run's
  provenance (config, seeds, version, command) in a collapsible section.

Nothing read from a file runs as code: the data go into the page as JSON (``<`` escaped) and
are shown as text. The page's JavaScript API ``window.suspoptReport`` (``studies[i].points``,
``.front`` and ``.parallel`` (plot ids), ``select(i, row)`` (``row`` a row number, or
``"config"``: the config's own design), ``selected``) and the attributes
``data-rendered`` (body) and ``data-drawn`` (a parallel-coordinates plot) are what the
browser test drives.
"""

from __future__ import annotations

import shlex
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ConfigError
from ..files import listed

__all__ = ["build_report", "collect", "Study", "MAX_SAMPLES", "MAX_BYTES"]

#: The most samples a time history keeps in the page (longer ones are thinned, their peaks
#: kept: :func:`_envelope`; a spectrum keeps the points of its band, 240 at most).
MAX_SAMPLES = 1000
#: The page may not grow beyond this [bytes] (a 1000-design front with 5 picks' signals
#: stays far below it).
MAX_BYTES = 10 << 20
#: The most designs whose signals a report simulates.
MAX_SIGNAL_DESIGNS = 12


@dataclass
class Study:
    """One result file as the page shows it (all arrays as lists, NaN as None)."""

    label: str
    kind: str
    data: dict[str, Any] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def _list(a) -> Any:
    """An array as nested lists, non-finite values as None (JSON has no NaN)."""
    a = np.asarray(a, dtype=float)
    out = a.astype(object)
    out[~np.isfinite(a)] = None
    return out.tolist()


def collect(path: str | Path, with_signals: Sequence[str] = ()) -> Study:
    """The study of one result file (module docstring); ConfigError naming the file for
    anything that is not a suspopt front, or a ``with_signals`` row it does not have."""
    from ..choosing.picks import read_table
    from ..h5read import H5Reader

    path, with_signals = Path(path), listed(with_signals)
    table = read_table(path)
    with H5Reader(path) as h5:
        attrs = {
            key: h5.text_attr(key)
            for key in ("suspopt_version", "created", "command", "config", "analysis", "status",
                        "algorithm")
            if h5.has_attr(key)
        }  # fmt: skip
        for key in ("seed", "optimiser_seed"):
            if h5.has_attr(key):
                attrs[key] = str(h5.attribute(h5.file, key, key))
        kind = "kesort" if table.table == "kesort" else attrs.get("analysis", "optimise")
        extra = _extras(h5, table)
    data: dict[str, Any] = {
        "rows": len(table.X),
        "objectives": table.obj_names,
        "objective_units": table.obj_units,
        "variables": table.var_names,
        "variable_units": table.var_units,
        "F": _list(table.F),
        "X": _list(table.X),
        "picks": table.picks,
        "ids": table.ids,  # (each row's design id: suspopt.design_ids, as --pick takes it)
        "source": shlex.quote(str(path)),  # (as given, for the commands that take a row on)
        "provenance": attrs,
        **extra,
    }
    study = Study(path.name, kind, data)
    if "as_built" in data:
        study.notes.append(
            f"sorted as built: the k-ε levels and picks rank each objective's "
            f"{data['as_built']:g}th percentile over each design's builds "
            f"(/kesort/F_as_built, offered as axes); the front is drawn at the nominal "
            f"values (/kesort/F), and a design's panel gives both"
        )
    _search_bounds(table, data, study.notes)
    rows = sorted(
        set(table.picks.values()) | {table.resolve(r, "--with-signals") for r in with_signals}
    )
    if len(rows) > MAX_SIGNAL_DESIGNS:
        raise ConfigError(
            f"--with-signals: {len(rows)} designs with signals, more than {MAX_SIGNAL_DESIGNS}"
        )
    data["signals"] = _signals(path, table, rows, study.notes)
    return study


def _search_bounds(table, data: dict[str, Any], notes: list[str]) -> None:
    """The design variables' search ranges (``variable_bounds``: lower and upper, None where
    unknown) and which designs lie at a bound (:func:`suspopt.optimisation.bounds.table_bounds`):
    ``at_bound``, one text per variable of one character per design, ``-`` at the lower
    bound, ``+`` at the upper, ``.`` neither (N bytes a variable, where lists of numbers
    would take a 20,000-design page past its size limit). A stored config that does not
    load leaves them out, with a note."""
    from ..optimisation.bounds import table_bounds

    try:
        lower, upper, at = table_bounds(table)
    except ConfigError as exc:
        notes.append(f"the design variables' bounds are not shown: {exc}")
        return
    data["variable_bounds"] = [_list(lower), _list(upper)]
    data["at_bound"] = [
        "".join({-1: "-", 0: ".", 1: "+"}[side] for side in column) for column in at.T
    ]


def _extras(h5, table) -> dict[str, Any]:
    """Feasibility, constraints, k-ε levels, cases, history and pseudo-fronts, where the
    file has them."""
    out: dict[str, Any] = {}
    N = len(table.X)
    group = table.table
    if group == "pareto" and h5._node("pareto/G") is not None:
        G = h5.array("pareto/G", ndim=2)
        if len(G) == N:
            out["G"] = _list(G)
            out["constraints"] = h5.labels("pareto/G", "names", G.shape[1])
            out["constraint_units"] = h5.labels("pareto/G", "units", G.shape[1])
            out["feasible"] = (G <= 0).all(axis=1).tolist()
    if group == "pareto" and h5._node("baseline/F") is not None:  # (the config's design)
        F0 = h5.array("baseline/F", ndim=2, columns=table.F.shape[1])
        X0 = h5.array("baseline/X", ndim=2, columns=table.X.shape[1])
        if len(F0) == len(X0) == 1:
            out["baseline"] = {"F": _list(F0[0]), "X": _list(X0[0])}
            if "G" in out and h5._node("baseline/G") is not None:
                G0 = h5.array("baseline/G", ndim=2, columns=len(out["constraints"]))
                out["baseline"]["G"] = _list(G0[0]) if len(G0) == 1 else None
    if group == "kesort":
        out["k_eps"] = _list(h5.array("kesort/k_eps", ndim=1))
        out["feasible"] = [bool(v) for v in h5.array("kesort/feasible", ndim=1)]
        case = h5.dataset("kesort/case")[()]
        out["case"] = [h5.text(v, "kesort/case") for v in np.atleast_1d(case)]
        if h5._node("kesort/F_as_built") is not None:  # (kesort --as-built)
            out["as_built"] = float(h5.number_attr("kesort/F_as_built", "percentile", 0, 100))
            built = h5.array("kesort/F_as_built", ndim=2, columns=table.F.shape[1])
            if len(built) != N:
                raise ConfigError(f"{h5.where}: /kesort/F_as_built: {len(built)} rows, not {N}")
            out["F_as_built"] = _list(built)
    if h5._node("history/generation") is not None:
        history = {"generation": _list(h5.array("history/generation", ndim=1))}
        for key in ("hypervolume", "feasible"):
            if h5._node(f"history/{key}") is not None:
                history[key] = _list(h5.array(f"history/{key}", ndim=1))
        if h5._node("history/best") is not None:
            best = h5.array("history/best", ndim=2)
            history["best"] = _list(best.T)
            history["best_names"] = h5.labels("history/best", "names", best.shape[1])
            units = h5.attribute(h5._node("history/best"), "units", "/history/best: units")
            history["best_units"] = (
                h5.labels("history/best", "units", best.shape[1])
                if units is not None
                else [""] * best.shape[1]
            )
        out["history"] = history
    if group == "pareto" and h5._node("builds/feasible_share") is not None:
        out["builds"] = _builds(h5, N, table.X.shape[1], table.F.shape[1])
    if h5._node("pseudo") is not None:
        fronts = []
        for label in h5.group("pseudo"):
            F = h5.array(f"pseudo/{label}/F", ndim=2, columns=table.F.shape[1])
            if len(F) == N:
                fronts.append({"label": str(label), "F": _list(F)})
        out["pseudo"] = fronts
    return out


def _builds(h5, N: int, n: int, m: int) -> dict[str, Any]:
    """What an ``analyse builds`` file says of each design's builds
    (:mod:`suspopt.analyse.builds`): the 5th and 95th percentiles of each objective, the share
    of feasible builds, what drives each objective's spread, how many builds and within which
    tolerance [%] (one per variable), and the batch of each variable ("" alone; a file
    written before batches has none)."""
    from ..analyse.builds import DISTRIBUTIONS, DRIVER_SAMPLES
    from ..params import MAX_SWEEP_DESIGNS

    low = h5.array("builds/F_p05", ndim=2, columns=m)
    high = h5.array("builds/F_p95", ndim=2, columns=m)
    share = h5.array("builds/feasible_share", ndim=1)
    r2 = h5.array("builds/contribution", ndim=3)
    tolerance = h5.array("builds/tolerance", ndim=1)
    if not (len(tolerance) == n and ((tolerance > 0) & (tolerance < 100)).all()):
        raise ConfigError(
            f"{h5.where}: /builds/tolerance: not one tolerance in (0, 100) % for each of the "
            f"front's {n} variables"
        )
    if not len(low) == len(high) == len(share) == N or r2.shape != (N, n, m):
        raise ConfigError(
            f"{h5.where}: /builds: the percentiles, shares and contributions do not have "
            f"the front's {N} rows, {n} variables and {m} objectives"
        )
    distribution = h5.text_attr("distribution", "builds")
    if distribution not in DISTRIBUTIONS:
        raise ConfigError(
            f"{h5.where}: /builds: attribute 'distribution': {distribution[:40]!r} is not one of "
            f"{', '.join(DISTRIBUTIONS)}"
        )
    batch = h5.texts("builds/batch", n) if h5._node("builds/batch") is not None else [""] * n
    return {
        "samples": h5.int_attr("builds", "samples", 1, MAX_SWEEP_DESIGNS),
        "batch": batch,
        "tolerance": _list(tolerance),
        "distribution": distribution,
        "low": _list(low),
        "high": _list(high),
        "share": _list(share),
        "contribution": _list(r2),
        "driver_samples": DRIVER_SAMPLES,
    }


def _signals(path: Path, table, rows: list[int], notes: list[str]) -> dict[str, Any]:
    """Time histories and spectra of the designs ``rows``, simulated in one batch per config
    of the table (each design with its own config)."""
    from ..choosing.picks import read_picks
    from ..metrics.spectral import record_psd
    from ..plots.runs import default_signals
    from ..plots.style import PSD_BAND, spectrum_limits
    from ..simulation import simulate
    from ..specs import METRICS

    out: dict[str, Any] = {
        "rows": [], "time": [], "signals": {}, "units": {}, "psd": {}, "psd_units": {}, "psd_range": {}
    }  # fmt: skip
    by_config: dict[int, list[int]] = {}
    for row in rows:
        by_config.setdefault(int(table.config_of[row]), []).append(row)
    results = []
    for group_rows in by_config.values():  # one batch per config (the pooled sets of kesort)
        picked = read_picks(path, [table.ids[r] for r in group_rows])
        with np.errstate(all="ignore"):
            results.append((group_rows, simulate(picked.config, picked.params())))
        if picked.config.seat is not None:
            _transmissibility(picked, group_rows, out)
    if not results:
        return out
    names = default_signals(results[0][1])
    names = [n for n in names if n.startswith(("seat.", "head."))] + [
        n for n in names if not n.startswith(("seat.", "head."))
    ]  # a seat's own first
    time = results[0][1].time
    step = max(1, -(-len(time) // MAX_SAMPLES))
    if step > 1:
        notes.append(
            f"time histories thinned for size: of each {2 * step} of the {len(time)} samples, "
            f"the lowest and the highest shown, in their order, each within {step} samples "
            f"of its time (the spectra are computed from all of them)"
        )
    shown = np.minimum(np.arange(2 * -(-len(time) // (2 * step))) * step, len(time) - 1)
    out["time"] = _list(time[shown] if step > 1 else time)
    fs = 1.0 / float(time[1] - time[0])
    spectra: dict[str, list[np.ndarray]] = {}
    for group_rows, result in results:
        for i, row in enumerate(group_rows):
            out["rows"].append(row)
            for name in names:
                if name not in result.signals:
                    continue
                y = np.asarray(result.signals[name][i], dtype=float)
                out["signals"].setdefault(name, []).append(_list(_envelope(y, step)))
                out["units"][name] = result.signal_unit(name)
                out["psd_units"][name] = METRICS["var"].unit(out["units"][name]) + "/Hz"
                with np.errstate(invalid="ignore"):
                    f, p = record_psd(y, fs)
                band = (f >= PSD_BAND[0]) & (f <= PSD_BAND[1])
                spectra.setdefault(name, []).append(p[band])
                out["psd_f"] = _list(f[band])
    for name, curves in spectra.items():
        out["psd"][name] = [_list(p) for p in curves]
        limits = spectrum_limits(np.array(curves))
        out["psd_range"][name] = None if limits is None else list(limits)
    return out


def _envelope(y: np.ndarray, step: int) -> np.ndarray:
    """``y (T,)`` thinned by ``step`` with its peaks kept: of each ``2 step`` samples (the
    last padded with its last value), the lowest and the highest, in the order they come
    (``2 ceil(T / 2 step)`` values, drawn at every ``step``-th time); NaN (a diverged
    design's samples) only where a whole group is NaN. ``step`` 1: ``y`` itself."""
    if step <= 1:
        return y
    groups = -(-y.size // (2 * step))
    padded = np.concatenate([y, np.full(groups * 2 * step - y.size, y[-1])]).reshape(groups, -1)
    low = np.argmin(np.where(np.isnan(padded), np.inf, padded), axis=1)
    high = np.argmax(np.where(np.isnan(padded), -np.inf, padded), axis=1)
    rows = np.arange(groups)[:, None]
    pair = np.sort(np.stack([low, high], axis=1), axis=1)
    return padded[rows, pair].ravel()


def _transmissibility(picked, rows: list[int], out: dict) -> None:
    """The seat's linear transmissibility ``|z̈_i / z̈_s|`` [1] from the floor to the seat and
    (with a passenger) to the head, the STHT of Eq 2.86, of the designs ``rows``
    (:func:`suspopt.seat.base_transmissibility` of the seat linearised about its static
    equilibrium, as ``suspopt analyse transmissibility`` computes its ``linear`` curves)."""
    from ..analyse.transmissibility import LINEAR_FREQUENCIES
    from ..params import ParamView
    from ..seat import base_transmissibility, build_seat, linearise

    cfg = picked.config
    seat = build_seat(cfg, ParamView(cfg, picked.params()))
    with np.errstate(all="ignore"):
        curves = np.abs(base_transmissibility(linearise(seat), LINEAR_FREQUENCIES))
    tr = out.setdefault(
        "transmissibility", {"f": _list(LINEAR_FREQUENCIES), "rows": [], "dofs": {}}
    )
    tr["rows"] += rows
    for j, name in enumerate(seat.dof_names):
        if name in ("seat", "head"):
            tr["dofs"].setdefault(name, []).extend(_list(curves[:, :, j]))


def _too_large(detail: str, with_signals: Sequence[str]) -> None:
    fewer = "fewer --with-signals designs or fewer files" if with_signals else "fewer files"
    raise ConfigError(
        f"report: the page would be more than {MAX_BYTES >> 20} MB ({detail}): give {fewer}"
    )


def build_report(
    paths: Sequence[str | Path],
    output: str | Path,
    with_signals: Sequence[str] = (),
    title: str | None = None,
) -> tuple[Path, int, list[str]]:
    """Write the report of the result files ``paths`` to ``output`` (module docstring);
    ``with_signals`` rows (or pick names) of every file get their signals too. Returns the
    path, its size [bytes] and the notes (what was thinned). ConfigError for a file that is
    not a suspopt front, a missing pick or row, or without plotly."""
    from .page import data_bytes, render

    paths, with_signals = listed(paths), listed(with_signals)
    if not paths:
        raise ConfigError("report: give at least one result file")
    studies: list[Study] = []
    data = 0
    for p in paths:  # (stopped as soon as the data alone are too large: 200 files took 20 s)
        studies.append(collect(p, with_signals))
        data += data_bytes(studies[-1])
        if data > MAX_BYTES:
            _too_large(
                f"the data of its first {len(studies)} of {len(paths)} files alone take "
                f"{data >> 20} MB",
                with_signals,
            )
    html = render(studies, title or ", ".join(s.label for s in studies))
    size = len(html.encode())
    if size > MAX_BYTES:
        _too_large(f"{size >> 20} MB", with_signals)
    from ..io import atomic_file

    with atomic_file(output) as stream:
        stream.write(html.encode())
    return Path(output), size, [n for s in studies for n in s.notes]
