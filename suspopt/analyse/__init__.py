"""Analyses behind ``suspopt analyse KIND SOURCE``.

Each kind is a library function ``run(source, output=None, plot=None) -> Report`` that reads a
config (or a result file), computes, writes its numbers to HDF5 when ``output`` is given and a
figure when ``plot`` is given, and returns a :class:`Report` for the CLI to render. Kinds are
listed in :data:`KINDS` by the module that implements them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Report", "KINDS", "analysis_kinds"]


@dataclass
class Report:
    """A table of results: ``columns`` headers, ``rows`` of formatted cells, and notes."""

    title: str
    columns: list[str]
    rows: list[list[str]]
    notes: list[str] = field(default_factory=list)


#: kind name -> run(source: Path, output: Path | None, plot: Path | None) -> Report
KINDS: dict[str, Callable[[Path, Path | None, Path | None], Report]] = {}


def analysis_kinds() -> dict[str, Callable[[Path, Path | None, Path | None], Report]]:
    """Every available analysis kind, importing the modules that provide them."""
    from . import cdf  # noqa: F401  (registers cdf-sensitivity)
    from . import transmissibility  # noqa: F401  (registers transmissibility)
    return dict(KINDS)
