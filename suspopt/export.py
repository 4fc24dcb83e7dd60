"""CSV export of a suspopt HDF5 file: every table it holds, one CSV file each, units in the header.

:func:`write_csv` reads any file suspopt wrote (``simulate``, ``optimise``, ``kesort``,
``analyse``) and writes its tables into a folder; ``/checkpoint`` (the optimiser's replay data,
in search coordinates) is left out. The tables follow from the datasets' dimensions
(:func:`suspopt.io.write_dataset`), group by group:

- a dataset of two or more dimensions whose last one holds names (``objective``,
  ``variable``, ``constraint``, ``supplementary``, ``dof``, ``corner``; or, in a file without
  dimension scales, its ``names`` attribute) is a wide table of its own, one row per design:
  ``/pareto/F`` gives ``design [1], f1 [(m/s^2)^2], f2 [m^2]`` (one unit per column);
- the other datasets of a group that share their dimensions form one long table: a column per
  dimension (its coordinate, one row per combination, the last dimension fastest), then one
  column per dataset. ``/signals`` gives ``design [1], time [s], body.heave [m], ...``, the
  rows of design 0 first; ``/metrics`` one row per design; the scalars of a group (``dims
  ()``, e.g. ``/kesort/picks``) one row.

The signals go into one file with a ``design`` column rather than one file per design: one
file whatever the batch size (a thousand designs would make a thousand files), the same rows
as ``suspopt.io.open_dataset(path, "signals").to_dataframe()``, ready to filter or pivot.

File names: ``<stem>.<group>.<dataset>.csv`` for a wide table and ``<stem>.<group>.csv`` for
a group's long table (``<stem>.csv`` for the root's), where ``stem`` is the HDF5 file's stem
and ``group`` its path joined by dots (characters other than letters, digits, ``_ . + -`` as
``_``); when a group has several long tables, each name ends in its dimensions joined by ``-``
(``scalars`` for the one-row table): ``ke.kesort.design.csv``, ``ke.kesort.tie.csv``,
``ke.kesort.scalars.csv``.

Format: UTF-8; the first line ``# written by suspopt <version> from <file> (<group>)`` (the
marker by which suspopt knows its outputs, :func:`suspopt.io.is_suspopt_output`), then the
header ``name [unit]`` and the rows, through Python's ``csv`` module (text quoted where it
needs to be). Numbers are written in full (``repr``: they read back bit for bit), NaN as
``nan``. ``pandas.read_csv(path, skiprows=1)`` reads a table.
"""

from __future__ import annotations

import csv
import re
import stat
from contextlib import ExitStack, contextmanager, suppress
from io import TextIOWrapper
from pathlib import Path
from typing import Any

import numpy as np

from ._version import __version__
from .errors import ConfigError
from .files import Unreadable, status

__all__ = ["write_csv"]

_SKIP = ("checkpoint",)
_ROWS = 20000  # rows per block written


def _text(values) -> list:
    return [
        v.decode("utf-8", "replace") if isinstance(v, bytes) else v
        for v in np.asarray(values).ravel().tolist()
    ]


def _is_text(ds) -> bool:
    return ds.dtype.kind in "SO"  # fixed-length bytes, variable-length strings


def _values(ds) -> np.ndarray:
    """The data of ``ds`` as a flat array (text decoded)."""
    if _is_text(ds):
        return np.array(_text(ds[()]), dtype=object)
    return np.asarray(ds[()]).ravel()


def _units(ds, columns: int) -> list[str]:
    raw = ds.attrs.get("units", "")
    units = _text(raw) if isinstance(raw, np.ndarray) and raw.ndim else [_text([raw])[0]]
    return units if len(units) == columns else [units[0] if units else ""] * columns


def _names(ds, dims) -> list[str] | None:
    """The column names of a wide table (module docstring), or None."""
    if ds.ndim < 2:
        return None
    scale = dims[-1][1]
    if scale is not None and _is_text(scale):
        return [str(v) for v in _text(scale[()])]
    names = ds.attrs.get("names")
    if names is not None and np.ndim(names) == 1 and len(names) == ds.shape[-1]:
        return [str(v) for v in _text(names)]
    return None


def _coordinate(name: str, scale, size: int) -> tuple[str, np.ndarray]:
    """Header and values of the index column of a dimension."""
    if scale is None:
        return f"{name} [1]", np.arange(size)
    return f"{name} [{_units(scale, 1)[0]}]", _values(scale)


def _index(dims, shape) -> tuple[list[str], list[np.ndarray]]:
    """Index columns: every combination of the coordinates, the last dimension fastest."""
    header, values = [], []
    for (name, scale), size in zip(dims, shape):
        title, coord = _coordinate(name, scale, size)
        header.append(title)
        values.append(coord)
    grids = np.meshgrid(*values, indexing="ij") if values else []
    return header, [g.ravel() for g in grids]


def _safe(part: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.+-]", "_", part)


def _plan(h5) -> list[tuple[str, str, list, list]]:
    """The tables of the file: (name, group path, datasets, dims) each; wide tables hold one
    dataset, long tables the datasets of one group with one set of dimensions."""
    import h5py

    from .h5read import MAX_DATASET_BYTES, dimension_scales

    groups = [h5]
    h5.visititems(
        lambda name, obj: (
            groups.append(obj)
            if isinstance(obj, h5py.Group) and name.split("/")[0] not in _SKIP
            else None
        )
    )
    tables = []
    for group in groups:
        parts = [_safe(p) for p in group.name.split("/") if p]
        wide: list[tuple] = []
        long: dict[tuple, tuple[Any, list]] = {}
        for name, ds in group.items():
            if not isinstance(ds, h5py.Dataset) or ds.is_scale or ds.dtype.kind not in "biufSO":
                continue
            if ds.size * max(ds.dtype.itemsize, 8) > MAX_DATASET_BYTES:
                raise ConfigError(
                    f"{h5.filename}: {ds.name}: shape {ds.shape} is larger than "
                    f"{MAX_DATASET_BYTES >> 20} MB: not a file of suspopt's"
                )
            dims = dimension_scales(ds)
            if _names(ds, dims) is not None:
                wide.append((".".join(parts + [_safe(name)]), group.name, [ds], dims))
            else:
                key = tuple((d, getattr(s, "name", None), n) for (d, s), n in zip(dims, ds.shape))
                long.setdefault(key, (dims, []))[1].append(ds)
        for dims, members in long.values():
            label = [] if len(long) == 1 else ["-".join(_safe(d) for d, _ in dims) or "scalars"]
            tables.append((".".join(parts + label), group.name, members, dims))
        tables.extend(wide)
    return tables


def _columns(members, dims) -> tuple[list[str], list[np.ndarray]]:
    """Header and columns of a table (module docstring)."""
    first = members[0]
    names = _names(first, dims)
    if names is not None:  # wide: one dataset, a column per name
        header, index = _index(dims[:-1], first.shape[:-1])
        data = _values(first).reshape(-1, len(names))
        units = _units(first, len(names))
        return (
            header + [f"{n} [{u}]" for n, u in zip(names, units)],
            index + [data[:, j] for j in range(len(names))],
        )
    header, index = _index(dims, first.shape)
    return (
        header + [f"{ds.name.rsplit('/', 1)[-1]} [{_units(ds, 1)[0]}]" for ds in members],
        index + [_values(ds) for ds in members],
    )


def _write_table(stream, comment: str, header: list[str], columns: list[np.ndarray]) -> None:
    text = TextIOWrapper(stream, encoding="utf-8", newline="")
    try:
        text.write(comment)
        writer = csv.writer(text, lineterminator="\n")
        writer.writerow(header)
        for start in range(0, len(columns[0]) if columns else 0, _ROWS):
            writer.writerows(zip(*(c[start : start + _ROWS].tolist() for c in columns)))
        text.flush()
    finally:
        text.detach()


def write_csv(h5_path: str | Path, folder: str | Path, force: bool = False) -> list[Path]:
    """Write every table of the suspopt HDF5 file ``h5_path`` as a CSV file in ``folder``
    (made if missing; its parent must exist) and return their paths (module docstring).

    The files are written atomically (:func:`!suspopt.io.atomic_file`), and together: none
    is renamed into place before every one is written. A file of that name in
    ``folder`` that suspopt did not write is not replaced unless ``force``: every target is
    checked before any is written. ConfigError (naming the file) for a file that is not a
    suspopt HDF5 file or a folder that cannot be written.
    """
    from .h5read import H5Reader
    from .io import atomic_file, check_target

    h5_path, folder = Path(h5_path), Path(folder)
    with H5Reader(h5_path) as reader:
        if not reader.has_attr("suspopt_version"):
            raise ConfigError(
                f"{h5_path}: not a file suspopt wrote (no root attribute 'suspopt_version')"
            )
        with _reading(h5_path):
            tables = _plan(reader.file)
        try:
            found = status(folder)
        except Unreadable as exc:
            raise ConfigError(f"--csv {folder}: {exc}") from None
        made = found is None
        if found is not None and not stat.S_ISDIR(found.st_mode):  # (mkdir: "File exists")
            raise ConfigError(f"--csv {folder}: is not a folder")
        try:
            folder.mkdir(exist_ok=True)
        except OSError as exc:
            raise ConfigError(f"--csv {folder}: cannot make the folder ({exc.strerror})") from None
        stem, names, targets = _safe(h5_path.stem), set(), []
        for name, *_ in tables:
            file = f"{stem}.{name}" if name else stem
            while file in names:
                file += "_"
            names.add(file)
            targets.append(check_target(folder / f"{file}.csv", force, "--csv"))
        # every file is renamed into place only once all are written (the stack's exit):
        # a failure on any (a damaged table, a full disk) leaves none of them
        try:
            with ExitStack() as written:
                for target, (_, group, members, dims) in zip(targets, tables):
                    with _reading(h5_path):
                        header, columns = _columns(members, dims)
                    comment = (
                        f"# written by suspopt {__version__} from "
                        f"{' '.join(str(h5_path).splitlines())} ({group})\n"
                    )
                    stream = written.enter_context(atomic_file(target, force))
                    _write_table(stream, comment, header, columns)
        except BaseException:
            if made:  # (the folder this call made, left empty)
                with suppress(OSError):
                    folder.rmdir()
            raise
    return targets


@contextmanager
def _reading(h5_path: Path):
    """Errors of libhdf5 reading a damaged file as ConfigError naming it."""
    try:
        yield
    except ConfigError:
        raise
    except (OSError, RuntimeError, KeyError, ValueError, TypeError) as exc:
        raise ConfigError(
            f"{h5_path}: damaged, cannot be read ({' '.join(str(exc).split())[:120]})"
        ) from None
