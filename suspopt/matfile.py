"""MATLAB ``.mat`` export of a suspopt HDF5 file: every group as a struct, read back bit for bit.

:func:`write_mat` writes any HDF5 file suspopt wrote (``simulate``, ``optimise``, ``kesort``,
``analyse ...``) as a MATLAB v5 MAT-file (``scipy.io.savemat``, zlib-compressed variables, as
MATLAB's ``save -v7`` writes; MATLAB 7 or later and GNU Octave load it); :func:`read_mat`
reads one back as the HDF5 file's datasets and attributes, the same values, dtypes and shapes.
Every group and dataset is written, ``/checkpoint`` included.

**Layout** (docs/guide/export-mat.md). Each HDF5 group is a struct; the root's members are the
file's variables (``pareto``, ``signals``, ``time``, ...). A struct has one field per member
of its group (a dataset's values, a subgroup's struct) and three more:

- ``units``: a field per dataset with a ``units`` attribute: its unit (SI, as in the HDF5
  file: a char array, or a cell array with one unit per column);
- ``attributes``: the group's own attributes (the root's: the provenance ``suspopt_version``,
  ``created``, ``command``, ``config``, ``seed`` and those of the command);
- ``meta``: a field per member: ``path`` (its HDF5 path) and ``kind`` (``'group'`` or
  ``'dataset'``); a dataset's also ``shape`` (its HDF5 shape, int64, 1 x ndim), ``dtype``
  (its NumPy dtype string: ``'<f8'``, ``'|b1'``, ``'|O'`` for variable-length text),
  ``dims`` (a cell array with the name of each axis: its dimension scale, else ``dim<k>``)
  and ``attributes`` (its attributes but ``units`` and those of the HDF5 dimension-scale
  API).

The root has a fourth variable, ``names_map``: an N x 2 cell array of the names that had to
change, HDF5 path (an attribute as ``path@name``) and MATLAB path (``signals.body_heave_acc``).

**Names** (:func:`matlab_name`): a MATLAB name has letters, digits and underscores, starts
with a letter, has at most 63 characters and is not a keyword. Each other character becomes
``_``; a name that does not start with a letter gets an ``x`` in front (``2nd`` -> ``x2nd``);
a keyword gets ``_`` after it; a name is cut to 63 characters; a name taken in its struct
(by a member before it, in HDF5's order, or by ``units``, ``attributes``, ``meta`` and, at
the root, ``names_map``) ends in ``_2``, ``_3``, ... instead.

**Values**: numbers keep their class (``double``, ``single``, ``int8`` ... ``uint64``;
complex as complex; ``float16``, which MATLAB has not, as ``single``), booleans are
``logical``, text is a cell array of char (a 0-d text dataset, a char array). MATLAB arrays
have two dimensions or more: a 1-D dataset of n values is an n x 1 column, a 0-d one 1 x 1,
other shapes are kept (``/builds/F``, sample x design x objective, is 3-D in MATLAB).
:func:`read_mat` gives the HDF5 shape back from ``meta.<name>.shape`` and the dtype from
``meta.<name>.dtype``; text comes back as h5py reads it (bytes).

Bad input is a :class:`~suspopt.config.ConfigError` in one line naming the file and the
dataset: a file that is not suspopt's or is damaged (read as :class:`!suspopt.h5read.H5Reader`
reads any input), data a MAT-file cannot hold bit for bit (compound or reference types, text
that is not UTF-8 or holds a NUL character), a dataset over
:data:`~suspopt.h5read.MAX_DATASET_BYTES`, a variable over :data:`MAX_VARIABLE_BYTES`; a
target whose name does not end in ``.mat`` or that cannot be written (:func:`!suspopt.io.
check_target`). The file is written atomically (:func:`!suspopt.io.atomic_file`): a failure
leaves nothing.
"""

from __future__ import annotations

import re
import time
from pathlib import Path

import numpy as np

from ._version import __version__
from .errors import ConfigError

__all__ = ["write_mat", "read_mat", "matlab_name", "MAX_NAME", "MAX_VARIABLE_BYTES"]

#: Longest MATLAB name (``namelengthmax``).
MAX_NAME = 63
#: Largest variable a MAT-file of version 7 holds [bytes] (MATLAB's documented 2 GB).
MAX_VARIABLE_BYTES = 2**31 - 1
#: The fields of every struct that are not members of its group (module docstring).
RESERVED = ("units", "attributes", "meta")
#: The root's extra variable: the names that changed.
NAMES_MAP = "names_map"
#: MATLAB's keywords (``iskeyword``): not valid names.
KEYWORDS = frozenset(
    "break case catch classdef continue else elseif end for function global if otherwise "
    "parfor persistent return spmd switch try while".split()
)
#: Attributes of the HDF5 dimension-scale API itself (``meta.<name>.dims`` says what they do).
H5DS = frozenset({"CLASS", "NAME", "REFERENCE_LIST", "DIMENSION_LIST"})
_INVALID = re.compile(r"[^A-Za-z0-9_]")


def matlab_name(name: str, taken: set[str]) -> str:
    """A valid MATLAB name for ``name`` not in ``taken`` (module docstring), added to it."""
    valid = _INVALID.sub("_", name)
    if not valid[:1].isalpha():
        valid = "x" + valid
    if valid in KEYWORDS:
        valid += "_"
    valid = valid[:MAX_NAME]
    candidate, n = valid, 1
    while candidate in taken:
        n += 1
        suffix = f"_{n}"
        candidate = valid[: MAX_NAME - len(suffix)] + suffix
    taken.add(candidate)
    return candidate


def _cell(items: list, shape: tuple[int, ...]) -> np.ndarray:
    """A MATLAB cell array (an object array) of ``items`` in ``shape``."""
    out = np.empty(len(items), dtype=object)
    out[:] = items
    return out.reshape(shape)


class _Writer:
    """The structs of one HDF5 file (module docstring), built group by group."""

    def __init__(self, reader):
        self.reader = reader
        self.where = reader.where
        self.names: list[tuple[str, str]] = []  # (HDF5 path, MATLAB path) of changed names

    def name(self, original: str, taken: set[str], hdf5: str, matlab: str) -> str:
        """The MATLAB name of ``original`` (at ``hdf5``) in the struct at ``matlab``."""
        mapped = matlab_name(original, taken)
        if mapped != original:
            self.names.append((hdf5, f"{matlab}.{mapped}" if matlab else mapped))
        return mapped

    def text(self, value, label: str) -> str:
        """``value`` as text a MATLAB char array holds as it is."""
        text = self.reader.text(value, label)
        if "\x00" in text:
            raise ConfigError(f"{self.where}: {label}: text with a NUL character")
        return text

    def attribute(self, value, label: str):
        """An attribute's value for the .mat file: text as char, text arrays as cells."""
        if isinstance(value, (str, bytes, np.bytes_)):
            return self.text(value, label)
        array = np.asarray(value)
        if array.dtype.kind in "OSU":
            return _cell([self.text(v, label) for v in array.ravel()], array.shape)
        return self.numbers(array, label)

    def attributes(self, obj, label: str, matlab: str, skip=H5DS) -> dict:
        """The attributes of ``obj`` (its HDF5 path ``label``) but ``skip``, as a struct."""
        out: dict = {}
        taken: set[str] = set()
        try:
            keys = sorted(obj.attrs)
        except (OSError, RuntimeError, KeyError, ValueError, TypeError):
            raise ConfigError(f"{self.where}: {label}: its attributes are damaged") from None
        for key in keys:
            if key in skip:
                continue
            where = f"{label}: attribute {key!r}"
            value = self.reader.attribute(obj, key, where)
            field = self.name(key, taken, f"{label}@{key}", matlab)
            out[field] = self.attribute(value, where)
        return out

    def numbers(self, array: np.ndarray, label: str) -> np.ndarray:
        """A numeric or boolean array as MATLAB holds it (module docstring)."""
        kind, size = array.dtype.kind, array.dtype.itemsize
        if kind == "f" and size == 2:
            return array.astype(np.float32)
        if kind in "biu" or (kind == "f" and size in (4, 8)) or (kind == "c" and size in (8, 16)):
            return array.astype(array.dtype.newbyteorder("="), copy=False)
        raise ConfigError(
            f"{self.where}: {label}: data of type {array.dtype}, which a MATLAB file "
            "cannot hold bit for bit"
        )

    def dataset(self, ds) -> tuple[object, dict, object]:
        """(values, ``meta`` entry, unit or None) of the dataset ``ds``."""
        import h5py

        from .h5read import MAX_DATASET_BYTES, dimension_scales

        label = ds.name
        text = ds.dtype.kind == "S" or (
            ds.dtype.kind == "O" and h5py.check_string_dtype(ds.dtype) is not None
        )
        if ds.size * max(ds.dtype.itemsize, 8) > MAX_DATASET_BYTES:
            raise ConfigError(
                f"{self.where}: {label}: shape {ds.shape} is larger than "
                f"{MAX_DATASET_BYTES >> 20} MB: not a file of suspopt's"
            )
        if not text:
            self.numbers(np.empty(0, ds.dtype), label)  # (its type, before it is read)
        values = np.asarray(ds[()])
        if text and values.ndim == 0:
            data: object = self.text(values, label)
        elif text:
            data = _cell([self.text(v, label) for v in values.ravel()], values.shape)
        else:
            data = self.numbers(values, label)
        dims = [ds.name.rsplit("/", 1)[-1]] if ds.is_scale else [d for d, _ in dimension_scales(ds)]
        meta = {
            "path": label,
            "kind": "dataset",
            "shape": np.array([ds.shape], dtype=np.int64).reshape(1, ds.ndim),
            "dtype": ds.dtype.str,
            "dims": _cell([self.text(d, label) for d in dims], (len(dims),)),
        }
        units = self.reader.attribute(ds, "units", f"{label}: attribute 'units'")
        if units is not None:
            units = self.attribute(units, f"{label}: attribute 'units'")
        return data, meta, units

    def group(self, group, matlab: str, reserved=RESERVED) -> dict:
        """The struct of ``group`` at the MATLAB path ``matlab`` ('' for the root)."""
        import h5py

        out: dict = {}
        taken = set(reserved)
        units: dict = {}
        meta: dict = {}
        for key, member in group.items():
            hdf5 = member.name if member is not None else f"{group.name}/{key}"
            field = self.name(key, taken, hdf5, matlab)
            inner = f"{matlab}.{field}" if matlab else field
            if isinstance(member, h5py.Group):
                out[field] = self.group(member, inner)
                meta[field] = {"path": member.name, "kind": "group"}
            elif isinstance(member, h5py.Dataset):
                out[field], meta[field], unit = self.dataset(member)
                meta[field]["attributes"] = self.attributes(
                    member, member.name, f"{matlab}.meta.{field}.attributes".lstrip("."),
                    H5DS | {"units"},
                )  # fmt: skip
                if unit is not None:
                    units[field] = unit
            else:  # (a damaged object header, a link to nothing, a committed datatype)
                raise ConfigError(
                    f"{self.where}: {hdf5}: damaged or not a group or dataset, cannot be read"
                )
        out["units"], out["meta"] = units, meta
        out["attributes"] = self.attributes(
            group, group.name, f"{matlab}.attributes" if matlab else "attributes"
        )
        return out


def _variables(reader) -> dict:
    """The variables of the .mat file of the open suspopt file ``reader`` (module docstring)."""
    from .export import _reading

    writer = _Writer(reader)
    with _reading(reader.path):
        root = writer.group(reader.file, "", RESERVED + (NAMES_MAP,))
    for name, meta in root["meta"].items():
        size = _bytes(root[name])
        if size > MAX_VARIABLE_BYTES:
            raise ConfigError(
                f"{reader.where}: {meta['path']}: {size >> 20} MB, more than the "
                f"{MAX_VARIABLE_BYTES >> 20} MB a MATLAB variable holds (export --csv "
                "writes any size)"
            )
    root[NAMES_MAP] = _cell([v for pair in writer.names for v in pair], (len(writer.names), 2))
    return root


def _bytes(value) -> int:
    """About the bytes ``value`` (a struct's dict, an array, text) takes in a MAT-file."""
    if isinstance(value, dict):
        return sum(_bytes(v) for v in value.values())
    if isinstance(value, np.ndarray) and value.dtype == object:
        return sum(_bytes(v) for v in value.ravel())
    if isinstance(value, str):
        return 2 * len(value)
    return int(np.asarray(value).nbytes)


def _header(h5_path: Path) -> bytes:
    """The 116 bytes of the MAT-file's text header, which say that suspopt wrote it (the
    marker by which suspopt knows its outputs, :func:`suspopt.io.is_suspopt_output`)."""
    made = time.strftime("%a %b %d %H:%M:%S %Y", time.gmtime())
    name = h5_path.name.encode("ascii", "replace").decode()
    text = f"MATLAB 5.0 MAT-file, written by suspopt {__version__}, Created on: {made} UTC, from "
    return (text + name).encode("ascii", "replace")[:116].ljust(116)


def write_mat(h5_path: str | Path, mat_path: str | Path, force: bool = False) -> Path:
    """Write the suspopt HDF5 file ``h5_path`` as the MATLAB file ``mat_path`` (module
    docstring) and return its path. ``mat_path`` must end in ``.mat``; an existing file that
    suspopt did not write is replaced only with ``force``. ConfigError (one line naming the
    file) for bad input or a target that cannot be written; nothing is left behind then."""
    import scipy.io

    from .h5read import H5Reader
    from .io import atomic_file, check_not_input, check_target

    h5_path, mat_path = Path(h5_path), Path(mat_path)
    inputs = [("the input", h5_path)]
    check_not_input(mat_path, inputs, "--mat")
    check_target(mat_path, force, "--mat")
    if mat_path.suffix.lower() != ".mat":
        raise ConfigError(f"--mat {mat_path}: a MATLAB file's name ends in .mat")
    with H5Reader(h5_path) as reader:
        if not reader.has_attr("suspopt_version"):
            raise ConfigError(
                f"{h5_path}: not a file suspopt wrote (no root attribute 'suspopt_version')"
            )
        variables = _variables(reader)
    with atomic_file(mat_path, force, inputs) as stream:
        scipy.io.savemat(
            stream, variables, long_field_names=True, do_compression=True, oned_as="column"
        )
        stream.seek(0)
        stream.write(_header(h5_path))
    return mat_path


def _fields(struct) -> dict:
    """The fields of a struct as ``scipy.io.loadmat`` reads it (a 1 x 1 record array)."""
    if not isinstance(struct, np.ndarray) or struct.dtype.names is None:
        return {}  # (an empty struct)
    return {name: struct[name][0, 0] for name in struct.dtype.names}


def _text(value) -> str:
    """A MATLAB char array as loadmat reads it (``chars_as_strings``) as a string."""
    return str(value.ravel()[0]) if value.size else ""


def _texts(value) -> list[str]:
    return [_text(v) for v in np.asarray(value, dtype=object).ravel()]


def _restore(value, meta: dict) -> np.ndarray:
    """The HDF5 dataset's values from the .mat file's ``value`` and ``meta`` entry."""
    shape = tuple(int(n) for n in np.ravel(meta["shape"]))
    dtype = np.dtype(_text(meta["dtype"]))
    if dtype.kind in "OS":
        items = [_text(value)] if len(shape) == 0 else _texts(value)
        encoded = [t.encode("utf-8") for t in items]
        if dtype.kind == "O":
            return _cell(encoded, shape)
        return np.array(encoded, dtype=dtype).reshape(shape)
    # (MATLAB's order is Fortran's: loadmat gives it back in NumPy's C order already)
    return np.asarray(value).reshape(shape).astype(dtype)


def _value(value):
    """An attribute as read back: text as str, cells as lists of str, numbers as arrays (a
    scalar as a NumPy scalar)."""
    if isinstance(value, np.ndarray) and value.dtype.kind == "U":
        return _text(value)
    if isinstance(value, np.ndarray) and value.dtype == object:
        return _texts(value)
    array = np.squeeze(value)
    return array[()] if array.ndim == 0 else array


def _read_attributes(struct, matlab: str, names: dict[str, str]) -> dict:
    """The attributes struct at the MATLAB path ``matlab``, by their HDF5 names."""
    out = {}
    for key, value in _fields(struct).items():
        original = names.get(f"{matlab}.{key}")
        out[original.rpartition("@")[2] if original else key] = _value(value)
    return out


def _read_group(struct: dict, path: str, matlab: str, read: tuple[dict, dict, dict]) -> None:
    """Fill ``read`` (datasets and attributes by HDF5 path, and the names map by MATLAB path)
    from the struct of the group ``path`` at the MATLAB path ``matlab``."""
    datasets, attributes, names = read
    units = _fields(struct.get("units"))
    attributes[path] = _read_attributes(struct.get("attributes"), f"{matlab}attributes", names)
    for field, entry in _fields(struct.get("meta")).items():
        meta = _fields(entry)
        member = _text(meta["path"])
        if _text(meta["kind"]) == "group":
            _read_group(_fields(struct[field]), member, f"{matlab}{field}.", read)
            continue
        datasets[member] = _restore(struct[field], meta)
        found = _read_attributes(meta["attributes"], f"{matlab}meta.{field}.attributes", names)
        if field in units:
            found["units"] = _value(units[field])
        attributes[member] = found


def read_mat(mat_path: str | Path) -> tuple[dict[str, np.ndarray], dict[str, dict]]:
    """Read a file of :func:`write_mat` back: (datasets, attributes), each by HDF5 path
    (``'/signals/body.heave_acc'``; ``'/'`` for the root's attributes), the datasets with the
    HDF5 file's dtype and shape, the attributes by their HDF5 names (``units`` included; the
    names that changed from ``names_map``), text as str, text arrays as lists, numbers as
    NumPy arrays squeezed (a scalar as a NumPy scalar)."""
    import scipy.io

    loaded = scipy.io.loadmat(mat_path, chars_as_strings=True, squeeze_me=False)
    root = {k: v for k, v in loaded.items() if not k.startswith("__")}
    pairs = _texts(root.get(NAMES_MAP, np.empty((0, 2), dtype=object)))
    names = dict(zip(pairs[1::2], pairs[0::2]))  # (MATLAB path -> HDF5 path)
    datasets: dict[str, np.ndarray] = {}
    attributes: dict[str, dict] = {}
    _read_group(root, "/", "", (datasets, attributes, names))
    return datasets, attributes
