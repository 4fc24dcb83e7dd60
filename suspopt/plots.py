"""matplotlib figures (the ``plot`` extra: ``pip install 'suspopt[plot]'``).

Each function draws one figure from a library result and saves it (PNG or SVG, by the file's
suffix); computing lives in the library modules, drawing here. matplotlib is imported inside
each function (Agg backend), so importing suspopt never needs it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["plot_kesort"]


def plot_kesort(selection, path: str | Path) -> Path:
    """The k-ε levels over the front (Fig. 6.7, 7.5, 7.6) of a
    :class:`suspopt.selection.Selection`.

    Left: the first two objectives (the main ones of Ch. 6-7, Fig. 7.5a/7.6), one marker per
    case, coloured by the pool's k-ε level; the pool's optimum is a star, each case's own
    optimum an open square, the Pareto picks (edges and knee, Fig. 8.21) are labelled. Right:
    the k-ε level of every design against the first objective (Fig. 6.7). With one objective
    only the right panel is drawn.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s, path = selection, Path(path)
    F, levels, names, units = s.F, s.sort.k_eps, s.names, s.units
    markers = "os^Dv<>phX*"
    two = F.shape[1] > 1
    fig, axes = plt.subplots(1, 2 if two else 1, figsize=(12 if two else 6, 5), squeeze=False)
    front, level_ax = (axes[0, 0], axes[0, 1]) if two else (None, axes[0, 0])
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
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
