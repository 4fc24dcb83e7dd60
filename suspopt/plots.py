"""Figures of the analyses, drawn from arrays (matplotlib, optional: ``pip install
'suspopt[plot]'``).

The analyses compute and write HDF5; this module draws what they hand it, so a figure can be
redrawn from a file (the simulation figure computes the Welch PSDs and ISO 2631-1 weighted
r.m.s. of the signals it is handed, with :mod:`suspopt.metrics`). Panel functions (``draw_*``) draw on one matplotlib ``Axes``; figure
functions lay panels out and :func:`save` writes the file, atomically (a temporary name, then
a rename), as PNG or SVG by its suffix. No pyplot: figures are ``matplotlib.figure.Figure``
objects, so nothing depends on a display or on global state; matplotlib is imported inside
the functions only (importing this module costs nothing). Each ``plot_*`` figure has a
``*_figure`` twin that returns the ``Figure`` unsaved.

Several curves on one panel (models, designs) get :func:`curve_styles`: colour, line style,
line width (the first curve widest and drawn underneath, the last narrowest on top) and a
marker shape at staggered positions (:func:`mark_indices`), so that curves which coincide
stay distinguishable; the data are never offset. A figure has one legend, below its panels,
never on the data; layouts are constrained (labels never overlap) and titles wrap.

Figures of the thesis they correspond to:

- :func:`model_comparison`: time responses and body-acceleration PSD of several models
  (Figs. 3.2-3.8, 3.9-3.15, 3.17-3.24);
- :func:`pareto_fronts`: a Pareto front and its pseudo-fronts (Figs. 7.4b, 8.22-8.24) with
  chosen designs marked, and the design variables along the front (Figs. 8.11-8.20);
- :func:`sensitivity`: the CDF threshold sweep (Figs. 4.7, 4.10);
- :func:`transmissibilities`: seat transmissibility and STHT (Eq 2.86, Figs. 2.18b, 8.26);
- :func:`plot_kesort`: the k-ε levels over a front (Figs. 6.7, 7.5, 7.6), from a
  :class:`suspopt.selection.Selection`;
- :func:`plot_simulation`: a :class:`suspopt.simulate.Result`'s signals over time, their
  Welch PSD and the ISO 2631-1 weighted r.m.s. of its accelerations against the comfort
  reactions (Annex C.2.3), one or several designs (``suspopt simulate --plot``);
- :func:`plot_optimisation`: an :class:`suspopt.optimise.OptimisationResult`'s front (or
  best value) and its history per generation (``suspopt optimise --plot``).
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from .metrics import COMFORT_REACTIONS

__all__ = ["FORMATS", "MAX_DESIGNS", "PSD_SEGMENT", "check_path", "new_figure", "save",
           "curve_styles", "mark_indices", "draw_time_responses", "draw_spectra",
           "draw_front", "draw_design_variable", "draw_comfort_levels", "draw_weighted_rms",
           "draw_history", "model_comparison", "model_figure", "pareto_fronts", "sensitivity",
           "transmissibilities", "plot_kesort", "simulation_figure", "plot_simulation",
           "default_signals", "optimisation_figure", "plot_optimisation"]

#: Figure formats, by file suffix.
FORMATS = {".png": "png", ".svg": "svg"}
#: Line styles cycled with the colours (solid first, then dashes of distinct rhythms).
_LINES = ("-", (0, (6, 2)), (0, (2, 1.5)), (0, (7, 2, 1.5, 2)), (0, (1, 1)),
          (0, (4, 1.5, 1, 1.5, 1, 1.5)))
#: Marker shapes cycled with the colours.
_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*", "<", ">")
#: Markers per curve, spread evenly along the x axis.
MARKS_PER_CURVE = 10
#: Line width of the curve drawn last (on top) [pt]; the ones under it are wider.
_THINNEST = 1.0
#: The style of one curve that stands for every design.
_SAME = dict(color="k", ls="-", lw=1.0)
#: Designs drawn at most on one simulation figure (more are unreadable).
MAX_DESIGNS = 8
#: Welch segment of the simulation figure's PSDs [s] (at most the record), as analyse models.
PSD_SEGMENT = 8.0
#: The ISO 2631-1 weighting of the simulation figure's comfort panel (vertical, seated).
COMFORT_WEIGHTING = "Wk"
#: Fewest line heights between two comfort-level labels (closer ones are left out).
_LABEL_GAP = 1.1
#: Objectives at or above this are failed designs (suspopt.optimise.problem.PENALTY).
_FAILED = 1e10


def check_path(path: str | Path) -> Path:
    """``path`` if its suffix names a known format (.png, .svg), else ValueError; call it
    before computing, so that a bad name fails before anything is written."""
    path = Path(path)
    if path.suffix.lower() not in FORMATS:
        raise ValueError(f"--plot {path}: the figure's suffix must be one of "
                         f"{', '.join(FORMATS)}")
    return path


def _figure_class():
    """matplotlib's ``Figure``, or ValueError naming the extra to install."""
    try:
        from matplotlib.figure import Figure
    except ImportError:
        raise ValueError("--plot needs matplotlib: pip install 'suspopt[plot]'") from None
    return Figure


def new_figure(panels: int, columns: int = 2, panel_size: tuple[float, float] = (4.6, 3.2)):
    """A figure with ``panels`` axes on a grid of ``columns``; returns (figure, [axes])."""
    Figure = _figure_class()
    columns = max(1, min(columns, panels))
    rows = math.ceil(panels / columns)
    fig = Figure(figsize=(panel_size[0] * columns, panel_size[1] * rows), layout="constrained")
    grid = fig.subplots(rows, columns, squeeze=False)
    axes = list(grid.ravel())
    for ax in axes[panels:]:
        ax.set_visible(False)
    return fig, axes[:panels]


def save(fig, path: str | Path, dpi: int = 120) -> Path:
    """Write ``fig`` to ``path`` (format from the suffix) atomically
    (:func:`suspopt.io.atomic_file`: a failed write never leaves a broken figure), marked as
    suspopt's in its metadata."""
    from . import __version__
    from .io import OUTPUT_MARKER, atomic_file

    path = check_path(path)
    kind = FORMATS[path.suffix.lower()]
    mark = f"{OUTPUT_MARKER} {__version__}"
    metadata = {"Software": mark} if kind == "png" else {"Creator": mark}
    with atomic_file(path) as stream:
        fig.savefig(stream, format=kind, dpi=dpi, metadata=metadata)
    return path


def _axis_label(name: str, unit: str) -> str:
    """``name [unit]``; a dimensionless unit ("1") as ``[-]``."""
    if unit == "1":
        unit = "-"
    return f"{name} [{unit}]" if unit else name


def curve_styles(n: int) -> list[dict]:
    """Styles (``Axes.plot`` keywords) of ``n`` curves on one panel that may coincide: a
    colour, a line style and a marker shape each, and widths from the widest (the first,
    drawn underneath) to :data:`_THINNEST` (the last, on top), so that every curve still shows
    at the edges of those drawn over it. One curve gets a plain line."""
    if n <= 1:
        return [dict(color="C0", ls="-", lw=1.2)]
    step = min(0.7, 2.4 / (n - 1))
    return [dict(color=f"C{i % 10}", ls=_LINES[i % len(_LINES)],
                 lw=_THINNEST + step * (n - 1 - i), marker=_MARKERS[i % len(_MARKERS)],
                 ms=4.5, mec=f"C{i % 10}") for i in range(n)]


def mark_indices(x: np.ndarray, i: int, n: int, count: int = MARKS_PER_CURVE,
                 log: bool = False) -> np.ndarray:
    """Sample indices at which curve ``i`` of ``n`` over the ascending ``x`` gets its
    markers: ``count`` points evenly spaced along x (in log10 x if ``log``), shifted by
    ``(i + 1/2)/n`` of a spacing, so that the markers of coinciding curves interleave. A
    point is the sample nearest to it, and is left out where the samples are sparser than
    the points of all ``n`` curves (the sample is nearer to another curve's point): curves
    over the same x never share a marked sample."""
    x = np.asarray(x, dtype=float)
    valid = np.isfinite(x) & (x > 0 if log else True)
    where = np.flatnonzero(valid)
    if n <= 1 or where.size < 2:
        return np.empty(0, dtype=int)
    u = np.log10(x[where]) if log else x[where]
    slot = (u[-1] - u[0]) / (count * n)
    targets = u[0] + (np.arange(count) * n + i + 0.5) * slot
    right = np.clip(np.searchsorted(u, targets), 1, u.size - 1)
    nearest = np.where(targets - u[right - 1] <= u[right] - targets, right - 1, right)
    keep = np.abs(u[nearest] - targets) < 0.5 * slot
    return where[nearest[keep]]


def _draw_curves(ax, series: Sequence[tuple[str, np.ndarray, np.ndarray]],
                 styles: Sequence[dict] | None, log: bool) -> None:
    """``(label, x, y)`` curves in ``styles`` (default :func:`curve_styles`), markers at
    :func:`mark_indices`."""
    styles = list(styles) if styles is not None else curve_styles(len(series))
    n = len(styles)
    for i, ((label, x, y), style) in enumerate(zip(series, styles)):
        if "marker" in style:
            style = dict(style, markevery=list(mark_indices(x, i, n, log=log)))
        ax.plot(x, y, label=label, **style)


def _legend_columns(fig, labels: Sequence[str], fontsize: float) -> int:
    """Legend columns that fit the figure's width (labels of ~0.6 em a character, a handle of
    ~3 em and a gap)."""
    width = fig.get_figwidth() * 72.0
    entry = (max((len(s) for s in labels), default=1) * 0.6 + 4.5) * fontsize
    return max(1, min(len(labels), int(width // entry)))


def _figure_legend(fig, entries, fontsize: float = 8) -> None:
    """One legend for the figure, with the entries of an axes, or ``entries`` ``(handles,
    labels)``: in the grid's first unused cell when there is one, else below all panels;
    outside the panels either way, so it never hides data."""
    handles, labels = entries if isinstance(entries, tuple) else \
        entries.get_legend_handles_labels()
    if not handles:
        return
    spare = [a for a in fig.axes if not a.get_visible()]
    if spare:
        cell = spare[0]
        cell.set_visible(True)
        cell.set_axis_off()
        cell.legend(handles, labels, loc="center", fontsize=fontsize, frameon=False,
                    ncols=1 if len(labels) <= 12 else 2)
        return
    fig.legend(handles, labels, loc="outside lower center", fontsize=fontsize,
               ncols=_legend_columns(fig, labels, fontsize), frameon=False)


def _legend_entries(styles: Sequence[dict], labels: Sequence[str]) -> tuple[list, list]:
    """Legend handles (lines without data) of curves drawn in ``styles``."""
    from matplotlib.lines import Line2D

    return [Line2D([], [], **style) for style in styles], list(labels)


def _title(fig, text: str, fontsize: float = 11) -> None:
    """``text`` as the figure's title, wrapped to the figure's width."""
    chars = max(20, int(fig.get_figwidth() * 72.0 / (0.58 * fontsize)))
    fig.suptitle("\n".join(textwrap.wrap(text, chars)) if text else "", fontsize=fontsize)


# --- panels --------------------------------------------------------------------------------

def draw_time_responses(ax, series: Sequence[tuple[str, np.ndarray, np.ndarray]],
                        name: str, unit: str, styles: Sequence[dict] | None = None,
                        legend: bool = True) -> None:
    """Time histories ``(label, t [s], y)`` of one signal, one line per label, in ``styles``
    (default :func:`curve_styles`); ``legend`` False leaves it to the figure."""
    _draw_curves(ax, series, styles, log=False)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(_axis_label(name, unit))
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(fontsize=8)


def draw_spectra(ax, series: Sequence[tuple[str, np.ndarray, np.ndarray]], name: str,
                 unit: str, f_range: tuple[float, float] = (0.1, 30.0),
                 styles: Sequence[dict] | None = None, legend: bool = True) -> None:
    """Spectra ``(label, f [Hz], value)`` on log-log axes, within ``f_range``, in ``styles``
    (default :func:`curve_styles`); ``legend`` False leaves it to the figure."""
    band = [(label, f[(f >= f_range[0]) & (f <= f_range[1])],
             value[(f >= f_range[0]) & (f <= f_range[1])]) for label, f, value in series]
    # zeros (a signal at rest) have no logarithm: masked, not drawn
    band = [(label, f, np.where(v > 0, v, np.nan)) for label, f, v in band]
    _draw_curves(ax, band, styles, log=True)
    ax.set_xscale("log")
    if any(np.isfinite(v).any() for _l, _f, v in band):
        ax.set_yscale("log")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(_axis_label(name, unit))
    ax.grid(True, which="both", alpha=0.3)
    if legend:
        ax.legend(fontsize=8)


def _spaced(positions: Sequence[float], gap: float) -> list[bool]:
    """Which of the ascending ``positions`` (axes fractions) to label: each at least
    ``gap`` from the previous one labelled."""
    keep, last = [], -math.inf
    for p in positions:
        keep.append(p - last >= gap)
        if keep[-1]:
            last = p
    return keep


def draw_comfort_levels(ax, axis: str = "x", outside: bool = False) -> None:
    """ISO 2631-1 comfort reactions (Annex C.2.3) as lines at the bands' lower edges within
    the current limits of a weighted-r.m.s. axis (Fig. 8.23), labelled with their wording:
    inside the panel along the lines, or with ``outside`` as the tick labels of a secondary
    axis (top for x, right for y), never on the data. A label closer than ``_LABEL_GAP``
    line heights to the previous one is left out (its line stays)."""
    from matplotlib.ticker import NullLocator

    vertical = axis == "x"
    low, high = ax.get_xlim() if vertical else ax.get_ylim()
    edges = [(lower, label) for lower, _upper, label in COMFORT_REACTIONS[1:]
             if low < lower < high]
    line = ax.axvline if vertical else ax.axhline
    for lower, _label in edges:
        line(lower, color="0.5", ls=":", lw=0.8, zorder=1)
    to_axes = ax.transAxes.inverted()
    fraction = [to_axes.transform(ax.transData.transform(
        (lower, 1.0) if vertical else (1.0, lower)))[0 if vertical else 1]
        for lower, _label in edges]
    # a label needs _LABEL_GAP line heights (1.2 font sizes) along the axis; the axes' size
    # is taken before the constrained layout shrinks it a little
    box = ax.get_position()
    length = (box.width * ax.figure.get_figwidth() if vertical else
              box.height * ax.figure.get_figheight())
    gap = _LABEL_GAP * 1.2 * (7 if outside else 6) / 72.0 / max(length, 1e-3)
    edges = [edge for edge, keep in zip(edges, _spaced(fraction, gap)) if keep]
    if outside:
        second = ax.secondary_xaxis("top") if vertical else ax.secondary_yaxis("right")
        target = second.xaxis if vertical else second.yaxis
        target.set_ticks([lower for lower, _label in edges],
                         [label for _lower, label in edges])
        target.set_minor_locator(NullLocator())
        second.tick_params(labelsize=7, colors="0.35", length=2)
        if vertical:
            second.tick_params(labelrotation=90)
        return
    for lower, label in edges:
        x, y = (lower, 1.0) if vertical else (1.0, lower)
        ax.annotate(label, (x, y), xycoords=("data", "axes fraction") if vertical else
                    ("axes fraction", "data"), fontsize=6, color="0.4",
                    rotation=90 if vertical else 0, ha="right", va="top")


def draw_front(ax, fronts: Sequence[tuple[str, np.ndarray, np.ndarray]], x_label: str,
               y_label: str, marks: Mapping[str, tuple[float, float]] | None = None,
               comfort: bool = False, legend: bool = True) -> None:
    """Fronts ``(label, x (N,), y (N,))`` as points, the first one (the optimised front)
    filled, the others (pseudo-fronts) hollow; ``marks`` (name -> (x, y)) as labelled stars;
    ``comfort`` draws the ISO 2631-1 levels on the x axis; ``legend`` False leaves the
    legend to the figure."""
    for i, (label, x, y) in enumerate(fronts):
        style = dict(s=18, label=label)
        if i:
            style.update(facecolors="none", edgecolors=f"C{i}")
        else:
            style.update(color="C0")
        ax.scatter(x, y, **style)
    for name, (x, y) in (marks or {}).items():
        ax.scatter([x], [y], marker="*", s=120, color="k", zorder=5)
        ax.annotate(name, (x, y), textcoords="offset points", xytext=(5, 5), fontsize=8)
    if comfort:
        draw_comfort_levels(ax, "x")
    ax.set_xlabel(x_label)
    ax.set_ylabel(y_label)
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(fontsize=8)


def draw_design_variable(ax, objective: np.ndarray, values: np.ndarray, x_label: str,
                         y_label: str) -> None:
    """One design variable along the front against an objective (Figs. 8.11-8.20)."""
    order = np.argsort(objective, kind="stable")
    ax.plot(objective[order], values[order], "o-", ms=3, lw=0.8)
    ax.set_xlabel(x_label)
    ax.set_ylabel(y_label)
    ax.grid(alpha=0.3)


def draw_weighted_rms(ax, names: Sequence[str], values: np.ndarray,
                      labels: Sequence[str], styles: Sequence[dict] | None = None,
                      weighting: str = COMFORT_WEIGHTING) -> None:
    """ISO 2631-1 weighted r.m.s. ``values (S, P)`` [m/s^2] of ``S`` accelerations ``names``
    for ``P`` designs ``labels``: one point per design beside the others at each signal, in
    the designs' colours and markers (``styles``), on a log axis that spans at least the
    first three comfort reactions, which :func:`draw_comfort_levels` draws and names at the
    right. Non-finite values (a diverged design) are left out."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    values = np.atleast_2d(np.asarray(values, dtype=float))
    S, P = values.shape
    styles = list(styles) if styles is not None else curve_styles(P)
    width = 0.6 / P
    for j, (label, style) in enumerate(zip(labels, styles)):
        x = np.arange(S) + (j - (P - 1) / 2) * width
        ax.plot(x, values[:, j], ls="none", marker=style.get("marker", "o"), ms=6,
                color=style["color"], mec=style.get("mec", style["color"]), label=label)
        if P <= 3:
            for xi, v in zip(x, values[:, j]):
                if np.isfinite(v):
                    ax.annotate(f"{v:.3g}", (xi, v), textcoords="offset points",
                                xytext=(6, 0), va="center", fontsize=7)
    finite = values[np.isfinite(values) & (values > 0)]
    low = min(0.2, 0.7 * finite.min()) if finite.size else 0.2
    high = max(1.0, 1.4 * finite.max()) if finite.size else 1.0
    ax.set_yscale("log")
    ax.set_ylim(low, high)
    ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _pos: f"{v:g}"))
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.set_xlim(-0.5, S - 0.5 + (0.35 if P <= 3 else 0.0))
    ax.set_xticks(range(S), list(names))
    ax.set_ylabel(_axis_label(f"{weighting}-weighted r.m.s.", "m/s^2"))
    ax.grid(True, axis="y", which="both", alpha=0.3)
    draw_comfort_levels(ax, "y", outside=True)


def draw_history(ax, generation: np.ndarray, values: np.ndarray, name: str,
                 unit: str, title: str | None = None) -> None:
    """``values`` per ``generation`` (NaN where there is none yet, e.g. no feasible design)
    as a line with points over every generation; the panel's title is ``title``, by default
    the last finite value."""
    from matplotlib.ticker import MaxNLocator

    generation = np.asarray(generation, dtype=float)
    values = np.asarray(values, dtype=float)
    ax.plot(generation, values, "o-", ms=3, lw=1.0, color="C0")
    ok = np.flatnonzero(np.isfinite(values))
    if title is None and ok.size:
        k = ok[-1]
        title = f"generation {generation[k]:g}: {values[k]:.4g}" + \
            ("" if unit in ("", "1") else f" {unit}")
    if not ok.size:
        ax.text(0.5, 0.5, "none yet", transform=ax.transAxes, ha="center", va="center",
                color="0.4")
    if title:
        ax.set_title(title, fontsize=9)
    if generation.size:
        low, high = float(generation.min()), float(generation.max())
        pad = max(0.5, 0.04 * (high - low))
        ax.set_xlim(low - pad, high + pad)
    ax.set_xlabel("generation [-]")
    ax.set_ylabel(_axis_label(name, unit))
    ax.grid(alpha=0.3)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))


# --- figures -------------------------------------------------------------------------------

def model_figure(title: str,
                 time_series: Mapping[str, Sequence[tuple[str, np.ndarray, np.ndarray]]],
                 spectra: Mapping[str, Sequence[tuple[str, np.ndarray, np.ndarray]]],
                 units: Mapping[str, str]):
    """The figure of :func:`model_comparison`, unsaved: every series lists the models in
    the same order, so each model has one :func:`curve_styles` style in every panel; the one
    legend is below the panels."""
    fig, axes = new_figure(len(time_series) + len(spectra))
    for ax, (name, series) in zip(axes, time_series.items()):
        draw_time_responses(ax, series, name, units[name], legend=False)
    for ax, (name, series) in zip(axes[len(time_series):], spectra.items()):
        draw_spectra(ax, series, "PSD", units[f"PSD of {name}"], legend=False)
        ax.set_title(f"PSD of {name}", fontsize=9)
    if axes:
        _figure_legend(fig, axes[0])
    _title(fig, title)
    return fig


def model_comparison(path: str | Path, title: str,
                     time_series: Mapping[str, Sequence[tuple[str, np.ndarray, np.ndarray]]],
                     spectra: Mapping[str, Sequence[tuple[str, np.ndarray, np.ndarray]]],
                     units: Mapping[str, str]) -> Path:
    """Several models side by side: one panel per signal of ``time_series`` (name -> series
    of ``(model, t, y)``) and one per spectrum of ``spectra`` (name -> ``(model, f, PSD)``);
    ``units`` maps each name to its unit. Models whose curves coincide stay distinguishable
    (:func:`curve_styles`); one legend below the panels (:func:`model_figure`)."""
    path = check_path(path)
    return save(model_figure(title, time_series, spectra, units), path)


def pareto_fronts(path: str | Path, title: str, objectives: Sequence[tuple[str, str]],
                  fronts: Sequence[tuple[str, np.ndarray]],
                  variables: Sequence[tuple[str, str, np.ndarray]] = (),
                  marks: Mapping[str, int] | None = None,
                  comfort: Sequence[bool] | None = None) -> Path:
    """Fronts ``(label, F (N, m))`` over ``objectives`` ``(name, unit)`` - the first the
    optimised front, the rest pseudo-fronts of the same designs - as the first objective
    against each other one (Figs. 7.5, 8.22-8.24); then each design variable
    ``(name, unit, values (N,))`` of the optimised front against the first objective
    (Figs. 8.11-8.20). ``marks`` (name -> design index) are starred on the optimised front;
    ``comfort[j]`` tells that objective ``j`` is an ISO 2631-1 weighted r.m.s. (its levels
    are drawn when it is the x axis)."""
    m = len(objectives)
    pairs = [(0, j) for j in range(1, m)] or [(0, 0)]
    fig, axes = new_figure(len(pairs) + len(variables), columns=3)
    (x_name, x_unit) = objectives[0]
    x_label = _axis_label(x_name, x_unit)
    for ax, (i, j) in zip(axes, pairs):
        F0 = fronts[0][1]
        points = {name: (F0[k, i], F0[k, j]) for name, k in (marks or {}).items()}
        draw_front(ax, [(label, F[:, i], F[:, j]) for label, F in fronts], x_label,
                   _axis_label(*objectives[j]), points, bool(comfort and comfort[0]))
    F0 = fronts[0][1]
    for ax, (name, unit, values) in zip(axes[len(pairs):], variables):
        draw_design_variable(ax, F0[:, 0], values, x_label, _axis_label(name, unit))
    fig.suptitle(title)
    return save(fig, path)


def sensitivity(path: str | Path, title: str, x: np.ndarray, x_label: str,
                panels: Sequence[Mapping[str, np.ndarray]], y_label: str,
                marker: float | None = None, marker_label: str = "") -> Path:
    """Sensitivity curves: one panel per mapping of ``panels`` (curve name -> (X,) values
    over ``x``), a zero line, and a dashed vertical ``marker`` (e.g. the base law's share)."""
    fig, axes = new_figure(len(panels), columns=1, panel_size=(7.0, 3.0))
    for k, (ax, curves) in enumerate(zip(axes, panels)):
        for name, values in curves.items():
            ax.plot(x, values, "o-", label=name)
        ax.axhline(0, color="0.6", lw=0.8)
        if marker is not None:
            ax.axvline(marker, color="0.4", ls="--", lw=0.8)
        ax.set_ylabel(y_label)
        ax.legend(loc="best")
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel(x_label + (f"; dashed: {marker_label}" if marker_label else ""))
    fig.suptitle(title)
    return save(fig, path)


def transmissibilities(path: str | Path, title: str,
                       lines: Sequence[tuple[str, np.ndarray, np.ndarray]],
                       points: Sequence[tuple[str, np.ndarray, np.ndarray]] = (),
                       f_range: tuple[float, float] = (0.1, 30.0)) -> Path:
    """Transmissibility magnitudes [-] on a log frequency axis: ``lines`` ``(label, f, T)``
    (e.g. linearised) as lines, ``points`` (e.g. simulated, H1, where coherent) as dots in
    the colours of the lines of the same position."""
    fig, (ax,) = new_figure(1, panel_size=(7.0, 4.5))
    for i, (label, f, value) in enumerate(lines):
        ax.plot(f, value, color=f"C{i}", label=label)
    for i, (label, f, value) in enumerate(points):
        ax.plot(f, value, ".", color=f"C{i}", ms=3, label=label)
    ax.set_xscale("log")
    ax.set_xlim(*f_range)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("acceleration transmissibility [-]")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return save(fig, path)


def plot_kesort(selection, path: str | Path) -> Path:
    """The k-ε levels over the front (Fig. 6.7, 7.5, 7.6) of a
    :class:`suspopt.selection.Selection`.

    Left: the first two objectives (the main ones of Ch. 6-7, Fig. 7.5a/7.6), one marker per
    case, coloured by the pool's k-ε level; the pool's optimum is a star, each case's own
    optimum an open square, the Pareto picks (edges and knee, Fig. 8.21) are labelled. Right:
    the k-ε level of every design against the first objective (Fig. 6.7). With one objective
    only the right panel is drawn.
    """
    s, path = selection, check_path(path)
    F, levels, names, units = s.F, s.sort.k_eps, s.names, s.units
    markers = "os^Dv<>phX*"
    two = F.shape[1] > 1
    fig, axes = new_figure(2 if two else 1, panel_size=(6.0, 5.0))
    front, level_ax = (axes[0], axes[1]) if two else (None, axes[0])
    lo, hi = float(levels.min()), float(levels.max())
    for c, label in enumerate(s.cases):
        rows = s.case == label
        style = dict(marker=markers[c % len(markers)], label=label, s=28)
        if two:
            points = front.scatter(F[rows, 0], F[rows, 1], c=levels[rows], cmap="viridis",
                                   vmin=lo, vmax=hi if hi > lo else lo + 1, **style)
        level_ax.scatter(F[rows, 0], levels[rows], **style)
    chosen = s.sort.chosen
    for ax, y in ((front, F[:, 1] if two else None), (level_ax, levels)):
        if ax is None:
            continue
        ax.scatter(F[chosen, 0], y[chosen], marker="*", s=260, facecolor="none",
                   edgecolor="red", linewidth=1.5, label="optimum (all)", zorder=3)
        for j, cs in enumerate(s.case_sorts.values()):
            ax.scatter(F[cs.chosen, 0], y[cs.chosen], marker="s", s=110, facecolor="none",
                       edgecolor="black", linewidth=1.0, zorder=3,
                       label="optimum of each case" if j == 0 else None)
    if two:
        at: dict[int, list[str]] = {}
        for key, i in s.picks.items():
            at.setdefault(i, []).append(key)
        for i, keys in at.items():
            front.annotate(", ".join(keys), (F[i, 0], F[i, 1]), textcoords="offset points",
                           xytext=(6, 6), fontsize=8)
        front.set_xlabel(f"{names[0]} [{units[0]}]")
        front.set_ylabel(f"{names[1]} [{units[1]}]")
        fig.colorbar(points, ax=front, label="k-ε level (Eq 6.10, 6.12)")
        front.set_title("front and k-ε levels")
        front.grid(alpha=0.3)
    level_ax.set_xlabel(f"{names[0]} [{units[0]}]")
    level_ax.set_ylabel("k-ε level (Eq 6.10: top level m - 1)")
    P = s.sort.P
    level_ax.set_title("k-ε levels" + (f", P = {P:.3g}" if P is not None else ""))
    level_ax.grid(alpha=0.3)
    level_ax.legend(loc="best", fontsize=8)
    return save(fig, path)


# --- simulate and optimise -----------------------------------------------------------------

def _comfort_signals(names: Sequence[str], units: Mapping[str, str]) -> list[str]:
    """The translational accelerations of ``names`` a person feels (the body, the seat, the
    passenger; not the wheels): those the comfort panel weights."""
    return [n for n in names if units[n] == "m/s^2" and not n.startswith("wheel.")]


def simulation_figure(time: np.ndarray, signals: Mapping[str, np.ndarray],
                      units: Mapping[str, str], labels: Sequence[str], title: str = ""):
    """The figure of :func:`plot_simulation` from arrays, unsaved: ``signals`` (name ->
    ``(P, T)`` over ``time (T,)`` [s]) with their ``units``, one design per row, ``labels``
    ``(P,)``. One row per signal: its time history (left) and its one-sided Welch PSD
    (right; Hann segments of :data:`PSD_SEGMENT` or the record, 0.1-30 Hz); then, when
    there are accelerations a person feels (:func:`_comfort_signals`) and the sampling rate
    is at least 100 Hz, their ISO 2631-1 :data:`COMFORT_WEIGHTING`-weighted r.m.s. against
    the comfort reactions (:func:`draw_weighted_rms`). Each design keeps one
    :func:`curve_styles` style throughout; the legend (several designs) is below."""
    from .metrics import psd
    from .metrics.iso2631 import MIN_SAMPLE_RATE, weighted_rms
    from .specs import METRICS

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
    Figure = _figure_class()
    fig = Figure(figsize=(9.6, 2.5 * len(names) + (2.9 if comfort else 0.0) + 0.6),
                 layout="constrained")
    grid = fig.add_gridspec(rows, 2, height_ratios=[1.0] * len(names) +
                            ([1.15] if comfort else []))
    segment = min(time.size, round(PSD_SEGMENT * fs))
    for r, name in enumerate(names):
        values = np.asarray(signals[name], dtype=float).reshape(P, -1)
        # a signal the designs do not change (the body under a one-way seat) is one curve
        same = P > 1 and all(np.array_equal(v, values[0], equal_nan=True) for v in values)
        drawn, row_labels, row_styles = (values[:1], ["every design"], [_SAME]) if same \
            else (values, labels, styles)
        ax = fig.add_subplot(grid[r, 0])
        draw_time_responses(ax, [(label, time, y) for label, y in zip(row_labels, drawn)],
                            name, units[name], row_styles, legend=False)
        if same:
            ax.set_title(f"the same for all {P} designs", fontsize=9)
        with np.errstate(invalid="ignore"):
            f, spectrum = psd(drawn, fs, segment)
        ax = fig.add_subplot(grid[r, 1])
        draw_spectra(ax, [(label, f, s) for label, s in zip(row_labels, spectrum)], "PSD",
                     METRICS["var"].unit(units[name]) + "/Hz", styles=row_styles,
                     legend=False)
        ax.set_title(f"PSD of {name}", fontsize=9)
    if comfort:
        ax = fig.add_subplot(grid[rows - 1, :])
        if fs >= MIN_SAMPLE_RATE:
            with np.errstate(invalid="ignore"):
                rms = np.array([weighted_rms(np.asarray(signals[n], dtype=float).reshape(P, -1),
                                             fs, COMFORT_WEIGHTING) for n in comfort])
            draw_weighted_rms(ax, comfort, rms, labels, styles)
            ax.set_title(f"ISO 2631-1 {COMFORT_WEIGHTING}-weighted r.m.s. and comfort "
                         f"reactions (Annex C.2.3)", fontsize=9)
        else:
            ax.set_axis_off()
            ax.text(0.5, 0.5, f"no ISO 2631-1 weighted r.m.s.: the signals are sampled at "
                    f"{fs:g} Hz, the weighting needs {MIN_SAMPLE_RATE:g} Hz or more "
                    f"(simulation.output_dt)", ha="center", va="center", fontsize=9)
    if P > 1:
        _figure_legend(fig, _legend_entries(styles, labels))
    _title(fig, title)
    return fig


def _short_names(paths: Sequence[str]) -> list[str]:
    """The shortest tails (two components at least) of dotted ``paths`` that tell them
    apart: ``vehicle.corners.F1.damper.c`` -> ``damper.c`` or ``F1.damper.c``."""
    parts = [p.split(".") for p in paths]
    for k in range(2, max((len(p) for p in parts), default=2) + 1):
        tails = [".".join(p[-k:]) for p in parts]
        if len(set(tails)) == len(tails):
            return tails
    return list(paths)


def _design_labels(designs: Mapping[str, np.ndarray], chosen: Sequence[int], P: int,
                   diverged_at: np.ndarray) -> list[str]:
    """``#i`` and the parameters that vary over the P designs (three at most), and where a
    design diverged."""
    varying = [k for k, v in designs.items()
               if np.size(v) == P and P > 1 and np.ptp(np.asarray(v, dtype=float)) > 0]
    short = _short_names(varying)
    labels = []
    for i in chosen:
        label = "design" if P == 1 else f"#{i}"
        values = [f"{s}={float(np.asarray(designs[k])[i]):.4g}"
                  for s, k in zip(short[:3], varying[:3])]
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


def _chosen_designs(P: int, designs: Sequence[int] | None) -> tuple[list[int], str]:
    """The design indices to draw and a note when they are not all of them."""
    if designs is None:
        if P <= MAX_DESIGNS:
            return list(range(P)), ""
        chosen = sorted({int(round(x)) for x in np.linspace(0, P - 1, MAX_DESIGNS)})
        return chosen, (f"{len(chosen)} of {P} designs drawn (evenly spaced by index; at "
                        f"most {MAX_DESIGNS} on one figure)")
    chosen = [int(i) for i in designs]
    if not chosen:
        raise ValueError("designs: choose at least one design")
    if len(chosen) > MAX_DESIGNS:
        raise ValueError(f"designs: {len(chosen)} designs; at most {MAX_DESIGNS} fit on one "
                         f"figure")
    if len(set(chosen)) != len(chosen):
        raise ValueError("designs: a design is chosen twice")
    bad = [i for i in chosen if not 0 <= i < P]
    if bad:
        raise ValueError(f"designs: {', '.join(map(str, bad))} out of range: the result has "
                         f"{P} design{'s' if P > 1 else ''} (0 to {P - 1})")
    return chosen, "" if len(chosen) == P else f"{len(chosen)} of {P} designs drawn"


def plot_simulation(result, path: str | Path, signals: Sequence[str] | None = None,
                    designs: Sequence[int] | None = None) -> Path:
    """Draw a :class:`suspopt.simulate.Result` (:func:`simulation_figure`) to ``path`` (.png
    or .svg): ``signals`` (default :func:`default_signals`) of the ``designs`` (indices;
    default every design, or :data:`MAX_DESIGNS` of them evenly spaced by index when there
    are more, which the title says). ValueError for an unknown signal, a design out of range,
    more than :data:`MAX_DESIGNS` designs, or no matplotlib."""
    import difflib

    path = check_path(path)
    names = list(signals) if signals is not None else default_signals(result)
    for name in names:
        if name not in result.signals:
            close = difflib.get_close_matches(name, list(result.signals), n=3)
            raise ValueError(f"unknown signal {name!r}" +
                             (f"; did you mean {', '.join(close)}?" if close else ""))
    P = result.P
    chosen, note = _chosen_designs(P, designs)
    labels = _design_labels(result.designs, chosen, P, np.asarray(result.diverged_at))
    cfg = result.config
    source = cfg.source.name if getattr(cfg, "source", None) else "simulation"
    title = f"{source}: road {cfg.road.kind}, {P} design{'s' if P > 1 else ''}" + \
        (f"; {note}" if note else "")
    data = {name: np.asarray(result.signals[name])[chosen] for name in names}
    fig = simulation_figure(result.time, data, {n: result.signal_unit(n) for n in names},
                            labels, title)
    return save(fig, path)


def optimisation_figure(F: np.ndarray, G: np.ndarray, names: Sequence[str],
                        units: Sequence[str], history: Mapping[str, np.ndarray],
                        title: str = "", weights: np.ndarray | None = None):
    """The figure of :func:`plot_optimisation` from arrays, unsaved: the optimum ``F (N,
    m)`` with constraints ``G (N, k)`` (G <= 0 feasible) over objectives ``names`` and
    ``units``, and the ``history`` of ``/history`` (generation, best, hypervolume,
    feasible, ...).

    Two objectives or more: the front as every pair of objectives (one panel for two, a
    panel per pair for more; feasible designs filled, infeasible ones hollow), then the
    hypervolume and the feasible share per generation. One objective, or a weighted sum
    (``weights``): the best value per generation (the weighted sum's; the panel's title
    gives the best design's objectives) and the feasible share. Failed designs (objectives
    of 1e10) are not drawn; the title counts them."""
    F = np.atleast_2d(np.asarray(F, dtype=float))
    G = np.asarray(G, dtype=float).reshape(len(F), -1)
    m = F.shape[1]
    failed = (F >= _FAILED).any(axis=1)
    feasible = (G <= 0).all(axis=1) & ~failed
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
            values = ", ".join(f"{n} = {F[k, j]:.4g}" + ("" if u in ("", "1") else f" {u}")
                               for j, (n, u) in enumerate(zip(names, units)))
            summary = "\n".join(textwrap.wrap(
                f"best design{'' if feasible[k] else ' (infeasible)'}: {values}", 60))
        draw_history(axes[0], generation, best, f"best {name}", unit, summary)
    else:
        pairs = [(i, j) for i in range(m) for j in range(i + 1, m)]
        fig, axes = new_figure(len(pairs) + 2, columns=3, panel_size=(4.2, 3.4))
        other = ~feasible & ~failed
        for ax, (i, j) in zip(axes, pairs):
            fronts = [("feasible", F[feasible, i], F[feasible, j])]
            if other.any():
                fronts.append(("infeasible (a constraint G > 0)", F[other, i], F[other, j]))
            draw_front(ax, fronts, _axis_label(names[i], units[i]),
                       _axis_label(names[j], units[j]), legend=False)
            ax.ticklabel_format(style="sci", scilimits=(-3, 4), useMathText=True)
        draw_history(axes[len(pairs)], generation, history["hypervolume"],
                     "hypervolume (normalised)", "1")
        _figure_legend(fig, axes[0])
    ax = axes[-1]
    draw_history(ax, generation, share, "feasible share", "1")
    ax.set_ylim(-0.05, 1.05)
    if failed.any():
        title += f" ({int(failed.sum())} failed design{'s' if failed.sum() > 1 else ''} " \
                 f"not drawn)"
    _title(fig, title)
    return fig


def plot_optimisation(result, path: str | Path) -> Path:
    """Draw a :class:`suspopt.optimise.OptimisationResult` (:func:`optimisation_figure`) to
    ``path`` (.png or .svg): the front or the best value, and the history per generation."""
    path = check_path(path)
    history = result.history
    generations = len(np.atleast_1d(history["generation"]))
    evaluations = int(history["evaluations"][-1]) if generations else 0
    N, m = np.atleast_2d(result.F).shape
    what = "best design" if (m == 1 or result.weights is not None) else \
        f"{N} design{'s' if N > 1 else ''} on the front"
    title = (f"{Path(result.path).name} ({result.status}): {what}, {generations} "
             f"generation{'s' if generations != 1 else ''}, {evaluations} evaluations")
    fig = optimisation_figure(result.F, result.G, result.obj_names, result.obj_units,
                              history, title, result.weights)
    return save(fig, path)
