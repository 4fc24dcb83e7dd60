"""What every analysis kind shares: its :class:`Kind` entry in :data:`KINDS` (filled by the
module that implements it), the :class:`Analysis` it returns, the :class:`Report` table that
shows it, the help's :data:`SUMMARIES` and :func:`relative_change`. Re-exported by
:mod:`suspopt.analyse`."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

    from ..config import Config

__all__ = ["Analysis", "Report", "Kind", "KINDS", "SUMMARIES", "relative_change"]


@dataclass
class Report:
    """A table of results: ``columns`` headers, ``rows`` of formatted cells, and notes."""

    title: str
    columns: list[str]
    rows: list[list[str]]
    notes: list[str] = field(default_factory=list)


@dataclass
class Analysis:
    """What an analysis computed, before anything is written or shown.

    Attributes
    ----------
    kind : str
        The analysis kind (``builds``, ``roads`` ...).
    title : str
        What it is of, in one line (the table's and the figure's title).
    data : object
        The kind's own result, with its units: ``suspopt.analyse.models.ModelComparison``,
        ``suspopt.analyse.pseudo.PseudoFronts``, ``suspopt.analyse.builds.Builds``,
        ``suspopt.analyse.transmissibility.SeatTransmissibility``,
        ``suspopt.analyse.cdf.CdfSensitivity`` or
        ``suspopt.analyse.scenarios.ScenarioSpread``.
    config : Config
        The config it ran (provenance; the written file's root attribute ``config``).
    sources : list of Path
        The files it read.
    writer : callable
        The kind's writer of its file, ``(path, command) -> path``, bound to ``data``
        (what :meth:`write` calls).
    drawer : callable or None
        Its figure, ``(path) -> path`` (what :meth:`plot` calls; None: it draws none).
    tabulate : callable
        Its table, ``() -> Report`` (what :meth:`report` calls).

    Computing it wrote nothing. :meth:`write` writes its HDF5 file (the kind's format in
    :mod:`suspopt.formats`), :meth:`plot` draws its figure and :meth:`report` makes its
    table; the command line calls them as ``-o``, ``--plot`` and its output ask.
    """

    kind: str
    title: str
    data: Any
    config: Config
    sources: list[Path]
    writer: Callable[[Path, str | None], Path] = field(repr=False)
    drawer: Callable[[Path], Path] | None = field(repr=False)
    tabulate: Callable[[], Report] = field(repr=False)

    def write(self, path: str | Path, command: str | None = None) -> Path:
        """Write the HDF5 file ``path`` (atomically; ``command`` the root attribute
        ``command``, default this process's command line); return its path."""
        return self.writer(Path(path), command)

    def plot(self, path: str | Path) -> Path:
        """Draw the figure ``path`` (``.png`` or ``.svg``); return its path."""
        from .. import plots

        plots.check_path(path)
        if self.drawer is None:
            raise ValueError(f"analyse {self.kind} draws no figure")
        return self.drawer(Path(path))

    def report(self) -> Report:
        """The table (formatted cells) and notes that ``suspopt analyse`` prints."""
        return self.tabulate()


def analysis(
    kind: str,
    title: str,
    data: Any,
    config: Config,
    sources: Sequence[str | Path],
    writer: Callable[[Path, str | None], Path],
    drawer: Callable[[Path], Path] | None,
    tabulate: Callable[[], Report],
) -> Analysis:
    """An :class:`Analysis` (its sources as paths)."""
    return Analysis(kind, title, data, config, [Path(s) for s in sources], writer, drawer, tabulate)


@dataclass(frozen=True)
class Kind:
    """An analysis kind: ``run(source | sources, **options) -> Analysis``, which computes and
    writes nothing.

    ``many``: ``run`` takes a list of sources (else exactly one path); ``options``: the names
    of the keyword options ``run`` accepts.
    """

    run: Callable[..., Analysis]
    many: bool = False
    options: tuple[str, ...] = ()


def relative_change(value, reference) -> np.ndarray:
    """``100 (value - reference) / reference`` [%] (the percentages of Tables 3.3-3.21,
    4.2-4.3, 8.12-8.13; their signs are each table's), NaN where it cannot be computed: the
    reference is 0 or NaN (a failed design's), the value NaN, or the change beyond the
    floating-point range (a stored value of 1e-308 or 1e308: a damaged file). Computed
    without a floating-point warning; a table shows NaN as ``n/a``
    (:func:`suspopt.analyse.cells.percent`)."""
    import numpy as np

    with np.errstate(all="ignore"):
        change = (np.asarray(value, dtype=float) - reference) / reference * 100.0
    return np.where(np.isfinite(change), change, np.nan)


#: kind name -> Kind
KINDS: dict[str, Kind] = {}
#: What each kind does, for ``suspopt analyse --help`` (which must not import the kinds'
#: modules to say so; a test checks that it lists every kind of :data:`KINDS`).
SUMMARIES = {
    "models": "configs side by side, as Ch. 3 does (transient or random-road metrics, modes)",
    "roads": "a Pareto file's designs on other roads (Sec 8.4.2, Table 8.12)",
    "masses": "a Pareto file's designs with another passenger mass (Sec 8.4.3, Table 8.13)",
    "controllers": "a Pareto file's designs with another controller (Fig. 7.4b)",
    "transmissibility": "seat-to-head and seat transmissibility of a config or of a front's "
    "edges and knee (Eq 2.86, Fig. 8.26)",
    "scenarios": "a robust front's picks under each of its scenarios (no simulation)",
    "tolerances": "a Pareto file's designs with each design variable off by ±t % in turn "
    "(as built: manufacturing tolerances)",
    "builds": "a Pareto file's designs built many times with every design variable off "
    "at once within ±t % (Monte Carlo of manufacturing tolerances)",
    "cdf-sensitivity": "the C_max share of an adaptive CDF threshold swept from 20 to 70 % "
    "(Figs. 4.7, 4.10)",
}
