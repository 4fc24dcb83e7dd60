"""The compiled loops of the metrics' arithmetic (:mod:`._compiled`: the weighting filter of
:mod:`suspopt.weighting`, the streamed block moments and power sums of
:mod:`suspopt.streaming`, each the numpy arithmetic it replaces, to the same bits), where
numba is installed."""

from __future__ import annotations

from typing import Any

from .._numba_cache import compiled_available

__all__ = ["compiled_reductions"]


def compiled_reductions() -> Any:
    """The module of compiled loops (:mod:`suspopt.loops._compiled`) when numba is installed,
    else None; the callers then run their numpy arithmetic."""
    if not compiled_available():
        return None
    from . import _compiled

    return _compiled
