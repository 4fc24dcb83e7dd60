"""The arithmetic of the streamed metrics, written once and compiled (:mod:`._compiled`):
the running moments and extremes, the weighting filter and the weighted power sums, which
the metrics (:mod:`suspopt.metrics.stats`, :mod:`suspopt.metrics.iso2631`), the weighting
(:mod:`suspopt.weighting`), the numpy engine's windows (:mod:`suspopt.streaming`) and the
compiled kernel (:mod:`suspopt.integrator._accumulate`) all call."""

from __future__ import annotations

from typing import Any

from .._numba_cache import INSTALL_FAST, compiled_available

__all__ = ["compiled_reductions"]


def compiled_reductions() -> Any:
    """The module of the metrics' compiled arithmetic (:mod:`suspopt.loops._compiled`);
    :class:`suspopt.InputError` (one line on the command line, exit 2) saying so when
    numba, a dependency, cannot be imported."""
    if not compiled_available():
        from ..errors import InputError

        raise InputError(
            f"suspopt's metrics need numba, which cannot be imported here: {INSTALL_FAST}"
        )
    from . import _compiled

    return _compiled
