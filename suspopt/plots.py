"""Figures of the analyses, drawn from arrays (matplotlib, optional: ``pip install
'suspopt[plot]'``).

The analyses compute and write HDF5; this module only draws what they hand it, so a figure can
be redrawn from a file. Panel functions (``draw_*``) draw on one matplotlib ``Axes``; figure
functions lay panels out and :func:`save` writes the file, atomically (a temporary name, then
a rename), as PNG or SVG by its suffix. No pyplot: figures are ``matplotlib.figure.Figure``
objects, so nothing depends on a display or on global state.

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
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from .metrics import COMFORT_REACTIONS

__all__ = ["FORMATS", "check_path", "new_figure", "save", "draw_time_responses",
           "draw_spectra", "draw_front", "draw_design_variable", "draw_comfort_levels",
           "model_comparison", "pareto_fronts", "sensitivity", "transmissibilities",
           "plot_kesort"]

#: Figure formats, by file suffix.
FORMATS = {".png": "png", ".svg": "svg"}
#: Line styles cycled with the colours, so that coinciding curves stay visible.
_LINES = ("-", "--", "-.", ":")


def check_path(path: str | Path) -> Path:
    """``path`` if its suffix names a known format (.png, .svg), else ValueError; call it
    before computing, so that a bad name fails before anything is written."""
    path = Path(path)
    if path.suffix.lower() not in FORMATS:
        raise ValueError(f"--plot {path}: the figure's suffix must be one of "
                         f"{', '.join(FORMATS)}")
    return path


def new_figure(panels: int, columns: int = 2, panel_size: tuple[float, float] = (4.6, 3.2)):
    """A figure with ``panels`` axes on a grid of ``columns``; returns (figure, [axes])."""
    try:
        from matplotlib.figure import Figure
    except ImportError:
        raise ValueError("--plot needs matplotlib: pip install 'suspopt[plot]'") from None
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
    return f"{name} [{unit}]" if unit else name


# --- panels --------------------------------------------------------------------------------

def draw_time_responses(ax, series: Sequence[tuple[str, np.ndarray, np.ndarray]],
                        name: str, unit: str) -> None:
    """Time histories ``(label, t [s], y)`` of one signal, one line per label."""
    for i, (label, t, y) in enumerate(series):
        ax.plot(t, y, lw=1.0, ls=_LINES[i % len(_LINES)], label=label)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(_axis_label(name, unit))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)


def draw_spectra(ax, series: Sequence[tuple[str, np.ndarray, np.ndarray]], name: str,
                 unit: str, f_range: tuple[float, float] = (0.1, 30.0)) -> None:
    """Spectra ``(label, f [Hz], value)`` on log-log axes, within ``f_range``."""
    for i, (label, f, value) in enumerate(series):
        band = (f >= f_range[0]) & (f <= f_range[1])
        ax.loglog(f[band], value[band], lw=1.0, ls=_LINES[i % len(_LINES)], label=label)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(_axis_label(name, unit))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)


def draw_comfort_levels(ax, axis: str = "x") -> None:
    """ISO 2631-1 comfort reactions (Annex C.2.3) as lines at the bands' lower edges within
    the current limits of a weighted-r.m.s. axis (Fig. 8.23)."""
    low, high = ax.get_xlim() if axis == "x" else ax.get_ylim()
    for lower, _upper, label in COMFORT_REACTIONS[1:]:
        if low < lower < high:
            line = ax.axvline if axis == "x" else ax.axhline
            line(lower, color="0.5", ls=":", lw=0.8)
            x, y = (lower, 1.0) if axis == "x" else (1.0, lower)
            ax.annotate(label, (x, y), xycoords=("data", "axes fraction") if axis == "x" else
                        ("axes fraction", "data"), fontsize=6, color="0.4", rotation=90
                        if axis == "x" else 0, ha="right", va="top")


def draw_front(ax, fronts: Sequence[tuple[str, np.ndarray, np.ndarray]], x_label: str,
               y_label: str, marks: Mapping[str, tuple[float, float]] | None = None,
               comfort: bool = False) -> None:
    """Fronts ``(label, x (N,), y (N,))`` as points, the first one (the optimised front)
    filled, the others (pseudo-fronts) hollow; ``marks`` (name -> (x, y)) as labelled stars;
    ``comfort`` draws the ISO 2631-1 levels on the x axis."""
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

def model_comparison(path: str | Path, title: str,
                     time_series: Mapping[str, Sequence[tuple[str, np.ndarray, np.ndarray]]],
                     spectra: Mapping[str, Sequence[tuple[str, np.ndarray, np.ndarray]]],
                     units: Mapping[str, str]) -> Path:
    """Several models side by side: one panel per signal of ``time_series`` (name -> series
    of ``(model, t, y)``) and one per spectrum of ``spectra`` (name -> ``(model, f, PSD)``);
    ``units`` maps each name to its unit."""
    fig, axes = new_figure(len(time_series) + len(spectra))
    for ax, (name, series) in zip(axes, time_series.items()):
        draw_time_responses(ax, series, name, units[name])
    for ax, (name, series) in zip(axes[len(time_series):], spectra.items()):
        draw_spectra(ax, series, f"PSD of {name}", units[f"PSD of {name}"])
    fig.suptitle(title)
    return save(fig, path)


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
