"""The datasets of a result file, declared once for the file and for memory.

A group of a suspopt HDF5 file is a list of :class:`Table` (name, data, units, dimensions,
coordinates, attributes). The writers write the tables (:func:`suspopt.io.write_tables`,
through :func:`suspopt.io.write_dataset`), and :func:`as_dataset` makes the same tables an
``xarray.Dataset`` in memory, the one :func:`suspopt.io.open_dataset` reads from the file
written: the same variables, named dimensions and coordinates (a dimension's scale is the
table of its name in the group or a group above it, else the column names or the row
numbers 0 ... n-1, units ``1``), ``units`` and other attributes as xarray reads them from
HDF5 (a list of texts, one entry as the entry itself), and the root's attributes
(provenance: ``suspopt_version``, ``created``, ``command``, ``config``, ``seed``) under the
group's own. So ``Result.to_xarray()`` needs no file (:meth:`suspopt.Result.to_xarray`,
:meth:`suspopt.optimisation.OptimisationResult.to_xarray`), and :func:`frame` makes a Dataset a
tidy pandas DataFrame.

:func:`simulation_tables` makes the tables of a ``suspopt simulate`` file and
:mod:`suspopt.optimisation.output` those of an optimisation's, each dataset as its file's
format declares it (:mod:`suspopt.formats`).
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from typing import Any

import numpy as np

from .formats import SIMULATE, Table

__all__ = ["Table", "simulation_tables", "as_dataset", "group_name", "group_dataset", "frame"]


def simulation_tables(
    result,
    signals: Sequence[str] | None = None,
    float32: bool = False,
    only: Collection[str] | None = None,
) -> dict[str, list[Table]]:
    """The groups of the file of a simulation ``result`` (:func:`suspopt.io.write_simulation`,
    docs/guide/results.md), group name (``""`` the root) -> its tables: ``signals`` (default
    every signal; float32 where asked), ``metrics``, ``diverged_at``, ``designs/X`` (when
    design parameters were given) and ``modal`` (:func:`suspopt.vehicle.modal_analysis`).
    ``only`` names the groups to compute (default all); the others are there, empty."""
    names = list(result.signals) if signals is None else list(signals)
    dtype = np.float32 if float32 else np.float64
    wanted = (lambda g: True) if only is None else (lambda g: g in only)
    t = SIMULATE.table
    groups: dict[str, list[Table]] = {
        "": [
            t("", "time", result.time),
            t("", "design", np.arange(len(result.diverged_at))),
            t("", "diverged_at", result.diverged_at),
        ],
        "signals": [
            t("signals", n, np.asarray(result.signals[n], dtype=dtype), result.signal_unit(n))
            for n in (names if wanted("signals") else [])
        ],
        "metrics": [
            t("metrics", n, np.asarray(v), result.metric_units[n])
            for n, v in result.metrics.items()
        ],
    }
    if result.designs:
        groups["designs"] = _designs(result) if wanted("designs") else []
    groups["modal"] = _modal(result.model) if wanted("modal") else []
    return groups


def _designs(result) -> list[Table]:
    """``/designs/X``: the design parameters by dotted path, each in its field's unit."""
    from .params import field_unit

    X = np.column_stack([result.designs[k] for k in result.designs])
    units = [field_unit(result.config, k) for k in result.designs]
    return [SIMULATE.table("designs", "X", X, units, names=list(result.designs))]


def _modal(model) -> list[Table]:
    """``/modal``: the modes of :func:`suspopt.vehicle.modal_analysis` of ``model``."""
    from .vehicle import modal_analysis

    modes = modal_analysis(model)
    dofs = list(modes.dof_names)
    t = SIMULATE.table
    return [
        t("modal", "frequency", modes.frequency, attrs={"dominant": list(modes.dominant[0])}),
        t("modal", "label", modes.label),
        t("modal", "energy_share", modes.energy, coords={"dof": dofs}, attrs={"dofs": dofs}),
    ]


def _as_read(value):
    """An attribute's value as xarray reads it back from HDF5 (engine ``h5netcdf``): texts as
    a list of ``str``, numbers as an array, and one entry of either as that entry."""
    if isinstance(value, (str, bytes)):
        return value.decode("utf-8") if isinstance(value, bytes) else value
    items = np.asarray(value)
    if items.dtype.kind in "USO":
        out: Any = [v.decode("utf-8") if isinstance(v, bytes) else str(v) for v in items.ravel()]
    else:
        out = items if items.ndim else items[()]
    return out[0] if isinstance(out, (list, np.ndarray)) and len(out) == 1 else out


def _attrs(table: Table) -> dict[str, Any]:
    """The attributes of ``table`` as read back: ``units``, ``names`` and its own."""
    found: dict[str, Any] = {"units": table.units}
    if table.names is not None:
        found["names"] = list(table.names)
    found.update(table.attrs)
    return {k: _as_read(v) for k, v in found.items()}


def _scale(dim: str, size: int, tables: Sequence[Table], above: Sequence[Table]):
    """The coordinate ``(dims, values, attrs)`` of dimension ``dim``: the scale of that name
    in the group or above it, else the columns' names or ``coords`` of a table along it,
    else the row numbers."""
    for t in [*tables, *above]:
        if t.dims == (t.name,) and t.name == dim:
            return (dim,), np.asarray(t.data), _attrs(t)
    for t in tables:
        if t.coords is not None and dim in t.coords:
            return (dim,), np.asarray(list(t.coords[dim])), {"units": "1"}
        if t.names is not None and t.dims[-1] == dim:
            return (dim,), np.asarray(list(t.names)), {"units": "1"}
    return (dim,), np.arange(size), {"units": "1"}


def as_dataset(tables: Sequence[Table], attrs: Mapping[str, Any] = {}, above: Sequence[Table] = ()):
    """The ``xarray.Dataset`` :func:`suspopt.io.open_dataset` reads from a group of
    ``tables`` (module docstring), ``above`` the tables of the groups above it (their
    scales), ``attrs`` the group's attributes (the root's included)."""
    import xarray

    variables, coords = {}, {}
    for t in tables:
        data = np.asarray(t.data)
        if t.dims == (t.name,):
            coords[t.name] = (t.dims, data, _attrs(t))
            continue
        variables[t.name] = (t.dims, data, _attrs(t))
        for dim, size in zip(t.dims, data.shape):
            if dim not in coords:
                coords[dim] = _scale(dim, size, tables, above)
    return xarray.Dataset(variables, coords, {k: _as_read(v) for k, v in attrs.items()})


def group_name(group: str | None) -> str:
    """``group`` as a path of groups without empty or ``.`` parts (``""`` the root);
    TypeError when it is not a text."""
    if group is not None and not isinstance(group, str):
        raise TypeError(f"group must be a str, e.g. 'signals'; got {type(group).__name__}")
    return "/".join(p for p in (group or "").split("/") if p not in ("", "."))


def group_dataset(
    groups: Mapping[str, Sequence[Table]],
    group: str | None,
    attrs: Mapping[str, Mapping[str, Any]],
    where: str,
):
    """:func:`as_dataset` of ``group`` (``None``, ``""``, ``"."`` or ``"/"``: the root) of
    ``groups`` (group -> tables), with ``attrs[""]`` (the root's) under ``attrs[group]``;
    a KeyError listing the groups ``where`` (the object) has for any other name."""
    name = group_name(group)
    if name not in groups:
        held = ", ".join(repr(g) for g in groups if g)
        raise KeyError(f"{where}: no group {group!r}; it has {held} (and the root, '')")
    parts = name.split("/") if name else []
    above = [t for depth in range(len(parts)) for t in groups.get("/".join(parts[:depth]), ())]
    return as_dataset(groups[name], {**attrs.get("", {}), **attrs.get(name, {})}, above)


def frame(ds):
    """A tidy pandas DataFrame of the Dataset ``ds``, each column's unit in
    ``df.attrs["units"]``. A table along one dimension (``design``, ``generation``), its
    variables of that dimension alone or of one more dimension of names (``variable``,
    ``objective``, ``constraint``), is one row per entry, a column per variable or per name
    (``best[f1]`` beside variables of the dimension alone, or for a name that two
    variables share). Anything else (signals over ``design``
    and ``time``) is long: ``ds.to_dataframe()``, one row per point of the dimensions."""
    import pandas as pd

    data = list(ds.data_vars.values())
    first = {v.dims[0] for v in data if v.dims}
    wide = len(first) == 1 and all(
        v.ndim == 1 or (v.ndim == 2 and ds[v.dims[1]].dtype.kind in "USO") for v in data
    )
    if not wide:
        df = ds.to_dataframe() if ds.sizes else pd.DataFrame()
        df.attrs["units"] = {str(k): v.attrs.get("units", "") for k, v in ds.data_vars.items()}
        return df
    labels = [
        [str(n)] if v.ndim == 1 else [str(c) for c in ds[v.dims[1]].values]
        for n, v in ds.data_vars.items()
    ]
    flat = [c for cols in labels for c in cols]
    plain = all(v.ndim == 2 for v in data)  # (a table of tables: X, F, G)
    columns, units = {}, {}
    for (name, v), cols in zip(ds.data_vars.items(), labels):
        values = np.asarray(v.values).reshape(len(v), -1)
        unit = np.broadcast_to(np.asarray(v.attrs.get("units", ""), dtype=object), (len(cols),))
        for j, c in enumerate(cols):
            key = c if v.ndim == 1 or (plain and flat.count(c) == 1) else f"{name}[{c}]"
            columns[key], units[key] = values[:, j], str(unit[j])
    dim = first.pop()
    df = pd.DataFrame(columns, index=pd.Index(ds[dim].values, name=dim))
    df.attrs["units"] = units
    return df
