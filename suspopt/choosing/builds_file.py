"""An ``analyse builds`` file read back for ``suspopt kesort --builds``: each design's share
of feasible builds (:func:`feasible_builds`) and a percentile of each of its objectives over
its builds (:func:`as_built_objectives`, ``kesort --as-built``).

Both check that the file holds the builds of every design of the front it is given for
(its ``/pareto/X`` is the front's, and it is no ``--pick`` file), and read only what they
use, through :class:`suspopt.h5read.H5Reader` (bad input in one line naming the file and
the dataset).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TypeVar

import numpy as np

from ..errors import ConfigError

__all__ = ["feasible_builds", "as_built_objectives"]

T = TypeVar("T")


def _read(path: str | Path, front: str | Path, read: Callable[..., T]) -> T:
    """``read(h5, D)`` of the ``analyse builds`` file ``path`` of the Pareto file ``front``
    (``D`` its number of designs), once the file is found to hold the builds of every design
    of that front; ConfigError naming ``--builds PATH`` otherwise."""
    from ..h5read import H5Reader
    from .selection import read_pareto

    own = read_pareto(front).X
    with H5Reader(path, where=f"--builds {path}") as h5:
        if not h5.has_attr("analysis") or h5.text_attr("analysis") != "builds":
            raise ConfigError(f"--builds {path}: not a file of suspopt analyse builds")
        X = h5.array("pareto/X", ndim=2)
        if "pareto/source_row" in h5.file:
            raise ConfigError(
                f"--builds {path}: holds the builds of {len(X)} picked design(s) (--pick); "
                f"kesort needs the builds of every design of {front}: build them all"
            )
        if X.shape != own.shape or not np.array_equal(X, own):
            raise ConfigError(
                f"--builds {path}: its designs (/pareto/X) are not those of {front}: give the "
                f"builds of that front"
            )
        return read(h5, len(own))


def feasible_builds(path: str | Path, front: str | Path) -> np.ndarray:
    """``(D,)`` the share of feasible builds of each design of the Pareto file ``front``, from
    the ``analyse builds`` file ``path`` of that front (``suspopt kesort --builds``);
    ConfigError naming the file when it is no builds file, or one of another front (its
    ``/pareto/X`` differs from the front's)."""

    def read(h5, D: int) -> np.ndarray:
        share = h5.array("builds/feasible_share", ndim=1)
        if len(share) != D or not ((share >= 0) & (share <= 1)).all():
            raise ConfigError(
                f"--builds {path}: /builds/feasible_share: not one share in [0, 1] per design"
            )
        return share

    return _read(path, front, read)


def as_built_objectives(
    path: str | Path, front: str | Path, names: Sequence[str], percentile: float
) -> np.ndarray:
    """``(D, len(names))`` the ``percentile`` [%] of each objective ``names`` (main or
    supplementary) over each design's builds, from the ``analyse builds`` file ``path`` of
    the Pareto file ``front``: ``/builds/F`` and ``/builds/S (sample, design, objective)``,
    the builds that failed to simulate (``/builds/failed``) left out; NaN for a design all
    of whose builds failed (``numpy.nanpercentile``, linear interpolation between builds).
    ConfigError naming the file for an objective it does not hold (builds made under another
    config), a dataset of the wrong shape, or a value that is not finite in a build that
    simulated (a damaged file)."""

    def read(h5, D: int) -> np.ndarray:
        failed = h5.array("builds/failed", ndim=2).astype(bool)
        N = failed.shape[0]
        if failed.shape != (N, D) or N < 1:
            raise ConfigError(
                f"--builds {path}: /builds/failed: shape {failed.shape}, not (builds, {D})"
            )
        columns: dict[str, tuple[str, np.ndarray]] = {}
        for key in ("F", "S"):
            if key == "S" and h5._node("builds/S") is None:
                continue
            values = h5.array(f"builds/{key}", ndim=3)
            labels = h5.labels(f"builds/{key}", "names", values.shape[2])
            if values.shape[:2] != (N, D):
                raise ConfigError(
                    f"--builds {path}: /builds/{key}: shape {values.shape}, not ({N}, {D}, ...)"
                )
            for j, label in enumerate(labels):
                columns.setdefault(label, (key, values[:, :, j]))
        missing = [name for name in names if name not in columns]
        if missing:
            raise ConfigError(
                f"--builds {path}: holds no builds of {', '.join(missing)} (it has "
                f"{', '.join(columns)}): give builds made under the config the sort uses"
            )
        for name in names:
            key, values = columns[name]
            bad = np.argwhere(~failed & ~np.isfinite(values))
            if len(bad):
                raise ConfigError(
                    f"--builds {path}: /builds/{key}: {name} of build {bad[0][0]} of design "
                    f"{bad[0][1]} is {values[tuple(bad[0])]}, though that build simulated: damaged"
                )
        stacked = np.stack([np.where(failed, np.nan, columns[n][1]) for n in names], axis=2)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # (every build failed: NaN)
            return np.nanpercentile(stacked, percentile, axis=0)

    return _read(path, front, read)
