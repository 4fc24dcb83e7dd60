"""Figures of the thesis's analyses laid out from panels (see :mod:`suspopt.plots`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from .panels import draw_design_variable, draw_front, draw_spectra, draw_time_responses
from .style import axis_label, check_path, figure_legend, figure_title, new_figure, save

# --- figures -------------------------------------------------------------------------------


def model_figure(
    title: str,
    time_series: Mapping[str, Sequence[tuple[str, np.ndarray, np.ndarray]]],
    spectra: Mapping[str, Sequence[tuple[str, np.ndarray, np.ndarray]]],
    units: Mapping[str, str],
):
    """The figure of :func:`model_comparison`, unsaved: every series lists the models in
    the same order, so each model has one :func:`curve_styles` style in every panel; the one
    legend is below the panels."""
    fig, axes = new_figure(len(time_series) + len(spectra))
    for ax, (name, series) in zip(axes, time_series.items()):
        draw_time_responses(ax, series, name, units[name], legend=False)
    for ax, (name, series) in zip(axes[len(time_series) :], spectra.items()):
        draw_spectra(ax, series, "PSD", units[f"PSD of {name}"], legend=False)
        ax.set_title(f"PSD of {name}", fontsize=9)
    if axes:
        figure_legend(fig, axes[0])
    figure_title(fig, title)
    return fig


def model_comparison(
    path: str | Path,
    title: str,
    time_series: Mapping[str, Sequence[tuple[str, np.ndarray, np.ndarray]]],
    spectra: Mapping[str, Sequence[tuple[str, np.ndarray, np.ndarray]]],
    units: Mapping[str, str],
) -> Path:
    """Several models side by side: one panel per signal of ``time_series`` (name -> series
    of ``(model, t, y)``) and one per spectrum of ``spectra`` (name -> ``(model, f, PSD)``);
    ``units`` maps each name to its unit. Models whose curves coincide stay distinguishable
    (:func:`curve_styles`); one legend below the panels (:func:`model_figure`)."""
    path = check_path(path)
    return save(model_figure(title, time_series, spectra, units), path)


def pareto_fronts(
    path: str | Path,
    title: str,
    objectives: Sequence[tuple[str, str]],
    fronts: Sequence[tuple[str, np.ndarray]],
    variables: Sequence[tuple[str, str, np.ndarray]] = (),
    marks: Mapping[str, int] | None = None,
    comfort: Sequence[bool] | None = None,
    cloud: tuple[str, np.ndarray] | None = None,
) -> Path:
    """Fronts ``(label, F (N, m))`` over ``objectives`` ``(name, unit)`` - the first the
    optimised front, the rest pseudo-fronts of the same designs - as the first objective
    against each other one (Figs. 7.5, 8.22-8.24); then each design variable
    ``(name, unit, values (N,))`` of the optimised front against the first objective
    (Figs. 8.11-8.20). ``marks`` (name -> design index) are starred on the optimised front;
    ``comfort[j]`` tells that objective ``j`` is an ISO 2631-1 weighted r.m.s. (its levels
    are drawn when it is the x axis); ``cloud`` ``(label, F (K, m))``: many points drawn
    faint beneath the fronts (the builds of ``analyse builds``)."""
    m = len(objectives)
    pairs = [(0, j) for j in range(1, m)] or [(0, 0)]
    fig, axes = new_figure(len(pairs) + len(variables), columns=3)
    (x_name, x_unit) = objectives[0]
    x_label = axis_label(x_name, x_unit)
    for ax, (i, j) in zip(axes, pairs):
        F0 = fronts[0][1]
        points = {name: (F0[k, i], F0[k, j]) for name, k in (marks or {}).items()}
        draw_front(
            ax,
            [(label, F[:, i], F[:, j]) for label, F in fronts],
            x_label,
            axis_label(*objectives[j]),
            points,
            bool(comfort and comfort[0]),
            cloud=None if cloud is None else (cloud[0], cloud[1][:, i], cloud[1][:, j]),
        )
    F0 = fronts[0][1]
    for ax, (name, unit, values) in zip(axes[len(pairs) :], variables):
        draw_design_variable(ax, F0[:, 0], values, x_label, axis_label(name, unit))
    fig.suptitle(title)
    return save(fig, path)


def sensitivity(
    path: str | Path,
    title: str,
    x: np.ndarray,
    x_label: str,
    panels: Sequence[Mapping[str, np.ndarray]],
    y_label: str,
    marker: float | None = None,
    marker_label: str = "",
) -> Path:
    """Sensitivity curves: one panel per mapping of ``panels`` (curve name -> (X,) values
    over ``x``), a zero line, and a dashed vertical ``marker`` (e.g. the base law's share)."""
    fig, axes = new_figure(len(panels), columns=1, panel_size=(7.0, 3.0))
    for ax, curves in zip(axes, panels):
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


def scenario_spread(
    path: str | Path,
    title: str,
    scenarios: Sequence[str],
    panels: Sequence[tuple[str, str, Mapping[str, np.ndarray]]],
) -> Path:
    """Designs' values under each scenario: one panel per ``(name, unit, {design label: (S,)
    values})``, the scenarios as named ticks (``suspopt analyse scenarios``)."""
    fig, axes = new_figure(len(panels), columns=1, panel_size=(7.0, 2.8))
    x = np.arange(len(scenarios))
    for ax, (name, unit, curves) in zip(axes, panels):
        for label, values in curves.items():
            ax.plot(x, values, "o-", label=label)
        ax.set_ylabel(axis_label(name, unit))
        ax.set_xticks(x, list(scenarios), rotation=30 if len(scenarios) > 4 else 0)
        ax.grid(alpha=0.3)
    figure_legend(fig, axes[0].get_legend_handles_labels())
    figure_title(fig, title)
    return save(fig, path)


def transmissibilities(
    path: str | Path,
    title: str,
    lines: Sequence[tuple[str, np.ndarray, np.ndarray]],
    points: Sequence[tuple[str, np.ndarray, np.ndarray]] = (),
    f_range: tuple[float, float] = (0.1, 30.0),
) -> Path:
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


def _mark_optima(ax, x: np.ndarray, y: np.ndarray, s) -> None:
    """The pool's k-ε optimum (a red star, its id in the legend: :mod:`suspopt.design_ids`)
    and each case's own (open squares) at ``(x, y)``."""
    from ..design_ids import selection_ids

    label = f"optimum (all): design {selection_ids(s)[s.sort.chosen]}"
    optimum = dict(marker="*", s=260, facecolor="none", edgecolor="red", linewidth=1.5)
    ax.scatter(x[s.sort.chosen], y[s.sort.chosen], label=label, zorder=3, **optimum)
    own = dict(marker="s", s=110, facecolor="none", edgecolor="black", linewidth=1.0)
    for j, cs in enumerate(s.case_sorts.values()):
        case_label = "optimum of each case" if j == 0 else None
        ax.scatter(x[cs.chosen], y[cs.chosen], zorder=3, label=case_label, **own)


def plot_kesort(selection, path: str | Path) -> Path:
    """The k-ε levels over the front (Fig. 6.7, 7.5, 7.6) of a
    :class:`suspopt.choosing.selection.Selection`.

    Left: the first two objectives (the main ones of Ch. 6-7, Fig. 7.5a/7.6), one marker per
    case, coloured by the pool's k-ε level; the pool's optimum is a star, each case's own
    optimum an open square, the Pareto picks (edges and knee, Fig. 8.21) are labelled. Right:
    the k-ε level of every design against the first objective (Fig. 6.7). Designs are named
    by their ids (:mod:`suspopt.design_ids`), as ``--pick`` takes them. With one objective
    only the right panel is drawn. A selection sorted as built (``kesort --as-built``) is
    drawn at the values it was sorted on (``F_as_built``), as its axes say.
    """
    from ..design_ids import selection_ids
    from ..errors import require_like

    s = require_like(
        selection,
        "Selection",
        ("F_sorted", "sort", "units", "names"),
        "selection",
        "from suspopt.choosing.selection.select(sets)",
    )
    path = check_path(path)
    F, levels, units = s.F_sorted, s.sort.k_eps, s.units
    built = "" if s.as_built is None else f", as built (p{s.as_built:g})"
    names = [name + built for name in s.names]
    markers = "os^Dv<>phX*"
    two = F.shape[1] > 1
    fig, axes = new_figure(2 if two else 1, panel_size=(6.0, 5.0))
    front, level_ax = (axes[0], axes[1]) if two else (axes[0], axes[0])  # (front: if two)
    lo, hi = float(levels.min()), float(levels.max())
    for c, label in enumerate(s.cases):
        rows = s.case == label
        style = dict(marker=markers[c % len(markers)], label=label, s=28)
        if two:
            points = front.scatter(
                F[rows, 0],
                F[rows, 1],
                c=levels[rows],
                cmap="viridis",
                vmin=lo,
                vmax=hi if hi > lo else lo + 1,
                **style,
            )
        level_ax.scatter(F[rows, 0], levels[rows], **style)
    if two:
        _mark_optima(front, F[:, 0], F[:, 1], s)
    _mark_optima(level_ax, F[:, 0], levels, s)
    if two:
        at: dict[int, list[str]] = {}
        for key, i in s.picks.items():
            at.setdefault(i, []).append(key)
        ids = selection_ids(s)
        for i, keys in at.items():
            front.annotate(
                f"{', '.join(keys)} (design {ids[i]})",
                (F[i, 0], F[i, 1]),
                textcoords="offset points",
                xytext=(6, 6),
                fontsize=8,
            )
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
