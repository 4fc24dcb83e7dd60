"""Figures of a simulation and of an optimisation run (``--plot``; see :mod:`suspopt.plots`)."""

from __future__ import annotations

import operator
import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..files import listed
from .panels import draw_front, draw_history, draw_spectra, draw_time_responses, draw_weighted_rms
from .style import (
    COMFORT_WEIGHTING,
    FAILED_VALUE,
    MAX_DESIGNS,
    SAME_STYLE,
    axis_label,
    check_path,
    curve_styles,
    figure_class,
    figure_legend,
    figure_title,
    legend_entries,
    new_figure,
    save,
)

# --- simulate and optimise -----------------------------------------------------------------


def _comfort_signals(names: Sequence[str], units: Mapping[str, str]) -> list[str]:
    """The translational accelerations of ``names`` a person feels (the body, the seat, the
    passenger; not the wheels): those the comfort panel weights."""
    return [n for n in names if units[n] == "m/s^2" and not n.startswith("wheel.")]


def _signal_row(fig, left, right, time, name: str, values, unit: str, labels, styles) -> None:
    """One signal's time history (``left`` grid cell) and Welch PSD (``right``), ``values``
    ``(P, T)`` [unit] over ``time (T,)`` [s]."""
    from ..metrics.spectral import record_psd
    from ..specs import METRICS

    P = len(values)
    fs = 1.0 / float(time[1] - time[0])
    # a signal the designs do not change (the body under a one-way seat) is one curve
    same = P > 1 and all(np.array_equal(v, values[0], equal_nan=True) for v in values)
    drawn, row_labels, row_styles = (
        (values[:1], ["every design"], [SAME_STYLE]) if same else (values, labels, styles)
    )
    ax = fig.add_subplot(left)
    draw_time_responses(
        ax,
        [(label, time, y) for label, y in zip(row_labels, drawn)],
        name,
        unit,
        row_styles,
        legend=False,
    )
    if same:
        ax.set_title(f"the same for all {P} designs", fontsize=9)
    with np.errstate(invalid="ignore"):
        f, spectrum = record_psd(drawn, fs)
    ax = fig.add_subplot(right)
    draw_spectra(
        ax,
        [(label, f, s) for label, s in zip(row_labels, spectrum)],
        "PSD",
        METRICS["var"].unit(unit) + "/Hz",
        styles=row_styles,
        legend=False,
    )
    ax.set_title(f"PSD of {name}", fontsize=9)


def _comfort_panel(ax, signals, comfort: list[str], fs: float, labels, styles) -> None:
    """The ISO 2631-1 weighted r.m.s. of the ``comfort`` signals against the comfort
    reactions, or a note when the sampling rate ``fs`` [Hz] is too low for the weighting."""
    from ..metrics.iso2631 import MIN_SAMPLE_RATE, weighted_rms

    P = len(labels)
    if fs >= MIN_SAMPLE_RATE:
        with np.errstate(invalid="ignore"):
            rms = np.array(
                [
                    weighted_rms(
                        np.asarray(signals[n], dtype=float).reshape(P, -1),
                        fs,
                        COMFORT_WEIGHTING,
                    )
                    for n in comfort
                ]
            )
        draw_weighted_rms(ax, comfort, rms, labels, styles)
        ax.set_title(
            f"ISO 2631-1 {COMFORT_WEIGHTING}-weighted r.m.s. and comfort reactions (Annex C.2.3)",
            fontsize=9,
        )
    else:
        ax.set_axis_off()
        ax.text(
            0.5,
            0.5,
            f"no ISO 2631-1 weighted r.m.s.: the signals are sampled at "
            f"{fs:g} Hz, the weighting needs {MIN_SAMPLE_RATE:g} Hz or more "
            f"(simulation.output_dt)",
            ha="center",
            va="center",
            fontsize=9,
        )


def simulation_figure(
    time: np.ndarray,
    signals: Mapping[str, np.ndarray],
    units: Mapping[str, str],
    labels: Sequence[str],
    title: str = "",
):
    """The figure of :func:`plot_simulation` from arrays, unsaved: ``signals`` (name ->
    ``(P, T)`` over ``time (T,)`` [s]) with their ``units``, one design per row, ``labels``
    ``(P,)``. One row per signal: its time history (left) and its one-sided Welch PSD
    (right; :func:`suspopt.metrics.spectral.record_psd`, 0.1-30 Hz); then, when
    there are accelerations a person feels (:func:`_comfort_signals`) and the sampling rate
    is at least 100 Hz, their ISO 2631-1 :data:`COMFORT_WEIGHTING`-weighted r.m.s. against
    the comfort reactions (:func:`draw_weighted_rms`). Each design keeps one
    :func:`curve_styles` style throughout; the legend (several designs) is below."""
    time = np.asarray(time, dtype=float)
    if time.size < 2:
        raise ValueError("a simulation figure needs at least two samples")
    if not signals:
        raise ValueError("a simulation figure needs at least one signal")
    fs = 1.0 / float(time[1] - time[0])
    names = list(signals)
    P = len(labels)
    styles = curve_styles(P)
    comfort = _comfort_signals(names, units)
    rows = len(names) + bool(comfort)
    Figure = figure_class()
    fig = Figure(
        figsize=(9.6, 2.5 * len(names) + (2.9 if comfort else 0.0) + 0.6), layout="constrained"
    )
    grid = fig.add_gridspec(rows, 2, height_ratios=[1.0] * len(names) + ([1.15] if comfort else []))
    for r, name in enumerate(names):
        values = np.asarray(signals[name], dtype=float).reshape(P, -1)
        _signal_row(fig, grid[r, 0], grid[r, 1], time, name, values, units[name], labels, styles)
    if comfort:
        _comfort_panel(fig.add_subplot(grid[rows - 1, :]), signals, comfort, fs, labels, styles)
    if P > 1:
        figure_legend(fig, legend_entries(styles, labels))
    figure_title(fig, title)
    return fig


def short_names(paths: Sequence[str]) -> list[str]:
    """The shortest tails of dotted ``paths`` that tell them apart, each of two components
    at least and holding its corner: ``vehicle.corners.F1.damper.c`` -> ``F1.damper.c``,
    ``vehicle.body.mass`` -> ``body.mass``."""
    parts = [p.split(".") for p in paths]
    least = [max(2, len(p) - p.index("corners") - 1) if "corners" in p[:-1] else 2 for p in parts]
    for k in range(2, max((len(p) for p in parts), default=2) + 1):
        tails = [".".join(p[-max(k, n) :]) for p, n in zip(parts, least)]
        if len(set(tails)) == len(tails):
            return tails
    return list(paths)


def varying_parameters(designs: Mapping[str, np.ndarray], P: int) -> list[str]:
    """The parameters of ``designs`` (dotted path -> (P,) values) whose values differ
    between the P designs, in their order."""
    return [
        k
        for k, v in designs.items()
        if np.size(v) == P and P > 1 and np.ptp(np.asarray(v, dtype=float)) > 0
    ]


def design_labels(
    designs: Mapping[str, np.ndarray],
    chosen: Sequence[int],
    P: int,
    diverged_at: np.ndarray,
    names: Sequence[str] | None = None,
) -> list[str]:
    """Each chosen design's name (``names[i]``, e.g. the pick it came from; default ``#i``),
    the parameters that vary over the P designs (three at most), and where it diverged."""
    varying = varying_parameters(designs, P)
    short = short_names(varying)
    labels = []
    for i in chosen:
        label = str(names[i]) if names is not None else "design" if P == 1 else f"#{i}"
        values = [
            f"{s}={float(np.asarray(designs[k])[i]):.4g}" for s, k in zip(short[:3], varying[:3])
        ]
        if values:
            label += " " + ", ".join(values) + (", ..." if len(varying) > 3 else "")
        if np.isfinite(diverged_at[i]):
            label += f" (diverged at {diverged_at[i]:.3g} s)"
        labels.append(label)
    return labels


def default_signals(result) -> list[str]:
    """The signals :func:`plot_simulation` draws unless told: body heave acceleration,
    suspension travel and tyre deflection of each corner, and the seat's and the head's
    acceleration where there is a seat (and a passenger)."""
    names = result.signals
    out = [n for n in ("body.heave_acc",) if n in names]
    out += [n for n in names if n.startswith("travel.")]
    out += [n for n in names if n.startswith("tyre_deflection.")]
    out += [n for n in ("seat.acc", "head.acc") if n in names]
    return out


def evenly_spaced(P: int, most: int) -> list[int]:
    """At most ``most`` of the design indices 0 to P - 1, evenly spaced by index, the first
    and the last included (all of them when there are no more than ``most``)."""
    if most >= P or most < 2:
        return list(range(min(P, most)))
    return sorted({int(round(x)) for x in np.linspace(0, P - 1, most)})


def chosen_designs(P: int, designs: Sequence[int] | None) -> tuple[list[int], str]:
    """The design indices to draw and a note when they are not all of them."""
    if designs is None:
        if P <= MAX_DESIGNS:
            return list(range(P)), ""
        chosen = evenly_spaced(P, MAX_DESIGNS)
        return chosen, (
            f"{len(chosen)} of {P} designs drawn (evenly spaced by index; at "
            f"most {MAX_DESIGNS} on one figure)"
        )
    try:  # (int() took 0.5 for design 0)
        chosen = [operator.index(i) for i in listed(designs)]
    except TypeError:
        raise ValueError(f"designs: give design indices, whole numbers; got {designs!r}") from None
    if not chosen:
        raise ValueError("designs: choose at least one design")
    if len(chosen) > MAX_DESIGNS:
        raise ValueError(f"designs: {len(chosen)} designs; at most {MAX_DESIGNS} fit on one figure")
    if len(set(chosen)) != len(chosen):
        raise ValueError("designs: a design is chosen twice")
    bad = [i for i in chosen if not 0 <= i < P]
    if bad:
        raise ValueError(
            f"designs: {', '.join(map(str, bad))} out of range: the result has "
            f"{P} design{'s' if P > 1 else ''} (0 to {P - 1})"
        )
    return chosen, "" if len(chosen) == P else f"{len(chosen)} of {P} designs drawn"


def plot_simulation(
    result,
    path: str | Path,
    signals: Sequence[str] | None = None,
    designs: Sequence[int] | None = None,
    design_names: Sequence[str] | None = None,
) -> Path:
    """Draw :func:`result_figure` of a :class:`suspopt.simulation.Result` to ``path`` (.png or
    .svg; ``suspopt simulate --plot``)."""
    path = check_path(path)
    return save(result_figure(result, signals, designs, design_names), path)


def result_figure(
    result,
    signals: Sequence[str] | None = None,
    designs: Sequence[int] | None = None,
    design_names: Sequence[str] | None = None,
):
    """The figure of a :class:`suspopt.simulation.Result` (:func:`simulation_figure`),
    unsaved: ``signals`` (default :func:`default_signals`) of the ``designs`` (indices;
    default every design, or :data:`MAX_DESIGNS` of them evenly spaced by index when there
    are more, which the title says). ``design_names`` (one per design of the result, e.g. the
    picks they came from) name the designs in the legend instead of ``#i``. ValueError for
    an unknown signal, a design out of range, more than :data:`MAX_DESIGNS` designs, design
    names that are not one text per design, or no matplotlib. :meth:`suspopt.Result.plot`
    and ``suspopt simulate --plot`` (:func:`plot_simulation`) draw it."""
    import difflib

    from ..errors import require_like

    require_like(result, "Result", ("signals", "time", "P"), "result", "from suspopt.simulate(cfg)")
    names = listed(signals) if signals is not None else default_signals(result)  # (one name: str)
    for name in names:
        if name not in result.signals:
            close = difflib.get_close_matches(name, list(result.signals), n=3)
            raise ValueError(
                f"unknown signal {name!r}"
                + (f"; did you mean {', '.join(close)}?" if close else "")
            )
    P = result.P
    if design_names is not None:
        design_names = listed(design_names)
        if len(design_names) != P or not all(isinstance(n, str) for n in design_names):
            raise ValueError(
                f"design_names: give one text per design ({P}); got {design_names!r:.200}"
            )
    chosen, note = chosen_designs(P, designs)
    labels = design_labels(result.designs, chosen, P, np.asarray(result.diverged_at), design_names)
    cfg = result.config
    source = cfg.source.name if getattr(cfg, "source", None) else "simulation"
    title = f"{source}: road {cfg.road.kind}, {P} design{'s' if P > 1 else ''}" + (
        f"; {note}" if note else ""
    )
    data = {name: np.asarray(result.signals[name])[chosen] for name in names}
    fig = simulation_figure(
        result.time, data, {n: result.signal_unit(n) for n in names}, labels, title
    )
    return fig


def optimisation_figure(
    F: np.ndarray,
    G: np.ndarray,
    names: Sequence[str],
    units: Sequence[str],
    history: Mapping[str, np.ndarray],
    title: str = "",
    weights: np.ndarray | None = None,
    marks: Mapping[str, int] | None = None,
):
    """The figure of :func:`plot_optimisation` from arrays, unsaved: the optimum ``F (N,
    m)`` with constraints ``G (N, k)`` (G <= 0 feasible) over objectives ``names`` and
    ``units``, and the ``history`` of ``/history`` (generation, best, hypervolume,
    feasible, ...); ``marks`` (name -> row of F) starred on each pair's panel, the names
    of one design in one label.

    Two objectives or more: the front as every pair of objectives (one panel for two, a
    panel per pair for more; feasible designs filled, infeasible ones hollow), then the
    hypervolume and the feasible share per generation. One objective, or a weighted sum
    (``weights``): the best value per generation (the weighted sum's; the panel's title
    gives the best design's objectives) and the feasible share. Failed designs (objectives
    of 1e10) are not drawn; the title counts them."""
    F = np.atleast_2d(np.asarray(F, dtype=float))
    G = np.asarray(G, dtype=float).reshape(len(F), -1)
    m = F.shape[1]
    failed = (F >= FAILED_VALUE).any(axis=1)
    feasible = np.asarray((G <= 0).all(axis=1) & ~failed)
    generation = np.asarray(history["generation"], dtype=float)
    share = np.asarray(history["feasible"], dtype=float)
    single = m == 1 or weights is not None
    if single:
        fig, axes = new_figure(2, columns=2, panel_size=(4.8, 3.4))
        best = np.asarray(history["best"], dtype=float).reshape(len(generation), -1)[:, 0]
        name, unit = (names[0], units[0]) if weights is None else ("weighted sum", "1")
        summary = None
        if (~failed).any():
            k = int(np.flatnonzero(~failed)[0])
            values = ", ".join(
                f"{n} = {F[k, j]:.4g}" + ("" if u in ("", "1") else f" {u}")
                for j, (n, u) in enumerate(zip(names, units))
            )
            summary = "\n".join(
                textwrap.wrap(f"best design{'' if feasible[k] else ' (infeasible)'}: {values}", 60)
            )
        draw_history(axes[0], generation, best, f"best {name}", unit, summary)
    else:
        pairs = [(i, j) for i in range(m) for j in range(i + 1, m)]
        by_row: dict[int, list[str]] = {}  # (one label per design: "best_f1, knee")
        for name, k in (marks or {}).items():
            by_row.setdefault(int(k), []).append(name)
        fig, axes = new_figure(len(pairs) + 2, columns=3, panel_size=(4.2, 3.4))
        other = ~feasible & ~failed
        for ax, (i, j) in zip(axes, pairs):
            fronts = [("feasible", F[feasible, i], F[feasible, j])]
            if other.any():
                fronts.append(("infeasible (a constraint G > 0)", F[other, i], F[other, j]))
            draw_front(
                ax,
                fronts,
                axis_label(names[i], units[i]),
                axis_label(names[j], units[j]),
                {", ".join(named): (F[k, i], F[k, j]) for k, named in by_row.items()},
                legend=False,
            )
            ax.ticklabel_format(style="sci", scilimits=(-3, 4), useMathText=True)
        draw_history(
            axes[len(pairs)], generation, history["hypervolume"], "hypervolume (normalised)", "1"
        )
        figure_legend(fig, axes[0])
    ax = axes[-1]
    draw_history(ax, generation, share, "feasible share", "1")
    ax.set_ylim(-0.05, 1.05)
    if failed.any():
        title += f" ({int(failed.sum())} failed design{'s' if failed.sum() > 1 else ''} not drawn)"
    figure_title(fig, title)
    return fig


def _check_picks(picks: Mapping[str, int] | None, N: int) -> None:
    """ValueError unless every pick of ``picks`` (name -> row) is a row of a front of ``N``."""
    for name, row in (picks or {}).items():
        if isinstance(row, bool) or not isinstance(row, (int, np.integer)) or not 0 <= row < N:
            raise ValueError(f"picks: {name!r}: {row!r} is not a row of the front (0 to {N - 1})")


def pareto_set_figure(pareto, picks: Mapping[str, int] | None = None):
    """The figure of :func:`optimisation_figure` for a :class:`suspopt.choosing.selection.ParetoSet`
    read from a file (:meth:`suspopt.choosing.selection.ParetoSet.plot`), unsaved: its front, with
    the file's ``/history`` (hypervolume and feasible share per generation) where it holds
    one, else empty history panels; ``picks`` (name -> row of the set) starred and named."""
    from ..h5read import H5Reader

    F = np.atleast_2d(pareto.F)
    N, m = F.shape
    _check_picks(picks, N)
    keys = ("generation", "hypervolume", "feasible")
    history: dict = {key: np.empty(0) for key in keys} | {"best": np.empty((0, m))}
    with H5Reader(pareto.path) as h5:
        if all(h5._node(f"history/{key}") is not None for key in keys):
            found = {key: h5.array(f"history/{key}", ndim=1) for key in keys}
            if len({len(v) for v in found.values()}) == 1:
                history.update(found)
    units = pareto.obj_units if pareto.obj_units is not None else [""] * m
    G = pareto.G if pareto.G is not None else np.zeros((N, 0))
    title = f"{Path(pareto.path).name}: {N} design{'s' if N != 1 else ''} of the set"
    return optimisation_figure(F, G, pareto.obj_names, units, history, title, None, picks)


def plot_optimisation(result, path: str | Path) -> Path:
    """Draw :func:`optimisation_result_figure` of a
    :class:`suspopt.optimisation.OptimisationResult` to ``path`` (.png or .svg; ``suspopt
    optimise --plot``)."""
    path = check_path(path)
    return save(optimisation_result_figure(result), path)


def optimisation_result_figure(result, picks: Mapping[str, int] | None = None):
    """The figure of a :class:`suspopt.optimisation.OptimisationResult`
    (:func:`optimisation_figure`), unsaved: the front or the best value, and the history per
    generation; ``picks`` (name -> row of the front, e.g. :func:`suspopt.pareto_picks`)
    starred and named on the front. :meth:`suspopt.optimisation.OptimisationResult.plot` and
    ``suspopt optimise --plot`` (:func:`plot_optimisation`) draw it."""
    from ..errors import require_like

    require_like(
        result,
        "OptimisationResult",
        ("F", "G", "history", "weights"),
        "result",
        "from suspopt.optimise(cfg, path)",
    )
    _check_picks(picks, len(np.atleast_2d(result.F)))
    history = result.history
    generations = len(np.atleast_1d(history["generation"]))
    evaluations = int(history["evaluations"][-1]) if generations else 0
    N, m = np.atleast_2d(result.F).shape
    what = (
        "best design"
        if (m == 1 or result.weights is not None)
        else f"{N} design{'s' if N > 1 else ''} on the front"
    )
    title = (
        f"{Path(result.path).name} ({result.status}): {what}, {generations} "
        f"generation{'s' if generations != 1 else ''}, {evaluations} evaluations"
    )
    fig = optimisation_figure(
        result.F,
        result.G,
        result.obj_names,
        result.obj_units,
        history,
        title,
        result.weights,
        picks,
    )
    return fig
