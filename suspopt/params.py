"""Design parameters: any numeric config field, addressed by its dotted path, as a (P,) array.

``simulate(cfg, params={"vehicle.corners.F1.spring.linear": k})`` runs ``P = len(k)`` designs in
one batch; every field not in ``params`` keeps its config value for all designs.
"""

from __future__ import annotations

import difflib
from collections.abc import Mapping
from typing import Any

import numpy as np

from .config import Config, ConfigError

__all__ = ["ParamView", "numeric_paths"]


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
