"""Reading HDF5 files that suspopt wrote, as untrusted input.

A file given to ``kesort``, ``analyse`` or ``optimise --resume`` may be truncated, foreign or
crafted. :class:`H5Reader` reads it so that every problem is a
:class:`~suspopt.config.ConfigError` naming the file and the dataset or attribute at fault:
only regular files are opened; a dataset is read only if it is numeric, has the expected
number of dimensions (and columns) and fits in :data:`MAX_DATASET_BYTES` (a dataset may
declare 10^12 rows it never wrote); text attributes must be UTF-8 and at most
:data:`~suspopt.config.yamlio.MAX_CONFIG_BYTES` long. Nothing in a file is executed.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

import numpy as np

from .config import ConfigError
from .config.yamlio import MAX_CONFIG_BYTES

__all__ = ["H5Reader", "MAX_DATASET_BYTES"]

#: Largest dataset read from an input file [bytes]. A Pareto set of a million designs with a
#: hundred columns is 800 MB.
MAX_DATASET_BYTES = 1 << 30


class H5Reader:
    """An open HDF5 input file (a context manager); ``where`` starts every message (default
    the file's name)."""

    def __init__(self, path: str | Path, where: str | None = None):
        import h5py

        self.path = Path(path)
        self.where = where or str(self.path)
        try:
            mode = os.stat(self.path).st_mode
        except FileNotFoundError:
            raise ConfigError(f"{self.where}: no such file") from None
        except OSError as exc:
            raise ConfigError(f"{self.where}: cannot read it ({exc.strerror})") from None
        if not stat.S_ISREG(mode):
            raise ConfigError(f"{self.where}: not a regular file")
        try:
            self.file = h5py.File(self.path, "r")
        except (OSError, ValueError):
            raise ConfigError(f"{self.where}: not an HDF5 file (or a damaged one)") from None

    def __enter__(self) -> H5Reader:
        return self

    def __exit__(self, *exc) -> None:
        self.file.close()

    def _node(self, name: str):
        try:
            return self.file.get(name)
        except (OSError, ValueError, KeyError, RuntimeError):
            raise ConfigError(f"{self.where}: /{name}: damaged, cannot be read") from None

    def _kind(self, name: str, kind: str):
        """``/name`` if it is a ``kind`` (``Group`` or ``Dataset``), else ConfigError."""
        import h5py

        node = self._node(name)
        if not isinstance(node, getattr(h5py, kind)):
            raise ConfigError(
                f"{self.where}: /{name}: missing (is this a suspopt file of the right kind?)"
            )
        return node

    def group(self, name: str):
        """The group ``/name``."""
        return self._kind(name, "Group")

    def dataset(self, name: str):
        """The dataset ``/name``."""
        return self._kind(name, "Dataset")

    def array(
        self, name: str, ndim: int, columns: int | None = None, integer: bool = False
    ) -> np.ndarray:
        """The numeric dataset ``/name`` as float64 (int64 with ``integer``), checked to have
        ``ndim`` dimensions and ``columns`` columns."""
        ds = self.dataset(name)
        kind = ds.dtype.kind
        if kind not in ("i", "u", "f", "b") or (integer and kind == "f"):
            want = "whole numbers" if integer else "numbers"
            raise ConfigError(f"{self.where}: /{name}: holds {ds.dtype} values, not {want}")
        if ds.ndim != ndim:
            raise ConfigError(
                f"{self.where}: /{name}: expected {ndim} dimension"
                f"{'s' if ndim > 1 else ''}, got shape {ds.shape}"
            )
        if columns is not None and ds.shape[-1] != columns:
            raise ConfigError(
                f"{self.where}: /{name}: expected {columns} columns, got {ds.shape[-1]}"
            )
        if ds.size * 8 > MAX_DATASET_BYTES:
            raise ConfigError(
                f"{self.where}: /{name}: shape {ds.shape} is larger than "
                f"{MAX_DATASET_BYTES >> 20} MB: not a file of suspopt's"
            )
        try:
            values = ds[()]
        except (OSError, ValueError, RuntimeError):
            raise ConfigError(f"{self.where}: /{name}: damaged, cannot be read") from None
        return np.asarray(values, dtype=np.int64 if integer else np.float64)

    def text(self, value, name: str) -> str:
        """``value`` (an attribute or dataset element) as text."""
        if isinstance(value, np.ndarray) and value.ndim == 0:
            value = value[()]
        if isinstance(value, (bytes, np.bytes_)):
            if len(value) > MAX_CONFIG_BYTES:
                raise ConfigError(f"{self.where}: {name}: longer than {MAX_CONFIG_BYTES >> 10} kB")
            try:
                return bytes(value).decode("utf-8")
            except UnicodeDecodeError:
                raise ConfigError(f"{self.where}: {name}: not UTF-8 text") from None
        if not isinstance(value, str):
            raise ConfigError(f"{self.where}: {name}: not text")
        if len(value) > MAX_CONFIG_BYTES:
            raise ConfigError(f"{self.where}: {name}: longer than {MAX_CONFIG_BYTES >> 10} kB")
        return value

    def has_attr(self, key: str, node: str = "") -> bool:
        """Whether ``/node`` (the root by default) has the attribute ``key``."""
        obj = self.file if not node else self._node(node)
        try:
            return obj is not None and key in obj.attrs
        except (OSError, ValueError, TypeError, RuntimeError, KeyError):
            raise ConfigError(
                f"{self.where}: attributes of /{node}: damaged, cannot be read"
            ) from None

    def text_attr(self, key: str, node: str = "") -> str:
        """The text attribute ``key`` of ``/node`` (the root by default)."""
        obj = self.file if not node else self._node(node)
        label = f"attribute {key!r}" + (f" of /{node}" if node else "")
        if not self.has_attr(key, node):
            raise ConfigError(f"{self.where}: {label}: missing")
        try:
            value = obj.attrs[key]
        except (OSError, ValueError, TypeError, RuntimeError, KeyError):
            raise ConfigError(f"{self.where}: {label}: damaged, cannot be read") from None
        return self.text(value, label)

    def int_attr(self, node: str, key: str, low: int, high: int) -> int:
        """The whole-number attribute ``key`` of ``/node``, in ``[low, high]``."""
        obj = self._node(node)
        label = f"/{node}: attribute {key!r}"
        try:
            value = obj.attrs[key] if obj is not None and key in obj.attrs else None
        except (OSError, ValueError, TypeError, RuntimeError, KeyError):
            value = None
        if isinstance(value, np.ndarray) and value.ndim == 0:
            value = value[()]
        if (
            not isinstance(value, (int, np.integer))
            or isinstance(value, bool)
            or not low <= value <= high
        ):
            raise ConfigError(
                f"{self.where}: {label}: missing or not a whole number in [{low}, {high}]"
            )
        return int(value)

    def labels(self, name: str, key: str, columns: int) -> list[str]:
        """The per-column text attribute ``key`` (``names``, ``units``) of dataset ``/name``,
        one entry per column."""
        ds = self.dataset(name)
        label = f"/{name}: attribute {key!r}"
        try:
            raw = ds.attrs[key] if key in ds.attrs else None
        except (OSError, ValueError, TypeError, RuntimeError, KeyError):
            raise ConfigError(f"{self.where}: {label}: damaged, cannot be read") from None
        if raw is None:
            raise ConfigError(f"{self.where}: {label}: missing")
        entries = [self.text(v, label) for v in np.atleast_1d(raw)]
        if len(entries) != columns:
            raise ConfigError(
                f"{self.where}: {label}: {len(entries)} entries for {columns} columns"
            )
        return entries
