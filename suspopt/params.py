"""Design parameters: any numeric config field, addressed by its dotted path, as a (P,) array.

``simulate(cfg, params={"vehicle.corners.F1.spring.linear": k})`` runs ``P = len(k)`` designs in
one batch; every field not in ``params`` keeps its config value for all designs.
"""

from __future__ import annotations

import difflib
import functools
import re
from collections.abc import Mapping
from typing import Any, get_args

import annotated_types
import numpy as np

from .config import Config, ConfigError
from .config.loader import require_config
from .files import listed

__all__ = ["ParamView", "numeric_paths", "field_range", "field_unit", "one_per_run", "ONE_PER_RUN"]

#: Config sections and fields that are one per run: the simulator never reads them per design.
ONE_PER_RUN = {
    "simulation": "the simulation settings are one per run",
    "road": "the road is one per run",
    "output": "the output settings are one per run",
    "optimiser": "the optimiser settings are one per run",
    "vehicle.gravity": "gravity is one per run",
    "vehicle.corner_defaults": "corner_defaults are merged into the corners when the config "
    "loads; vary vehicle.corners.<corner>... instead",
}


def one_per_run(path: str) -> str | None:
    """Why the dotted ``path`` cannot vary between the designs of one batch, or None."""
    for prefix, why in ONE_PER_RUN.items():
        if path == prefix or path.startswith(prefix + "."):
            return why
    return None


def _walk(node: Any, prefix: str, out: dict[str, float]) -> None:
    if isinstance(node, dict):
        for key, value in node.items():
            _walk(value, f"{prefix}.{key}" if prefix else str(key), out)
    elif isinstance(node, (int, float)) and not isinstance(node, bool):
        out[prefix] = float(node)


def numeric_paths(cfg: Config) -> dict[str, float]:
    """Every numeric field of ``cfg`` by dotted path, with its value."""
    out: dict[str, float] = {}
    _walk(require_config(cfg).model_dump(), "", out)
    return out


@functools.cache
def _limits(model: Any, name: str) -> tuple[float, bool, float, bool]:
    """``(low, low_closed, high, high_closed)`` of a float field of a config section, read
    from its annotation's constraints (the ranges of :mod:`suspopt.config.base`)."""
    low, low_closed, high, high_closed = -np.inf, True, np.inf, True
    info = model.model_fields[name]
    metadata = list(info.metadata)
    for arg in get_args(info.annotation):  # Annotated[...] | None
        for inner in getattr(arg, "__metadata__", ()):
            metadata += getattr(inner, "metadata", [])
    for item in metadata:
        bound: Any  # (a number: the ranges of suspopt.config.base)
        if isinstance(item, annotated_types.Ge):
            bound = item.ge
            low, low_closed = float(bound), True
        elif isinstance(item, annotated_types.Gt):
            bound = item.gt
            low, low_closed = float(bound), False
        elif isinstance(item, annotated_types.Le):
            bound = item.le
            high, high_closed = float(bound), True
        elif isinstance(item, annotated_types.Lt):
            bound = item.lt
            high, high_closed = float(bound), False
    return low, low_closed, high, high_closed


def _section(cfg: Config, path: str) -> tuple[Any, str]:
    """The config section holding the field at the dotted ``path``, and the field's name."""
    node: Any = cfg
    parts = path.split(".")
    for part in parts[:-1]:
        node = node[part] if isinstance(node, dict) else getattr(node, part)
    return node, parts[-1]


def field_range(cfg: Config, path: str) -> tuple[float, bool, float, bool]:
    """The range a numeric config field accepts, ``(low, low_closed, high, high_closed)``
    (infinite where it has no bound)."""
    node, name = _section(cfg, path)
    section: Any = type(node)  # (a pydantic model class: hashable, as the cache needs)
    return _limits(section, name)


_UNIT = re.compile(r"\[([^\],]+)\]")


def field_unit(cfg: Config, path: str) -> str:
    """The SI unit of the numeric config field at ``path``, read from its description
    (``... [N/m]``: the last bracket); "SI" where the description names none."""
    node, name = _section(cfg, path)
    info = type(node).model_fields.get(name)
    found = _UNIT.findall(info.description or "") if info is not None else []
    return found[-1] if found else "SI"


def _check_range(cfg: Config, path: str, values: np.ndarray) -> None:
    """ConfigError unless every design's value lies in the field's range."""
    low, low_closed, high, high_closed = field_range(cfg, path)
    bad = (
        (values < low)
        | (values > high)
        | (~low_closed & (values == low))
        | (~high_closed & (values == high))
    )
    if bad.any():
        where = np.flatnonzero(bad)
        span = f"{'[' if low_closed else '('}{low:g}, {high:g}{']' if high_closed else ')'}"
        raise ConfigError(
            f"params: {path}: must be in {span}, got {values[where[0]]:g} "
            f"(designs {where[:5].tolist()})"
        )


class ParamView:
    """Read config values by dotted path, overridden per design by ``params``.

    ``get(path)`` returns a float64 array of shape (P,); ``P`` is the common length of the
    ``params`` arrays (1 when there are none; an empty array is a ConfigError).
    """

    def __init__(self, cfg: Config, params: Mapping[str, Any] | None = None):
        self.values = numeric_paths(cfg)
        if params is not None and not isinstance(params, Mapping):
            raise TypeError(
                "params must be a mapping of dotted config paths to arrays of designs, e.g. "
                f"{{'vehicle.corners.F1.damper.c': [1000.0, 2000.0]}}; got {type(params).__name__}"
            )
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
            if not arr.size:
                raise ConfigError(f"params: {path}: no designs (an empty array); give one or more")
            if not np.all(np.isfinite(arr)):
                raise ConfigError(f"params: {path}: values must be finite")
            _check_range(cfg, path, arr)
            sizes.add(arr.size)
            self.params[path] = arr
        if len(sizes) > 1:
            raise ConfigError(
                f"params: all design arrays must have the same length, got {sorted(sizes)}"
            )
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


# --- batches from the command line ---------------------------------------------------------

#: Most designs a sweep makes (a grid of several sweeps multiplies quickly).
MAX_SWEEP_DESIGNS = 1_000_000


def _split(item: str, option: str) -> tuple[str, str]:
    path, sep, value = item.partition("=")
    if not sep or not path.strip() or not value.strip():
        raise ConfigError(f"{option} {item!r}: expected PATH=VALUE")
    return path.strip(), value.strip()


def _numeric_type(annotation: Any) -> bool:
    """Whether a field's ``annotation`` admits a number (int or float, not bool), through
    ``Optional`` and ``Annotated``."""
    return annotation in (int, float) or any(_numeric_type(a) for a in get_args(annotation))


def _unset_numeric(cfg: Config, path: str) -> bool:
    """Whether ``path`` is a numeric field of an existing section that the config leaves
    unset (``optimiser.generations`` of a run budgeted by evaluations): ``--set`` gives it a
    value, as writing it in the YAML would."""
    try:
        node, name = _section(cfg, path)
    except (AttributeError, KeyError, TypeError):
        return False
    info = getattr(type(node), "model_fields", {}).get(name)
    return info is not None and getattr(node, name) is None and _numeric_type(info.annotation)


def _numeric_path(cfg: Config, path: str, option: str, unset: bool = False) -> None:
    """ConfigError unless ``path`` is a numeric field of ``cfg`` (or, with ``unset``, one it
    leaves unset), naming the closest ones."""
    paths = numeric_paths(cfg)
    if path not in paths and not (unset and _unset_numeric(cfg, path)):
        close = difflib.get_close_matches(path, list(paths), n=3)
        raise ConfigError(
            f"{option} {path}: not a numeric field of this config"
            + (f"; did you mean {', '.join(close)}?" if close else "")
        )


def apply_sets(cfg: Config, items: list[str]) -> Config:
    """``cfg`` with each ``PATH=VALUE`` of ``--set`` written into it: any numeric field,
    checked as if the YAML said so (the result's text is the edited YAML)."""
    from .config.loader import edit_config, set_path
    from .config.yamlio import YamlError, parse_yaml

    values = {}
    for item in listed(items):  # (one PATH=VALUE as a string: not letter by letter)
        path, text = _split(item, "--set")
        _numeric_path(cfg, path, "--set", unset=True)
        try:
            value, _ = parse_yaml(text)
        except YamlError:
            value = None
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise ConfigError(f"--set {item}: {text!r} is not a number")
        values[path] = value
    if not values:
        return cfg

    def put(data: dict) -> None:
        for path, value in values.items():
            set_path(data, path, value)

    described = ", ".join(f"{p} = {v!r}" for p, v in values.items())
    return edit_config(cfg.text, put, cfg.source, f"--set {described}")


def sweep(cfg: Config, items: list[str], zipped: bool = False) -> dict[str, np.ndarray]:
    """``params`` of ``--sweep PATH=START:STOP:N`` (each N values evenly spaced, ends
    included): the grid of all sweeps (every combination, the last sweep varying fastest),
    or with ``zipped`` their values side by side (every sweep the same N)."""
    ranges = {}
    for item in listed(items):
        path, text = _split(item, "--sweep")
        _numeric_path(cfg, path, "--sweep")
        why = one_per_run(path)
        if why is not None:
            raise ConfigError(
                f"--sweep {path}: cannot vary between the designs of one run: {why}; use --set"
            )
        parts = text.split(":")
        try:
            start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
            if len(parts) != 3:
                raise ValueError
        except (ValueError, IndexError):
            raise ConfigError(f"--sweep {item}: expected PATH=START:STOP:N") from None
        if not (np.isfinite(start) and np.isfinite(stop)) or not 1 <= count <= MAX_SWEEP_DESIGNS:
            raise ConfigError(
                f"--sweep {item}: START and STOP must be finite and N from 1 to {MAX_SWEEP_DESIGNS}"
            )
        if path in ranges:
            raise ConfigError(f"--sweep {path}: given twice")
        ranges[path] = np.linspace(start, stop, count)
    if not ranges:
        return {}
    if zipped:
        sizes = {len(v) for v in ranges.values()}
        if len(sizes) > 1:
            raise ConfigError(
                f"--zip: the sweeps have {sorted(sizes)} values; zipped sweeps need the same N"
            )
        return ranges
    total = int(np.prod([len(v) for v in ranges.values()], dtype=float))
    if total > MAX_SWEEP_DESIGNS:
        raise ConfigError(
            f"--sweep: the grid has {total} designs, more than "
            f"{MAX_SWEEP_DESIGNS}; use fewer values or --zip"
        )
    grid = np.meshgrid(*ranges.values(), indexing="ij")
    return {path: g.reshape(-1) for path, g in zip(ranges, grid)}
