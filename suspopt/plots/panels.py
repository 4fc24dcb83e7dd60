"""Panels: each ``draw_*`` draws on one matplotlib ``Axes`` (see :mod:`suspopt.plots`)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from ..metrics import COMFORT_REACTIONS
from .style import (
    COMFORT_WEIGHTING,
    LABEL_GAP,
    PSD_BAND,
    axis_label,
    curve_styles,
    draw_curves,
    spectrum_limits,
)

# --- panels --------------------------------------------------------------------------------


def draw_time_responses(
    ax,
    series: Sequence[tuple[str, np.ndarray, np.ndarray]],
    name: str,
    unit: str,
    styles: Sequence[dict] | None = None,
    legend: bool = True,
) -> None:
    """Time histories ``(label, t [s], y)`` of one signal, one line per label, in ``styles``
    (default :func:`curve_styles`); ``legend`` False leaves it to the figure."""
    draw_curves(ax, series, styles, log=False)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(axis_label(name, unit))
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(fontsize=8)


def draw_spectra(
    ax,
    series: Sequence[tuple[str, np.ndarray, np.ndarray]],
    name: str,
    unit: str,
    f_range: tuple[float, float] = PSD_BAND,
    styles: Sequence[dict] | None = None,
    legend: bool = True,
) -> None:
    """Spectra ``(label, f [Hz], value)`` on log-log axes, within ``f_range``, in ``styles``
    (default :func:`curve_styles`), the value axis over :func:`spectrum_limits` (at most
    :data:`PSD_DECADES` decades below the highest value); ``legend`` False leaves it to the
    figure."""
    band = [
        (
            label,
            f[(f >= f_range[0]) & (f <= f_range[1])],
            value[(f >= f_range[0]) & (f <= f_range[1])],
        )
        for label, f, value in series
    ]
    # zeros (a signal at rest) have no logarithm: masked, not drawn
    band = [(label, f, np.where(v > 0, v, np.nan)) for label, f, v in band]
    draw_curves(ax, band, styles, log=True)
    ax.set_xscale("log")
    limits = spectrum_limits(np.concatenate([v for _l, _f, v in band])) if band else None
    if limits is not None:
        ax.set_yscale("log")
        ax.set_ylim(*limits)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(axis_label(name, unit))
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
    axis (top for x, right for y), never on the data. A label closer than ``LABEL_GAP``
    line heights to the previous one is left out (its line stays)."""
    from matplotlib.ticker import NullLocator

    vertical = axis == "x"
    low, high = ax.get_xlim() if vertical else ax.get_ylim()
    edges = [(lower, label) for lower, _upper, label in COMFORT_REACTIONS[1:] if low < lower < high]
    line = ax.axvline if vertical else ax.axhline
    for lower, _label in edges:
        line(lower, color="0.5", ls=":", lw=0.8, zorder=1)
    to_axes = ax.transAxes.inverted()
    fraction = [
        to_axes.transform(ax.transData.transform((lower, 1.0) if vertical else (1.0, lower)))[
            0 if vertical else 1
        ]
        for lower, _label in edges
    ]
    # a label needs LABEL_GAP line heights (1.2 font sizes) along the axis; the axes' size
    # is taken before the constrained layout shrinks it a little
    box = ax.get_position()
    length = (
        box.width * ax.figure.get_figwidth() if vertical else box.height * ax.figure.get_figheight()
    )
    gap = LABEL_GAP * 1.2 * (7 if outside else 6) / 72.0 / max(length, 1e-3)
    edges = [edge for edge, keep in zip(edges, _spaced(fraction, gap)) if keep]
    if outside:
        second = ax.secondary_xaxis("top") if vertical else ax.secondary_yaxis("right")
        target = second.xaxis if vertical else second.yaxis
        target.set_ticks([lower for lower, _label in edges], [label for _lower, label in edges])
        target.set_minor_locator(NullLocator())
        second.tick_params(labelsize=7, colors="0.35", length=2)
        if vertical:
            second.tick_params(labelrotation=90)
        return
    for lower, label in edges:
        x, y = (lower, 1.0) if vertical else (1.0, lower)
        ax.annotate(
            label,
            (x, y),
            xycoords=("data", "axes fraction") if vertical else ("axes fraction", "data"),
            fontsize=6,
            color="0.4",
            rotation=90 if vertical else 0,
            ha="right",
            va="top",
        )


def draw_front(
    ax,
    fronts: Sequence[tuple[str, np.ndarray, np.ndarray]],
    x_label: str,
    y_label: str,
    marks: Mapping[str, tuple[float, float]] | None = None,
    comfort: bool = False,
    legend: bool = True,
    cloud: tuple[str, np.ndarray, np.ndarray] | None = None,
) -> None:
    """Fronts ``(label, x (N,), y (N,))`` as points, the first one (the optimised front)
    filled, the others (pseudo-fronts) hollow; ``marks`` (name -> (x, y)) as labelled stars;
    ``comfort`` draws the ISO 2631-1 levels on the x axis; ``legend`` False leaves the
    legend to the figure; ``cloud`` ``(label, x, y)``: many points (a front's builds) as
    faint dots beneath the rest."""
    if cloud is not None:
        label, x, y = cloud
        ax.scatter(x, y, s=2, color="0.6", alpha=0.4, linewidths=0, label=label, zorder=0)
    for i, (label, x, y) in enumerate(fronts):
        style = dict(s=18, label=label)
        if i:
            style.update(facecolors="none", edgecolors=f"C{i}")
        else:
            style.update(color="C0")
        ax.scatter(x, y, **style)
    for name, (x_mark, y_mark) in (marks or {}).items():
        ax.scatter([x_mark], [y_mark], marker="*", s=120, color="k", zorder=5)
        ax.annotate(name, (x_mark, y_mark), textcoords="offset points", xytext=(5, 5), fontsize=8)
    if comfort:
        draw_comfort_levels(ax, "x")
    ax.set_xlabel(x_label)
    ax.set_ylabel(y_label)
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(fontsize=8)


def draw_design_variable(
    ax, objective: np.ndarray, values: np.ndarray, x_label: str, y_label: str
) -> None:
    """One design variable along the front against an objective (Figs. 8.11-8.20)."""
    order = np.argsort(objective, kind="stable")
    ax.plot(objective[order], values[order], "o-", ms=3, lw=0.8)
    ax.set_xlabel(x_label)
    ax.set_ylabel(y_label)
    ax.grid(alpha=0.3)


def draw_weighted_rms(
    ax,
    names: Sequence[str],
    values: np.ndarray,
    labels: Sequence[str],
    styles: Sequence[dict] | None = None,
    weighting: str = COMFORT_WEIGHTING,
) -> None:
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
        ax.plot(
            x,
            values[:, j],
            ls="none",
            marker=style.get("marker", "o"),
            ms=6,
            color=style["color"],
            mec=style.get("mec", style["color"]),
            label=label,
        )
        if P <= 3:
            for xi, v in zip(x, values[:, j]):
                if np.isfinite(v):
                    ax.annotate(
                        f"{v:.3g}",
                        (xi, v),
                        textcoords="offset points",
                        xytext=(6, 0),
                        va="center",
                        fontsize=7,
                    )
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
    ax.set_ylabel(axis_label(f"{weighting}-weighted r.m.s.", "m/s^2"))
    ax.grid(True, axis="y", which="both", alpha=0.3)
    draw_comfort_levels(ax, "y", outside=True)


def draw_history(
    ax, generation: np.ndarray, values: np.ndarray, name: str, unit: str, title: str | None = None
) -> None:
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
        title = f"generation {generation[k]:g}: {values[k]:.4g}" + (
            "" if unit in ("", "1") else f" {unit}"
        )
    if not ok.size:
        ax.text(0.5, 0.5, "none yet", transform=ax.transAxes, ha="center", va="center", color="0.4")
    if title:
        ax.set_title(title, fontsize=9)
    if generation.size:
        low, high = float(generation.min()), float(generation.max())
        pad = max(0.5, 0.04 * (high - low))
        ax.set_xlim(low - pad, high + pad)
    ax.set_xlabel("generation [-]")
    ax.set_ylabel(axis_label(name, unit))
    ax.grid(alpha=0.3)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
