"""The compiled loops of the metrics' arithmetic (:mod:`._loops`: the weighting filter, the
streamed block moments and power sums, each the numpy arithmetic it replaces, to the same
bits), where numba is installed."""

from __future__ import annotations

from typing import Any

from .._numba_cache import compiled_available

__all__ = ["compiled_reductions"]


def compiled_reductions() -> Any:
    """The module of compiled loops (:mod:`suspopt.metrics._loops`) when numba is installed,
    else None; the callers then run their numpy arithmetic."""
    if not compiled_available():
        return None
    from . import _loops

    return _loops
