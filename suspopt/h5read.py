"""Reading HDF5 files that suspopt wrote, as untrusted input.

A file given to ``kesort``, ``analyse`` or ``optimise --resume`` may be truncated, foreign or
crafted. :class:`!H5Reader` reads it so that every problem is a
:class:`~suspopt.config.ConfigError` naming the file and the dataset or attribute at fault:
only regular files are opened; a dataset is read only if it is numeric, has the expected
number of dimensions (and columns) and fits in :data:`MAX_DATASET_BYTES` (a dataset may
declare 10^12 rows it never wrote); text attributes must be UTF-8 and at most
:data:`~suspopt.config.yamlio.MAX_CONFIG_BYTES` long. Nothing in a file is executed.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import time
from pathlib import Path

import numpy as np

from .config.yamlio import MAX_CONFIG_BYTES
from .errors import ConfigError
from .files import kind_of

__all__ = [
    "H5Reader",
    "MAX_DATASET_BYTES",
    "MAX_ATTRIBUTE_BYTES",
    "LOWEST_OBJECTIVE",
    "open_dataset",
]

#: Largest dataset read from an input file [bytes]. A Pareto set of a million designs with a
#: hundred columns is 800 MB.
MAX_DATASET_BYTES = 1 << 30
#: Longest a forked probe may take to walk a file's metadata (:func:`_probe`): this many
#: seconds, and one more per :data:`PROBE_BYTES_PER_SECOND` of file. A sound file's walk takes
#: milliseconds (a 1000-design front: about 5 ms), but on a loaded machine (a test suite's
#: workers on two cores, a cluster node) the fork and its first page faults took over a
#: second, and a sound file was called damaged: the budget is wall time, so it is generous.
PROBE_SECONDS = 5.0
PROBE_BYTES_PER_SECOND = 50e6
#: Memory a probe's walk may take beyond what the process held when it forked [bytes]: this
#: much, and :data:`PROBE_MEMORY_PER_BYTE` more per byte of file. A sound file's metadata
#: decodes to a few times its size; a damaged global heap behind a text attribute can declare
#: a gigabyte in a 12 kB file, which the HDF5 library allocates and reads before it finds the
#: heap's size wrong.
PROBE_MEMORY = 64 << 20
PROBE_MEMORY_PER_BYTE = 8
#: Lowest objective value a file may hold: minus the optimiser's penalty value
#: (:data:`suspopt.optimisation.problem.PENALTY`, what a failed design gets). No objective of a
#: simulation comes near it; a damaged file's -1e308 broke the figures and the knee.
LOWEST_OBJECTIVE = -1.0e10
#: Files this process has probed: (device, inode, size, modification time).
_PROBED: set[tuple[int, int, int, int]] = set()
#: Largest attribute read from an input file [bytes]: a damaged attribute may declare a shape
#: of 10^15 elements, which h5py would allocate before reading.
MAX_ATTRIBUTE_BYTES = 4 * MAX_CONFIG_BYTES


def _declared_bytes(obj, key: str) -> int:
    """Bytes the attribute ``key`` of ``obj`` declares (its shape times its item size), read
    from its header without allocating it."""
    import h5py

    declared = h5py.h5a.open(obj.id, key.encode())
    return math.prod(declared.shape) * max(declared.dtype.itemsize, 1)


def _walk(path: Path) -> None:
    """Read every attribute and every text dataset of ``path`` (within the size limits) and
    open every dataset's dimension scales (:func:`dimension_scales`). What fails to read (an
    object that cannot be opened included) is the reader's to report: the walk goes on past
    it, so that a crash or a hang further on is still met; running out of memory ends it (a
    MemoryError naming what was being read)."""
    import h5py

    def attempt(label: str, read):
        """``read()``, or None when it fails."""
        try:
            return read()
        except Exception as exc:  # the reader's to report, by its own checks
            if isinstance(exc, MemoryError) or "allocat" in str(exc).lower():
                raise MemoryError(label) from None
            return None

    def visit(obj) -> None:
        for key in attempt(f"{obj.name}: its attributes", lambda: list(obj.attrs)) or []:
            attempt(f"{obj.name}: attribute {key!r}", lambda key=key: _read_attribute(obj, key))
        if isinstance(obj, h5py.Dataset):
            attempt(obj.name, lambda: _read_text(obj))
            attempt(f"{obj.name}: its dimension scales", lambda: dimension_scales(obj))

    def visit_named(f, name: str) -> None:
        # each object opened here, not by visititems, which stops at one it cannot open
        obj = attempt(f"/{name}", lambda: f[name])
        if obj is not None:
            visit(obj)

    with h5py.File(path, "r") as f:
        visit(f)
        f.visit(lambda name: visit_named(f, name))


def _read_attribute(obj, key: str) -> None:
    """Read the attribute ``key`` of ``obj`` if it fits in :data:`MAX_ATTRIBUTE_BYTES`."""
    if _declared_bytes(obj, key) <= MAX_ATTRIBUTE_BYTES:
        obj.attrs[key]


def _read_text(ds) -> None:
    """Read the dataset ``ds`` if it holds text and fits in :data:`MAX_DATASET_BYTES`."""
    if ds.dtype.kind in "OSU" and ds.size * max(ds.dtype.itemsize, 16) <= MAX_DATASET_BYTES:
        ds[()]


def dimension_scales(ds) -> list[tuple[str, object]]:
    """(name, scale or None) of every axis of the dataset ``ds``: its first dimension scale,
    else ``dim<k>``. The scales are looked up only when the dataset's list of them has one
    entry per axis (libhdf5 reads past the list of a crafted file, where it has fewer); a
    damaged reference in a well-shaped list can still crash the library, which is why the
    probe (:func:`_walk`) opens them before a reader does."""
    listed = ds.attrs.get("DIMENSION_LIST")
    if listed is None or np.shape(listed) != (ds.ndim,):
        return [(f"dim{axis}", None) for axis in range(ds.ndim)]
    out: list[tuple[str, object]] = []
    for axis in range(ds.ndim):
        scales = ds.dims[axis]
        scale = scales[0] if len(scales) else None
        if scale is None or scale.name is None:  # (none, or one no path of the file reaches)
            out.append((f"dim{axis}", None))
        else:
            out.append((scale.name.rsplit("/", 1)[-1], scale))
    return out


def _cap_memory(allowance: int) -> None:
    """Limit this process (the probe's child) to ``allowance`` more bytes than it holds now
    (Linux; elsewhere nothing is limited). The address-space limit cannot stop the allocator
    from serving a request from memory freed earlier and kept (:func:`memory.reuse_memory`:
    after a large run, a heap of a GB or more), so the heap's free top is given back first
    and its remaining holes are counted in the allowance."""
    import resource

    from .memory import release_free

    with contextlib.suppress(OSError, ValueError):
        holes = release_free()
        with open("/proc/self/statm") as statm:
            held = int(statm.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
        soft, hard = resource.getrlimit(resource.RLIMIT_AS)
        cap = held + max(allowance - holes, 0)
        if soft != resource.RLIM_INFINITY:
            cap = min(cap, soft)
        resource.setrlimit(resource.RLIMIT_AS, (cap, hard))


def _probe(path: Path, where: str) -> None:
    """Walk the file's metadata in a forked child first: a damaged file can send the HDF5
    library into an endless loop or a crash, in C, where no Python timer reaches, or into
    allocating far more than the file holds (a corrupted global heap behind a text attribute
    does each). The child's other errors are left to the reader's checks; a child that does
    not finish in time (:data:`PROBE_SECONDS`), dies by a signal or runs out of its memory
    (:data:`PROBE_MEMORY`) makes the file bad input. Where there is no ``fork`` the probe is
    skipped."""
    if not hasattr(os, "fork"):
        return
    info = path.stat()
    key = (info.st_dev, info.st_ino, info.st_size, info.st_mtime_ns)
    if key in _PROBED:  # this file, unchanged, walked already by this process
        return
    budget = PROBE_SECONDS + info.st_size / PROBE_BYTES_PER_SECOND
    allowance = PROBE_MEMORY + PROBE_MEMORY_PER_BYTE * info.st_size
    said, say = os.pipe()  # what the child ran out of memory reading, if it did
    pid = os.fork()
    if pid == 0:  # the child: walk, and leave without running any of the parent's exit code
        with contextlib.suppress(BaseException):
            # the kernel ends the child even in a loop in C, and even if the parent is gone
            signal.signal(signal.SIGALRM, signal.SIG_DFL)
            signal.signal(signal.SIGTERM, signal.SIG_DFL)  # (not the parent's handler)
            signal.alarm(int(budget) + 2)
            import faulthandler

            faulthandler.disable()  # its crash is the parent's to report, in one line
            os.dup2(os.open(os.devnull, os.O_WRONLY), 2)
            _cap_memory(allowance)
            try:
                _walk(path)
            except MemoryError as exc:  # (the walk's other errors are the reader's to report)
                os.write(say, (str(exc) or "its metadata").encode("utf-8", "replace")[:300])
        os._exit(0)
    os.close(say)
    try:
        _wait_for_probe(pid, where, budget)
        short = os.read(said, 1024).decode("utf-8", "replace")  # (the child has left)
    finally:
        os.close(said)
    if short:
        raise ConfigError(
            f"{where}: damaged: {short} would take more than {allowance >> 20} MB to read"
        )
    _PROBED.add(key)


def _wait_for_probe(pid: int, where: str, budget: float) -> None:
    """Wait for the probe ``pid``; ConfigError when it crashed or ran past ``budget`` s."""
    deadline = time.monotonic() + budget
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            if os.WIFSIGNALED(status):
                raise ConfigError(
                    f"{where}: damaged: reading its metadata crashed the HDF5 library"
                )
            return
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            raise ConfigError(
                f"{where}: damaged: reading its metadata did not finish in {budget:.3g} s"
            )
        time.sleep(0.0005)


def _from_h5py(kind, tb) -> bool:
    """Whether an exception of ``kind`` with traceback ``tb`` is h5py's (or the HDF5
    library's) failure to read, raised in h5py's own code."""
    if kind is None or issubclass(kind, ConfigError):
        return False
    if not issubclass(kind, (OSError, RuntimeError, KeyError, ValueError, TypeError)):
        return False
    while tb is not None and tb.tb_next is not None:
        tb = tb.tb_next
    return tb is not None and "h5py" in Path(tb.tb_frame.f_code.co_filename).parts


#: The top-level groups that tell what a suspopt file holds (the first one found names it),
#: for a file without the root attribute ``analysis``: the layouts of docs/guide/results.md.
_HOLDS = (
    ("kesort", "a k-ε selection (suspopt kesort)"),
    ("pareto", "a Pareto front (suspopt optimise)"),
    ("signals", "a simulation's signals (suspopt simulate)"),
    ("linear", "transmissibilities (suspopt analyse transmissibility)"),
    ("cdf_sensitivity", "a threshold sweep (suspopt analyse cdf-sensitivity)"),
)


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
        kind = kind_of(mode)
        if kind is not None:
            raise ConfigError(f"{self.where}: is {kind}, not a regular file")
        _probe(self.path, self.where)
        try:
            self.file = h5py.File(self.path, "r")
        except (OSError, ValueError):
            raise ConfigError(f"{self.where}: not an HDF5 file (or a damaged one)") from None

    def __enter__(self) -> H5Reader:
        return self

    def __exit__(self, kind, exc, tb) -> None:
        with contextlib.suppress(OSError, RuntimeError, ValueError):  # a damaged file's close
            self.file.close()
        if _from_h5py(kind, tb):
            # a damaged file fails inside h5py wherever it is walked (keys, membership,
            # attributes): bad input, one line, whatever the reader was doing
            text = " ".join(str(exc).split()).strip("'\"")
            raise ConfigError(f"{self.where}: damaged, cannot be read ({text})") from None

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
            raise ConfigError(f"{self.where}: /{name}: missing{self._holds()}")
        return node

    def _holds(self) -> str:
        """What the file holds, for a message about a group it lacks: a result of another
        command is the usual slip (``kesort chosen.h5``)."""
        import h5py

        try:
            top = {k for k, v in self.file.items() if isinstance(v, h5py.Group)}
            analysis, source = self.file.attrs.get("analysis"), self.file.attrs.get("source")
        except (OSError, RuntimeError, KeyError, ValueError, TypeError):
            top, analysis, source = set(), None, None
        if isinstance(analysis, str) and analysis.isidentifier():
            shown = isinstance(source, str) and source.isprintable() and len(source) <= 300
            made_from = f" of {source}" if shown else ""
            return f"; the file holds the results of suspopt analyse {analysis}{made_from}"
        for group, what in _HOLDS:
            if group in top:
                return f"; the file holds {what}"
        return " (is this a suspopt file of the right kind?)"

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
        return np.asarray(self._values(ds, name), dtype=np.int64 if integer else np.float64)

    def objectives(self, name: str, values: np.ndarray, labels) -> None:
        """ConfigError naming ``/name`` and the column when a column of the objectives
        ``values`` holds a value at or below :data:`LOWEST_OBJECTIVE`, which no objective
        suspopt writes does (a failed design has the penalty value, +1e10): a damaged file's
        -1e308 overflowed the figures' axes and, beside a 1e308, the knee's normalisation."""
        with np.errstate(invalid="ignore"):
            low = values <= LOWEST_OBJECTIVE
        for j in np.flatnonzero(low.any(axis=0)):
            lowest = float(np.min(values[:, j][low[:, j]]))
            raise ConfigError(
                f"{self.where}: /{name}: {labels[j]} holds {lowest:g}, at or below "
                f"{LOWEST_OBJECTIVE:g} (not values suspopt wrote)"
            )

    def _values(self, ds, name: str):
        """What the dataset ``ds`` (``/name``) holds; ConfigError when it cannot be read."""
        try:
            return ds[()]
        except (OSError, ValueError, RuntimeError):
            raise ConfigError(f"{self.where}: /{name}: damaged, cannot be read") from None

    def texts(self, name: str, count: int) -> list[str]:
        """The 1-D text dataset ``/name``, checked to hold ``count`` entries of
        UTF-8 text (each as :meth:`text` reads it)."""
        ds = self.dataset(name)
        if ds.dtype.kind not in ("O", "S") or ds.ndim != 1 or len(ds) != count:
            raise ConfigError(
                f"{self.where}: /{name}: expected {count} entries of text, got {ds.dtype} "
                f"values of shape {ds.shape}"
            )
        return [self.text(v, f"/{name}") for v in self._values(ds, name)]

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
        try:  # (h5py hands bytes that are not UTF-8 over as lone surrogates)
            value.encode("utf-8")
        except UnicodeEncodeError:
            raise ConfigError(f"{self.where}: {name}: not UTF-8 text") from None
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

    def attribute(self, obj, key: str, label: str):
        """The attribute ``key`` of the group or dataset ``obj``, None when it has none;
        ConfigError (``label`` naming it) when it is damaged or declares more than
        :data:`MAX_ATTRIBUTE_BYTES`, checked before anything is allocated."""
        try:
            if obj is None or key not in obj.attrs:
                return None
            size = _declared_bytes(obj, key)
            if size > MAX_ATTRIBUTE_BYTES:
                raise ConfigError(
                    f"{self.where}: {label}: declares {size} bytes, more than the "
                    f"{MAX_ATTRIBUTE_BYTES} an attribute may take"
                )
            return obj.attrs[key]
        except (OSError, ValueError, TypeError, RuntimeError, KeyError) as exc:
            if isinstance(exc, ConfigError):
                raise
            raise ConfigError(f"{self.where}: {label}: damaged, cannot be read") from None

    def text_attr(self, key: str, node: str = "") -> str:
        """The text attribute ``key`` of ``/node`` (the root by default)."""
        obj = self.file if not node else self._node(node)
        label = f"attribute {key!r}" + (f" of /{node}" if node else "")
        if not self.has_attr(key, node):
            raise ConfigError(f"{self.where}: {label}: missing")
        return self.text(self.attribute(obj, key, label), label)

    def int_attr(self, node: str, key: str, low: int, high: int) -> int:
        """The whole-number attribute ``key`` of ``/node``, in ``[low, high]``."""
        return int(self.number_attr(node, key, low, high, integer=True))

    def number_attr(
        self, node: str, key: str, low: float, high: float, integer: bool = False
    ) -> int | float:
        """The numeric attribute ``key`` of ``/node`` (a whole number with ``integer``), in
        ``[low, high]`` (NaN is not)."""
        label = f"/{node}: attribute {key!r}"
        value = self.attribute(self._node(node), key, label)
        if isinstance(value, np.ndarray) and value.ndim == 0:
            value = value[()]
        kinds = (int, np.integer) if integer else (int, float, np.integer, np.floating)
        if (
            not isinstance(value, kinds)
            or isinstance(value, (bool, np.bool_))
            or not low <= value <= high
        ):
            what = "a whole number" if integer else "a number"
            raise ConfigError(f"{self.where}: {label}: missing or not {what} in [{low}, {high}]")
        return int(value) if integer else float(value)

    def labels(
        self, name: str, key: str, columns: int, *, kind: str = "Dataset", of: str = "columns"
    ) -> list[str]:
        """The per-column text attribute ``key`` (``names``, ``units``) of dataset ``/name``,
        one entry per column; of a group with ``kind="Group"``, one per item ``of`` it
        (``picks`` of ``/designs``: one per design)."""
        obj = self._kind(name, kind)
        label = f"/{name}: attribute {key!r}"
        raw = self.attribute(obj, key, label)
        if raw is None:
            raise ConfigError(f"{self.where}: {label}: missing")
        entries = [self.text(v, label) for v in np.atleast_1d(raw)]
        if len(entries) != columns:
            raise ConfigError(f"{self.where}: {label}: {len(entries)} entries for {columns} {of}")
        return entries


def open_dataset(path: str | Path, group: str | None = None):
    """The datasets of ``group`` (default the root; ``"pareto"``, ``"kesort/cases/A"``) of a
    suspopt HDF5 file as an ``xarray.Dataset`` (lazy, through xarray's ``h5netcdf`` engine):
    named dimensions with their coordinates, those held by the groups above included (``time``
    and ``design`` for ``/signals``), each variable's attributes (``units``, ``names``), and the
    root's attributes (``suspopt_version``, ``created``, ``command``, ``config``, ``seed``, ...)
    under the group's own, which win where both have one. ``suspopt.layout.as_dataset``
    gives the same Dataset from a result in memory (``Result.to_xarray()``).
    ``open_dataset(p, "pareto")["F"].to_pandas()`` is the Pareto front's objectives as a
    pandas DataFrame.

    Parameters
    ----------
    path : str or Path
        A file suspopt wrote.
    group : str, optional
        The group, e.g. ``"pareto"`` (default the root).

    Returns
    -------
    xarray.Dataset
        Its variables with their ``units``. A file that is missing, not HDF5 or damaged is a
        ConfigError naming it, a group the file lacks a KeyError listing the groups it has.
    """
    try:
        import h5netcdf  # noqa: F401
        import xarray
    except ImportError:
        raise ModuleNotFoundError(
            "suspopt.io.open_dataset needs xarray and h5netcdf, dependencies of suspopt that "
            "cannot be imported here: pip install xarray h5netcdf"
        ) from None

    def load(name: str | None):
        return xarray.open_dataset(
            path,
            engine="h5netcdf",
            group=name,
            phony_dims="sort",
            decode_times=False,
            decode_timedelta=False,
        )

    import h5py

    if group is not None and not isinstance(group, str):
        raise TypeError(f"group must be a str, e.g. 'pareto'; got {type(group).__name__}")
    parts = [p for p in (group or "").split("/") if p not in ("", ".")]  # ("." is the root)
    asked, group = group, "/".join(parts) or None
    with H5Reader(path) as h5:  # (a missing, foreign or damaged file: ConfigError first)
        if group and (".." in parts or not isinstance(h5.file.get(group), h5py.Group)):
            groups: list[str] = []
            h5.file.visititems(
                lambda name, obj: groups.append(name) if isinstance(obj, h5py.Group) else None
            )
            raise KeyError(f"{path}: no group {asked!r}; it has {', '.join(groups) or 'none'}")
    ds = load(group)
    for depth in range(len(parts) - 1, -1, -1):  # the nearest group above first
        missing = [d for d in ds.sizes if d not in ds.coords]
        if not missing:
            break
        with load("/".join(parts[:depth]) or None) as above:
            found = {
                d: above[d].load()
                for d in missing
                if d in above.coords and above.sizes[d] == ds.sizes[d]
            }
        ds = ds.assign_coords(found)
    if parts:  # the provenance, under the group's own attributes
        with load(None) as root:
            ds.attrs = {**root.attrs, **ds.attrs}
    return ds
