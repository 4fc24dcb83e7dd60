"""HDF5 output, written atomically: a temporary file in the target folder, then a rename.

Root attributes of every file: ``suspopt_version``, ``created`` (UTC ISO 8601), ``command``,
``config`` (the YAML text) and ``seed`` (the config's random seed, -1 when it draws nothing).
Every dataset carries a ``units`` attribute.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterable
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path

import h5py
import numpy as np

from . import __version__
from .config import Config

__all__ = ["atomic_h5", "write_dataset", "write_simulation", "read_simulation_signals"]


def _seed_of(cfg: Config) -> int:
    seed = getattr(cfg.road, "seed", None)
    return -1 if seed is None else int(seed)


@contextmanager
def atomic_h5(path: str | Path, cfg: Config, command: str | None = None):
    """Open a new HDF5 file for writing under a temporary name; rename it on success.

    On any exception the temporary file is removed and ``path`` is left untouched.
    """
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with h5py.File(tmp, "w") as h5:
            h5.attrs["suspopt_version"] = __version__
            h5.attrs["created"] = datetime.now(timezone.utc).isoformat(timespec="seconds")
            h5.attrs["command"] = command if command is not None else " ".join(sys.argv)
            h5.attrs["config"] = cfg.text
            h5.attrs["seed"] = _seed_of(cfg)
            yield h5
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_dataset(group: h5py.Group, name: str, data, units: str | list[str],
                  **attrs) -> h5py.Dataset:
    """Create ``group[name]`` with its ``units`` attribute (one string, or one per column) and
    any other attributes."""
    ds = group.create_dataset(name, data=data)
    ds.attrs["units"] = np.array(units, dtype="S") if isinstance(units, list) else units
    for key, value in attrs.items():
        ds.attrs[key] = value
    return ds


def write_simulation(path: str | Path, result, signals: Iterable[str] | None = None,
                     float32: bool = False, command: str | None = None) -> Path:
    """Write a simulation ``Result`` with the layout of DESIGN.md.

    ``/time (T,)``, ``/signals/<name> (P, T)``, ``/metrics/<name> (P,)``, ``/diverged_at (P,)``
    (NaN where the design did not diverge), ``/designs/X (P, n)`` with attr ``names`` when
    design parameters were given, and ``/modal/frequency (P, n)`` with attr ``dominant``.
    """
    from .vehicle import modal_analysis

    names = list(result.signals) if signals is None else list(signals)
    dtype = np.float32 if float32 else np.float64
    with atomic_h5(path, result.config, command) as h5:
        write_dataset(h5, "time", result.time, "s")
        grp = h5.create_group("signals")
        for name in names:
            write_dataset(grp, name, np.asarray(result.signals[name], dtype=dtype),
                     result.signal_unit(name))
        met = h5.create_group("metrics")
        for name, value in result.metrics.items():
            write_dataset(met, name, np.asarray(value), result.metric_units[name])
        write_dataset(h5, "diverged_at", result.diverged_at, "s")
        if result.designs:
            X = np.column_stack([result.designs[k] for k in result.designs])
            write_dataset(h5.create_group("designs"), "X", X, "SI",
                     names=np.array(list(result.designs), dtype="S"))
        modes = modal_analysis(result.model)
        write_dataset(h5.create_group("modal"), "frequency", modes.frequency, "Hz",
                 dominant=np.array(modes.dominant[0], dtype="S"))
    return Path(path)


def read_simulation_signals(path: str | Path) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Read ``/time`` and every ``/signals/<name>`` back from a simulate output file."""
    with h5py.File(path, "r") as h5:
        return h5["time"][()], {k: v[()] for k, v in h5["signals"].items()}
