"""Figures of the analyses, drawn from arrays (matplotlib, optional: ``pip install
'suspopt[plot]'``).

The analyses compute and write HDF5; this module draws what they hand it, so a figure can be
redrawn from a file. Panel functions (``draw_*``) draw on one matplotlib ``Axes``; figure
functions lay panels out and :func:`save` writes the file, atomically (a temporary name, then
a rename), as PNG or SVG by its suffix. No pyplot: figures are ``matplotlib.figure.Figure``
objects, so nothing depends on a display or on global state; matplotlib is imported inside
the functions only (importing this module costs nothing).

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
  :class:`suspopt.selection.Selection`.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from .metrics import COMFORT_REACTIONS

__all__ = ["FORMATS", "check_path", "new_figure", "save", "curve_styles", "mark_indices",
           "draw_time_responses", "draw_spectra", "draw_front", "draw_design_variable",
           "draw_comfort_levels", "model_comparison", "model_figure", "pareto_fronts",
           "sensitivity", "transmissibilities", "plot_kesort"]

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
#: Fewest line heights between two comfort-level labels (closer ones are left out).
_LABEL_GAP = 1.1


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

