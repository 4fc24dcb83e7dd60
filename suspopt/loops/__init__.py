"""The arithmetic of the streamed metrics, written once and compiled (:mod:`._compiled`):
the running moments and extremes, the weighting filter and the weighted power sums, which
the metrics (:mod:`suspopt.metrics.stats`, :mod:`suspopt.metrics.iso2631`), the weighting
(:mod:`suspopt.weighting`), the numpy engine's windows (:mod:`suspopt.streaming`) and the
compiled kernel (:mod:`suspopt.integrator._accumulate`) all call."""

from __future__ import annotations

from typing import Any

from .._numba_cache import compiled_available

__all__ = ["compiled_reductions"]


def compiled_reductions() -> Any:
    """The module of the metrics' compiled arithmetic (:mod:`suspopt.loops._compiled`);
    ImportError saying so when numba, a dependency, is missing."""
    if not compiled_available():
        raise ImportError("suspopt needs numba for its metrics: pip install numba")
    from . import _compiled

    return _compiled
