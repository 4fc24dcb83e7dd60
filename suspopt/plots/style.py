"""The figure and its styles: formats, atomic saving, curve styles and markers, legends and titles (see :mod:`suspopt.plots`)."""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence
from pathlib import Path

import numpy as np

#: Figure formats, by file suffix.
FORMATS = {".png": "png", ".svg": "svg"}
#: Line styles cycled with the colours (solid first, then dashes of distinct rhythms).
_LINES = (
    "-",
    (0, (6, 2)),
    (0, (2, 1.5)),
    (0, (7, 2, 1.5, 2)),
    (0, (1, 1)),
    (0, (4, 1.5, 1, 1.5, 1, 1.5)),
)
#: Marker shapes cycled with the colours.
_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*", "<", ">")
#: Markers per curve, spread evenly along the x axis.
MARKS_PER_CURVE = 10
#: Line width of the curve drawn last (on top) [pt]; the ones under it are wider.
_THINNEST = 1.0
#: The style of one curve that stands for every design.
SAME_STYLE = dict(color="k", ls="-", lw=1.0)
#: Designs drawn at most on one simulation figure (more are unreadable).
MAX_DESIGNS = 8
#: The band the figures draw spectra in [Hz] (the ride band of ISO 2631-1 and beyond).
PSD_BAND = (0.1, 30.0)
#: Decades a spectrum's axis shows below its highest value: the computed PSD of a smooth
#: signal falls to numerical noise (about 1e-16 of its peak) at high frequency, which is no
#: information but would squeeze every mode into the top of the axis.
PSD_DECADES = 6.0
#: The ISO 2631-1 weighting of the simulation figure's comfort panel (vertical, seated).
COMFORT_WEIGHTING = "Wk"
#: Fewest line heights between two comfort-level labels (closer ones are left out).
LABEL_GAP = 1.1
#: Objectives at or above this are failed designs (suspopt.optimisation.problem.PENALTY).
FAILED_VALUE = 1e10


def check_path(path: str | Path) -> Path:
    """``path`` if its suffix names a known format (.png, .svg), else ValueError; call it
    before computing, so that a bad name fails before anything is written."""
    path = Path(path)
    if path.suffix.lower() not in FORMATS:
        raise ValueError(f"--plot {path}: the figure's suffix must be one of {', '.join(FORMATS)}")
    return path


def _matplotlib_folders() -> None:
    """Where matplotlib cannot make or write its config and cache folders (``HOME`` unset,
    read-only or absent, as for a container's or CI's user), point ``MPLCONFIGDIR`` at a
    private folder of this user in the temporary directory: matplotlib would otherwise print
    two warning lines on every run and build its font cache again each time. Nothing is
    changed when ``MPLCONFIGDIR`` is set, matplotlib is loaded, or its folders are fine."""
    import os
    import stat
    import sys
    import tempfile

    if "MPLCONFIGDIR" in os.environ or "matplotlib" in sys.modules:
        return
    home = os.path.expanduser("~")
    for variable, default in (("XDG_CONFIG_HOME", ".config"), ("XDG_CACHE_HOME", ".cache")):
        folder = os.path.join(os.environ.get(variable) or os.path.join(home, default), "matplotlib")
        try:
            os.makedirs(folder, exist_ok=True)
        except OSError:
            break
        if not os.access(folder, os.W_OK):
            break
    else:
        return
    private = os.path.join(tempfile.gettempdir(), f"suspopt-matplotlib-{os.getuid()}")
    try:
        os.makedirs(private, mode=0o700, exist_ok=True)
        info = os.lstat(private)
    except OSError:
        return
    if stat.S_ISDIR(info.st_mode) and info.st_uid == os.getuid():  # (not another user's)
        os.environ["MPLCONFIGDIR"] = private


def figure_class():
    """matplotlib's ``Figure``, or ValueError naming the extra to install."""
    _matplotlib_folders()
    try:
        from matplotlib.figure import Figure
    except ImportError:
        raise ValueError(
            "--plot needs matplotlib, a dependency of suspopt that cannot be imported here: "
            "pip install matplotlib"
        ) from None
    return Figure


def new_figure(panels: int, columns: int = 2, panel_size: tuple[float, float] = (4.6, 3.2)):
    """A figure with ``panels`` axes on a grid of ``columns``; returns (figure, [axes])."""
    Figure = figure_class()
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
    from .._version import __version__
    from ..io import OUTPUT_MARKER, atomic_file

    path = check_path(path)
    kind = FORMATS[path.suffix.lower()]
    mark = f"{OUTPUT_MARKER} {__version__}"
    metadata = {"Software": mark} if kind == "png" else {"Creator": mark}
    with atomic_file(path) as stream:
        fig.savefig(stream, format=kind, dpi=dpi, metadata=metadata)
    return path


def axis_label(name: str, unit: str) -> str:
    """``name [unit]``; a dimensionless unit ("1") as ``[-]``."""
    if unit == "1":
        unit = "-"
    return f"{name} [{unit}]" if unit else name


def spectrum_limits(values, decades: float = PSD_DECADES) -> tuple[float, float] | None:
    """The range [unit of ``values``] of a log axis for the spectra ``values`` (any shape):
    from the smallest positive finite value, but no lower than ``decades`` decades below the
    highest, to the highest with a tenth of a decade above it; None when no value is
    positive (nothing to draw on a log axis)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v) & (v > 0)]
    if not v.size:
        return None
    high = float(v.max())
    return max(float(v.min()), high * 10.0**-decades) / 10**0.1, high * 10**0.1


def curve_styles(n: int) -> list[dict]:
    """Styles (``Axes.plot`` keywords) of ``n`` curves on one panel that may coincide: a
    colour, a line style and a marker shape each, and widths from the widest (the first,
    drawn underneath) to :data:`_THINNEST` (the last, on top), so that every curve still shows
    at the edges of those drawn over it. One curve gets a plain line."""
    if n <= 1:
        return [dict(color="C0", ls="-", lw=1.2)]
    step = min(0.7, 2.4 / (n - 1))
    return [
        dict(
            color=f"C{i % 10}",
            ls=_LINES[i % len(_LINES)],
            lw=_THINNEST + step * (n - 1 - i),
            marker=_MARKERS[i % len(_MARKERS)],
            ms=4.5,
            mec=f"C{i % 10}",
        )
        for i in range(n)
    ]


def mark_indices(
    x: np.ndarray, i: int, n: int, count: int = MARKS_PER_CURVE, log: bool = False
) -> np.ndarray:
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


def draw_curves(
    ax,
    series: Sequence[tuple[str, np.ndarray, np.ndarray]],
    styles: Sequence[dict] | None,
    log: bool,
) -> None:
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


def figure_legend(fig, entries, fontsize: float = 8) -> None:
    """One legend for the figure, with the entries of an axes, or ``entries`` ``(handles,
    labels)``: in the grid's first unused cell when there is one, else below all panels;
    outside the panels either way, so it never hides data."""
    handles, labels = entries if isinstance(entries, tuple) else entries.get_legend_handles_labels()
    if not handles:
        return
    spare = [a for a in fig.axes if not a.get_visible()]
    if spare:
        cell = spare[0]
        cell.set_visible(True)
        cell.set_axis_off()
        cell.legend(
            handles,
            labels,
            loc="center",
            fontsize=fontsize,
            frameon=False,
            ncols=1 if len(labels) <= 12 else 2,
        )
        return
    fig.legend(
        handles,
        labels,
        loc="outside lower center",
        fontsize=fontsize,
        ncols=_legend_columns(fig, labels, fontsize),
        frameon=False,
    )


def legend_entries(styles: Sequence[dict], labels: Sequence[str]) -> tuple[list, list]:
    """Legend handles (lines without data) of curves drawn in ``styles``."""
    from matplotlib.lines import Line2D

    return [Line2D([], [], **style) for style in styles], list(labels)


def figure_title(fig, text: str, fontsize: float = 11) -> None:
    """``text`` as the figure's title, wrapped to the figure's width."""
    chars = max(20, int(fig.get_figwidth() * 72.0 / (0.58 * fontsize)))
    fig.suptitle("\n".join(textwrap.wrap(text, chars)) if text else "", fontsize=fontsize)
