"""Design parameters: any numeric config field, addressed by its dotted path, as a (P,) array.

``simulate(cfg, params={"vehicle.corners.F1.spring.linear": k})`` runs ``P = len(k)`` designs in
one batch; every field not in ``params`` keeps its config value for all designs.
"""

from __future__ import annotations

import difflib
import functools
from collections.abc import Mapping
from typing import Any, get_args

import annotated_types
import numpy as np

from .config import Config, ConfigError

__all__ = ["ParamView", "numeric_paths", "field_range"]


def _walk(node: Any, prefix: str, out: dict[str, float]) -> None:
    if isinstance(node, dict):
        for key, value in node.items():
            _walk(value, f"{prefix}.{key}" if prefix else str(key), out)
    elif isinstance(node, (int, float)) and not isinstance(node, bool):
        out[prefix] = float(node)


def numeric_paths(cfg: Config) -> dict[str, float]:
    """Every numeric field of ``cfg`` by dotted path, with its value."""
    out: dict[str, float] = {}
    _walk(cfg.model_dump(), "", out)
    return out


@functools.cache
def _limits(model: type, name: str) -> tuple[float, bool, float, bool]:
    """``(low, low_closed, high, high_closed)`` of a float field of a config section, read
    from its annotation's constraints (the ranges of :mod:`suspopt.config.base`)."""
    low, low_closed, high, high_closed = -np.inf, True, np.inf, True
    info = model.model_fields[name]
    metadata = list(info.metadata)
    for arg in get_args(info.annotation):           # Annotated[...] | None
        for inner in getattr(arg, "__metadata__", ()):
            metadata += getattr(inner, "metadata", [])
    for item in metadata:
        if isinstance(item, annotated_types.Ge):
            low, low_closed = float(item.ge), True
        elif isinstance(item, annotated_types.Gt):
            low, low_closed = float(item.gt), False
        elif isinstance(item, annotated_types.Le):
            high, high_closed = float(item.le), True
        elif isinstance(item, annotated_types.Lt):
            high, high_closed = float(item.lt), False
    return low, low_closed, high, high_closed


def field_range(cfg: Config, path: str) -> tuple[float, bool, float, bool]:
    """The range a numeric config field accepts, ``(low, low_closed, high, high_closed)``
    (infinite where it has no bound)."""
    node: Any = cfg
    parts = path.split(".")
    for part in parts[:-1]:
        node = node[part] if isinstance(node, dict) else getattr(node, part)
    return _limits(type(node), parts[-1])


def _check_range(cfg: Config, path: str, values: np.ndarray) -> None:
    """ConfigError unless every design's value lies in the field's range."""
    low, low_closed, high, high_closed = field_range(cfg, path)
    bad = (values < low) | (values > high) | (~low_closed & (values == low)) \
        | (~high_closed & (values == high))
    if bad.any():
        where = np.flatnonzero(bad)
        span = f"{'[' if low_closed else '('}{low:g}, {high:g}{']' if high_closed else ')'}"
        raise ConfigError(f"params: {path}: must be in {span}, got {values[where[0]]:g} "
                          f"(designs {where[:5].tolist()})")


class ParamView:
    """Read config values by dotted path, overridden per design by ``params``.

    ``get(path)`` returns a float64 array of shape (P,); ``P`` is the common length of the
    ``params`` arrays (1 when there are none).
    """

    def __init__(self, cfg: Config, params: Mapping[str, Any] | None = None):
        self.values = numeric_paths(cfg)
        self.params: dict[str, np.ndarray] = {}
        sizes = set()
        for path, value in (params or {}).items():
            if path not in self.values:
                close = difflib.get_close_matches(path, list(self.values), n=3)
                hint = f"; did you mean {', '.join(close)}?" if close else ""
                raise ConfigError(f"params: {path}: not a numeric field of this config{hint}")
            arr = np.atleast_1d(np.asarray(value, dtype=float))
            if arr.ndim != 1:
                raise ConfigError(f"params: {path}: values must be a 1-D array of designs")
            if not np.all(np.isfinite(arr)):
                raise ConfigError(f"params: {path}: values must be finite")
            _check_range(cfg, path, arr)
            sizes.add(arr.size)
            self.params[path] = arr
        if len(sizes) > 1:
            raise ConfigError(f"params: all design arrays must have the same length, got "
                              f"{sorted(sizes)}")
        self.P = sizes.pop() if sizes else 1

    def get(self, path: str) -> np.ndarray:
        """Value of ``path`` for every design, shape (P,)."""
        if path in self.params:
            return self.params[path]
        return np.full(self.P, self.values[path])

    def varies(self, prefix: str) -> list[str]:
        """Design-parameter paths under ``prefix``."""
        return [p for p in self.params if p == prefix or p.startswith(prefix + ".")]

    def require_positive(self, path: str) -> np.ndarray:
        """``get(path)``, checking every design's value is > 0."""
        value = self.get(path)
        bad = np.flatnonzero(value <= 0)
        if bad.size:
            raise ConfigError(f"params: {path}: must be > 0 (designs {bad[:5].tolist()})")
        return value
