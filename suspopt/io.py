"""Output files: checked targets, one writer at a time, written atomically.

**Targets** (:func:`check_target`): an output is a regular file or a new name in an existing
folder. An empty name, a directory, a device (``/dev/null``), a FIFO, a socket or a symbolic
link is bad input, and so is an existing file that suspopt did not write (an HDF5 file without
the root attribute ``suspopt_version``, or another file without the word ``suspopt`` in its
first 4 kB: suspopt writes it into every figure and text it makes) unless ``force``. A
config (``init``, ``export -o``) ends in a signature line, the SHA-256 of the lines above it
(:func:`suspopt.signature.signed_config`): it is suspopt's only while they are unedited, and
a ``.yaml`` or ``.yml`` file without a signature is the user's. An output that is the same file as one of
the command's inputs is bad input even with ``force`` (:func:`claim`).

**One writer** (:func:`claim`): a writer holds an exclusive ``flock`` on ``.NAME.suspopt-lock``
beside the target for as long as it writes (``suspopt optimise``: the whole run), so a second
run on the same output fails at once with the first one's process id. Holding the lock, it
removes what a killed run left behind, its lock and the temporary files ``.NAME.*.suspopt-tmp``
(no live writer can own them), and says so in one line that the command line prints as
``note: ...`` (:func:`take_notes`; the lock file's contents: :mod:`suspopt.locks`).

**Atomic writes** (:func:`atomic_file`, :func:`atomic_h5`): the file is written to a temporary
file created exclusively, with an unpredictable name, in the target's folder, through the
descriptor it was created with (a link planted at that name is never followed), flushed to
disk (``fsync``), then renamed over the target, and the folder synced. A killed or failed
write leaves the target as it was.

Root attributes of every HDF5 file (:data:`suspopt.formats.ROOT_ATTRIBUTES`):
``suspopt_version``, ``created`` (UTC ISO 8601), ``command``, ``config`` (the YAML text) and
``seed`` (the config's random seed, -1 when it draws nothing); of a command's output (a
:func:`claim` with a guard) also ``request`` and, with a figure, ``plot``
(:mod:`suspopt.replacing`, which says what such a file may be replaced by). Every dataset
carries a ``units`` attribute, and is made as its file's format declares it (:func:`put`).

**Dimensions** (:func:`write_dataset`, the one writer of every dataset): each axis of a dataset
is attached to an HDF5 dimension scale, the netCDF-4 way, so that xarray (engine
``h5netcdf``), netCDF tools and pandas see named dimensions with coordinates: ``time`` [s],
``design`` (row numbers), ``objective``, ``variable``, ``constraint`` (names, as text) and the
like (docs/guide/results.md). A dimension's scale is a 1-D dataset of that name in
the dataset's group or a group above it; one name means one length along every path of groups,
so the whole file also opens as an ``xarray.DataTree``. Names, text data and text attributes
are variable-length UTF-8 strings. :func:`open_dataset` reads a group back as an
``xarray.Dataset``.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import stat
import sys
import tempfile
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from ._version import __version__
from .config import Config, ConfigError
from .files import Unreadable, link_kind, status
from .formats import FileFormat
from .h5read import open_dataset  # (suspopt.io.open_dataset, as docs/guide/results.md reads it)
from .locks import take_lock, take_notes, this_command
from .replacing import (
    OUTPUT_MARKER,
    Guard,
    _not_ours,
    admit,
    deferred,
    is_suspopt_output,
    remove_figure,
)

__all__ = [
    "OUTPUT_MARKER",
    "take_notes",
    "this_command",
    "WRITE_ERRNOS",
    "WriteError",
    "check_target",
    "claim",
    "is_output",
    "atomic_file",
    "atomic_h5",
    "put",
    "commit",
    "check_replace",
    "config_inputs",
    "check_not_input",
    "write_dataset",
    "write_attrs",
    "text_array",
    "write_simulation",
    "write_tables",
    "root_attrs",
    "read_simulation_signals",
    "open_dataset",
    "is_suspopt_output",
]

#: Written into every non-HDF5 file suspopt makes (figure metadata, a comment), so that it
#: can tell its own outputs from other files.
_TMP = ".suspopt-tmp"
#: Locks this process holds: resolved target -> [descriptor, depth, force, guard].
_held: dict[Path, list] = {}


def _seed_of(cfg: Config) -> int:
    seed = getattr(cfg.road, "seed", None)
    return -1 if seed is None else int(seed)


def check_target(path: str | Path, force: bool = False, option: str = "-o") -> Path:
    """``path`` if suspopt may write it (module docstring), else ConfigError naming
    ``option``."""
    text = str(path)
    if not text.strip():
        raise ConfigError(f"{option}: an empty file name")
    path = Path(path)
    if text.endswith(os.sep) or path.name in ("", ".", ".."):
        raise ConfigError(f"{option} {path}: names a folder, not a file")
    folder = path.parent
    try:
        found = status(folder)
    except Unreadable as exc:  # (a name too long, a folder that may not be searched)
        raise ConfigError(f"{option} {path}: folder {folder}: {exc}") from None
    if found is not None and not stat.S_ISDIR(found.st_mode):
        raise ConfigError(f"{option} {path}: {folder} is not a folder")
    try:  # (a relative name in a working folder that was deleted: '.' is still a folder)
        exists = found is not None and folder.resolve(strict=True).is_dir()
    except OSError:
        exists = False
    if not exists:
        raise ConfigError(f"{option} {path}: folder {folder} does not exist")
    try:
        exists, kind = link_kind(path)
    except OSError as exc:
        raise ConfigError(f"{option} {path}: cannot inspect it ({exc.strerror})") from None
    if not exists:
        return path
    if kind is not None:
        raise ConfigError(
            f"{option} {path}: is {kind}; an output must be a regular file or a new name"
        )
    if not force:
        try:
            why = _not_ours(path)
        except OSError as exc:
            raise ConfigError(f"{option} {path}: cannot read it ({exc.strerror})") from None
        if why is not None:
            raise ConfigError(f"{option} {path}: {why}; give --force to replace it")
    return path


def _key(path: Path) -> Path:
    return path.parent.resolve() / path.name


def _same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name the same file: the same inode where both exist (links
    and other spellings of a path included), else the same folder and name."""
    with contextlib.suppress(OSError):  # (one of them does not exist: compare names)
        return os.path.samefile(a, b)
    try:
        return _key(a) == _key(b)
    except OSError:  # (a working folder that was deleted: check_target says so)
        return False


def is_output(path: str | Path) -> bool:
    """Whether ``path`` is the same file as an output claimed now (:func:`claim`): an
    input that the running command would replace."""
    return any(_same_file(Path(path), key) for key in _held)


def check_not_input(
    path: str | Path, inputs: Iterable[tuple[str, str | Path]], option: str = "-o"
) -> None:
    """ConfigError when ``path`` is the same file as one of ``inputs`` (``(what, path)``
    pairs; another spelling, a hard or a symbolic link count), which writing it would
    replace."""
    for given, source in inputs:
        if str(path).strip() and _same_file(Path(path), Path(source)):
            raise ConfigError(
                f"{option} {path}: is the same file as {given} {source}, which writing it "
                "would replace; choose another output"
            )


@contextmanager
def claim(
    path: str | Path,
    force: bool = False,
    option: str = "-o",
    inputs: Iterable[tuple[str, str | Path]] = (),
    command: str | None = None,
    guard: Guard | None = None,
) -> Iterator[Path]:
    """Check ``path`` (:func:`check_target`), hold the writer's lock of it (module docstring)
    and clear the temporary files of dead writers; ConfigError when another process writes
    it, or when it is one of the command's ``inputs`` (``(option, path)`` pairs: a file the
    command reads, or its other output), which writing would replace or overwrite, whatever
    ``force`` says (``kesort front.h5 -o front.h5`` replaced the front). Re-entrant in one
    process; a write inside the block may replace the file when ``force`` was given here.

    What a killed run left (its lock and temporary files) is removed and said in a line for
    :func:`take_notes`. ``command``: what the lock file says this run is (default: this
    process's command line, :func:`this_command`). ``guard``: what the result written there
    may replace (:func:`suspopt.replacing.refusal`, checked by :func:`atomic_h5`)."""
    check_not_input(path, inputs, option)
    path = check_target(path, force, option)
    key = _key(path)
    if key in _held:
        _held[key][1] += 1
        try:
            yield path
        finally:
            _held[key][1] -= 1
        return
    lock, fd = take_lock(path, option, command, _TMP)
    _held[key] = [fd, 1, force, guard]
    try:
        yield path
    finally:
        del _held[key]
        try:
            lock.unlink(missing_ok=True)
        finally:
            os.close(fd)


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


class WriteError(ConfigError):
    """An output that could not be written (:data:`WRITE_ERRNOS`); the file is as it was."""


#: What a write may fail with that the user, not suspopt, has to mend: a full disk or quota,
#: a file too large for the file system, a read-only file system, an I/O error.
WRITE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS, errno.EIO})


@contextmanager
def atomic_file(
    path: str | Path, force: bool = False, inputs: Iterable[tuple[str, str | Path]] = ()
) -> Iterator:
    """A binary file object that becomes ``path`` when the block ends without an exception
    (module docstring); ``path`` is checked with :func:`check_target` first (with the
    ``force`` of an enclosing :func:`claim`). A write that fails for a reason in
    :data:`WRITE_ERRNOS` (a full disk) is a :class:`WriteError` naming ``path``, which is
    left as it was (a traceback before)."""
    path = Path(path)
    try:
        with _atomic_file(path, force, inputs) as stream:
            yield stream
    except OSError as exc:
        if exc.errno not in WRITE_ERRNOS:
            raise
        raise WriteError(f"{path}: cannot write it ({exc.strerror})") from None


@contextmanager
def _atomic_file(path: Path, force: bool, inputs: Iterable[tuple[str, str | Path]]) -> Iterator:
    try:  # (the folder: the one look-up, as check_target's, which words what is wrong)
        parent = status(path.parent)
    except Unreadable:
        parent = None
    held = _held.get(_key(path)) if parent is not None and stat.S_ISDIR(parent.st_mode) else None
    force = force or (held is not None and held[2])
    with claim(path, force, inputs=inputs):
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=_TMP, dir=path.parent)
        try:
            os.fchmod(fd, 0o666 & ~_umask())  # mkstemp's 0600 is for the temp name only
            with os.fdopen(fd, "w+b") as stream:
                yield stream
                stream.flush()
                os.fsync(stream.fileno())
            if not deferred(_key(path), Path(tmp)):  # (else renamed with its group)
                commit(Path(tmp), path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise


def commit(tmp: Path, path: Path) -> None:
    """Rename the written temporary file ``tmp`` over ``path`` (nothing having taken its
    place meanwhile) and sync the folder."""
    check_target(path, force=True)
    os.replace(tmp, path)
    try:
        folder = os.open(path.parent, os.O_RDONLY | os.O_DIRECTORY)
    except OSError:
        return
    try:
        with contextlib.suppress(OSError):  # a folder some file systems cannot sync
            os.fsync(folder)
    finally:
        os.close(folder)


@contextmanager
def atomic_h5(
    path: str | Path,
    cfg: Config,
    command: str | None = None,
    force: bool = False,
    inputs: Iterable[tuple[str, str | Path]] = (),
):
    """A new HDF5 file written atomically (:func:`atomic_file`) with the root attributes of
    every suspopt file. On any exception ``path`` is left untouched. ``path`` may not be one
    of ``inputs``, nor ``cfg``'s own file or road profile (:func:`config_inputs`): the
    library's writers replaced them (``optimise(cfg, "study.yaml")`` wrote over the config)
    where the command line refused."""
    import h5py

    guard = _guarded(Path(path), cfg, force)
    with atomic_file(path, force, [*config_inputs(cfg), *inputs]) as stream:
        with h5py.File(stream, "w") as h5:
            h5.attrs.update(root_attrs(cfg, command))
            if guard is not None:
                h5.attrs["request"] = json.dumps(guard.request)
                if guard.plot is not None:
                    h5.attrs["plot"] = os.path.relpath(guard.plot, Path(path).parent)
            yield h5
    if guard is not None and guard.stale is not None:  # (the figure of the result replaced)
        remove_figure(guard.stale)
        guard.stale = None


def check_replace(path: str | Path, cfg: Config) -> None:
    """ConfigError when the command that claimed ``path`` may not replace what it holds with
    a result of ``cfg`` (:func:`suspopt.replacing.refusal`): said before a long run starts,
    not at its first write."""
    _guarded(Path(path), cfg, False)


def _guarded(path: Path, cfg: Config, force: bool) -> Guard | None:
    """The guard a command's claim of ``path`` holds, once it lets ``cfg``'s result replace
    what ``path`` holds (:func:`suspopt.replacing.admit`; checked on the first write);
    ConfigError saying why when it does not."""
    try:
        held = _held.get(_key(path))
    except OSError:
        return None
    guard = held[3] if held is not None else None
    if guard is not None:
        if force:
            guard.force = True
        admit(path, cfg.text, guard, cfg.source)
    return guard


def root_attrs(cfg: Config, command: str | None = None) -> dict:
    """The root attributes of every suspopt HDF5 file (module docstring), written now:
    ``command`` default this process's command line."""
    return {
        "suspopt_version": __version__,
        "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "command": command if command is not None else " ".join(sys.argv),
        "config": cfg.text,
        "seed": _seed_of(cfg),
    }


def config_inputs(cfg: Config) -> list[tuple[str, Path]]:
    """The files ``cfg`` was read from: its own (when it has one) and its road profile."""
    from .config.loader import require_config
    from .config.road import FileRoad, resolve_road_file

    source = require_config(cfg).source
    found = [("the config", Path(source))] if source is not None else []
    if isinstance(cfg.road, FileRoad):
        found.append(("the road profile", resolve_road_file(cfg.road, cfg.base_dir)))
    return found


def text_array(values) -> np.ndarray:
    """``values`` (strings or bytes, any shape) as an array of variable-length UTF-8 strings."""
    import h5py

    items = np.asarray(values, dtype=object)
    flat = [
        v.decode("utf-8") if isinstance(v, (bytes, np.bytes_)) else str(v) for v in items.ravel()
    ]
    return np.array(flat, dtype=h5py.string_dtype()).reshape(items.shape)


def _is_text(value) -> bool:
    """Whether ``value`` is an array or sequence of strings (not one string)."""
    if isinstance(value, np.ndarray) and value.dtype.kind != "O":
        return value.dtype.kind in "US"
    if not isinstance(value, (list, tuple, np.ndarray)):
        return False
    items = np.asarray(value, dtype=object).ravel()
    return items.size > 0 and all(isinstance(v, (str, bytes)) for v in items)


def write_attrs(obj, **attrs) -> None:
    """Set the attributes of ``obj`` (a file, group or dataset): sequences of strings as
    variable-length UTF-8 strings, anything else as given (h5py writes ``str`` as UTF-8)."""
    for key, value in attrs.items():
        obj.attrs[key] = text_array(value) if _is_text(value) else value


def _text_values(ds) -> list:
    """The values of the 1-D dataset ``ds``, text decoded."""
    values = ds[()]
    return [v.decode("utf-8") if isinstance(v, bytes) else v for v in values.tolist()]


def _find_scale(group, dim: str):
    """The dimension scale ``dim`` in ``group`` or the nearest group above it, or None."""
    node = group
    while True:
        found = node.get(dim)
        if found is not None and getattr(found, "is_scale", False):
            return found
        if node.name == "/":
            return None
        node = node.parent


def _scale(group, dim: str, size: int, values=None):
    """The scale of dimension ``dim`` for an axis of length ``size`` in ``group``
    (:func:`_find_scale`), else a new one in ``group`` holding ``values`` (default the row
    numbers 0 ... size-1)."""
    found = _find_scale(group, dim)
    if found is None:
        return write_dataset(
            group, dim, np.arange(size) if values is None else values, "1", dims=(dim,)
        )
    if found.shape != (size,):
        raise ValueError(
            f"{group.name}: dimension {dim!r} of length {size}, but {found.name} "
            f"has {found.shape[0]}"
        )
    if values is not None and _text_values(found) != list(values):
        raise ValueError(
            f"{group.name}: dimension {dim!r}: {list(values)} are not the values of {found.name}"
        )
    return found


def write_dataset(
    group,
    name: str,
    data,
    units: str | Sequence[str],
    dims: Sequence[str] = (),
    coords: dict | None = None,
    names: Sequence[str] | None = None,
    **attrs,
):
    """Create ``group[name]`` holding ``data``, with its ``units`` attribute (one string, or
    one per column) and its dimensions (module docstring); return the dataset.

    ``dims`` names every axis (``()`` for a scalar). Each is attached to the dimension scale
    of that name in ``group`` or the nearest group above it; where there is none, one is made
    in ``group`` holding ``coords[dim]`` (names as text, units ``1``) or, without, the row
    numbers 0 ... n-1 (``design``, ``mode``, ...). A 1-D dataset whose dimension is its own
    name is that dimension's scale (``time``). ``names``, the columns' names, is written as
    the attribute ``names`` and is the coordinate of the last dimension. Text data, ``names``,
    per-column ``units`` and text attributes are written as variable-length UTF-8 strings.
    """
    data = text_array(data) if _is_text(data) else np.asarray(data)
    dims = tuple(dims)
    if len(dims) != data.ndim:
        raise ValueError(f"{group.name}/{name}: {data.ndim} axes, dimensions {dims}")
    coords = dict(coords or {})
    if names is not None:
        attrs["names"] = text_array(list(names))
        coords.setdefault(dims[-1], list(names))
    above = _find_scale(group.parent, name) if dims == (name,) and group.name != "/" else None
    if above is not None and above.shape != data.shape:  # one length along every path
        raise ValueError(
            f"{group.name}/{name}: dimension {name!r} of length "
            f"{data.shape[0]}, but {above.name} has {above.shape[0]}"
        )
    ds = group.create_dataset(name, data=data)
    ds.attrs["units"] = text_array(list(units)) if isinstance(units, (list, tuple)) else units
    write_attrs(ds, **attrs)
    if dims == (name,):
        ds.make_scale(name)
        return ds
    for axis, dim in enumerate(dims):
        ds.dims[axis].attach_scale(_scale(group, dim, data.shape[axis], coords.get(dim)))
    return ds


def write_tables(group, tables) -> None:
    """Write each :class:`suspopt.formats.Table` of ``tables`` into ``group``
    (:func:`write_dataset`)."""
    for t in tables:
        write_dataset(
            group, t.name, t.data, t.units, dims=t.dims, coords=t.coords, names=t.names, **t.attrs
        )


def put(
    fmt: FileFormat,
    group,
    name: str,
    data,
    units: str | Sequence[str] | None = None,
    names: Sequence[str] | None = None,
    coords: dict | None = None,
    **attrs,
):
    """Create ``group[name]`` holding ``data`` as the file format ``fmt`` declares it: its
    dimensions and fixed unit from the declaration, ``units`` only where the declaration
    leaves them to the run (:meth:`suspopt.formats.FileFormat.table`); return the dataset."""
    t = fmt.table(group.name, name, data, units, names=names, coords=coords, attrs=attrs)
    return write_dataset(
        group, t.name, t.data, t.units, dims=t.dims, coords=coords, names=t.names, **t.attrs
    )


def write_simulation(
    path: str | Path,
    result,
    signals: Iterable[str] | None = None,
    float32: bool = False,
    command: str | None = None,
    extra=None,
) -> Path:
    """Write a simulation ``Result`` as its format declares it
    (:data:`suspopt.formats.SIMULATE`, through :func:`suspopt.layout.simulation_tables`):
    ``signals`` (default every signal; float32 where asked), its metrics, when each design
    diverged, the design parameters when there are some and the modes.
    ``extra(h5)`` adds the caller's groups (the picks) before ``/modal``.
    """
    from .layout import simulation_tables

    groups = simulation_tables(result, None if signals is None else list(signals), float32)
    with atomic_h5(path, result.config, command) as h5:
        for name, tables in groups.items():
            if name == "modal" and extra is not None:  # what the caller adds (e.g. the picks)
                extra(h5)
            write_tables(h5.create_group(name) if name else h5, tables)
    return Path(path)


def read_simulation_signals(path: str | Path) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Read ``/time`` and every ``/signals/<name>`` back from a simulate output file."""
    import h5py

    with h5py.File(path, "r") as h5:
        return h5["time"][()], {k: v[()] for k, v in h5["signals"].items()}
