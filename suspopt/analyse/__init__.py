"""Analyses behind ``suspopt analyse KIND SOURCE...``.

Each kind is a library function ``run(source, **options) -> Analysis`` that reads its input
(a config, several configs, or a Pareto file), computes and writes nothing: the
:class:`Analysis` holds the data (with units) and its provenance, and the command line asks
it for its HDF5 file (:meth:`Analysis.write`), its figure (:meth:`Analysis.plot`) and its
table (:meth:`Analysis.report`, a :class:`Report`). :func:`run_analysis` runs a kind by name.
Kinds are listed in :data:`KINDS` by the module that implements them, as a :class:`Kind`
that says whether ``run`` takes one source or a list of them and which keyword options it
accepts (the CLI passes only those).

| kind | source | module |
|---|---|---|
| ``models`` | several configs (Ch. 3) | :mod:`.models` |
| ``cdf-sensitivity`` | a config with an adaptive threshold (Figs. 4.7, 4.10) | :mod:`.cdf` |
| ``roads``, ``masses``, ``controllers`` | a Pareto file (Sec 8.4.2-8.4.3, Ch. 7) | :mod:`.pseudo` |
| ``transmissibility`` | a config with a seat (Eq 2.86, Fig. 8.26) | :mod:`.transmissibility` |
| ``scenarios`` | a robust optimisation's Pareto file | :mod:`.scenarios` |
| ``tolerances`` | a Pareto file (each design variable off by ±t %) | :mod:`.tolerances` |
| ``builds`` | a Pareto file (built many times, every variable off at once) | :mod:`.builds` |
"""

from __future__ import annotations

from .registry import KINDS, SUMMARIES, Analysis, Kind, Report, relative_change

__all__ = [
    "Analysis",
    "run_analysis",
    "Report",
    "Kind",
    "KINDS",
    "SUMMARIES",
    "analysis_kinds",
    "relative_change",
]


def analysis_kinds() -> dict[str, Kind]:
    """Every available analysis kind, importing the modules that provide them."""
    from . import (
        builds,  # noqa: F401  (registers builds)
        cdf,  # noqa: F401  (registers cdf-sensitivity)
        models,  # noqa: F401  (registers models)
        pseudo,  # noqa: F401  (registers roads, masses, controllers)
        scenarios,  # noqa: F401  (registers scenarios)
        tolerances,  # noqa: F401  (registers tolerances)
        transmissibility,  # noqa: F401  (registers transmissibility)
    )

    return dict(KINDS)


def run_analysis(kind: str, sources, **options) -> Analysis:
    """Run the analysis ``kind`` of ``sources`` and return what it computed, writing nothing.

    Parameters
    ----------
    kind : str
        One of ``suspopt.analyse.SUMMARIES`` (``models``, ``roads``, ``masses``, ``controllers``,
        ``tolerances``, ``builds``, ``transmissibility``, ``scenarios``, ``cdf-sensitivity``).
    sources : path or list of paths
        The config or Pareto file it analyses (``models``: several configs).
    **options
        The kind's options, as ``suspopt analyse KIND --help`` lists them (``samples=200``,
        ``tolerance=["C_v=15"]``, ``pick=["knee"]``, ``road=["B"]``, ``with_=[path]`` ...).

    Returns
    -------
    Analysis
        Its data (SI units) and provenance; ``.write(path)`` writes the HDF5 file,
        ``.plot(path)`` the figure, ``.report()`` gives the table.

    Raises
    ------
    suspopt.InputError
        For bad input (a file, an option), naming it.
    """
    from ..files import listed

    kinds = analysis_kinds()
    if kind not in kinds:
        raise ValueError(f"no analysis kind {kind!r}; available: {', '.join(sorted(kinds))}")
    spec = kinds[kind]
    wrong = sorted(set(options) - set(spec.options))
    if wrong:
        raise ValueError(f"analyse {kind} does not take {', '.join(wrong)}")
    given = listed(sources)
    if not spec.many and len(given) != 1:
        raise ValueError(f"analyse {kind} takes one source, got {len(given)}")
    return spec.run(given if spec.many else given[0], **options)
