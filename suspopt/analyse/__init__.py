"""Analyses behind ``suspopt analyse KIND SOURCE...``.

Each kind is a library function ``run(source, output=None, plot=None, **options) -> Report``
that reads its input (a config, several configs, or a Pareto file), computes, writes its
numbers to HDF5 when ``output`` is given and a figure when ``plot`` is given, and returns a
:class:`Report` for the CLI to render. Kinds are listed in :data:`KINDS` by the module that
implements them, as a :class:`Kind` that says whether ``run`` takes one source or a list of
them and which keyword options it accepts (the CLI passes only those).

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

from .registry import KINDS, SUMMARIES, Kind, Report, relative_change

__all__ = [
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
