"""Designs picked from a result file, taken onward: re-simulated, or written as a config.

A *design table* is the table of designs a result file holds, with their variables ``X``
(physical values) and objectives ``F``:

- ``suspopt optimise`` output: ``/pareto`` (the optimum or the Pareto set);
- ``suspopt kesort`` output: ``/kesort`` (the pooled sets; each design keeps the config of
  its set, ``/kesort/sets/config``);
- ``suspopt analyse roads|masses|controllers|tolerances|builds`` output: ``/pareto`` (the
  stored front, or the designs it was given with ``--pick``: :func:`read_front`);
- ``suspopt analyse transmissibility`` of a front: ``/designs`` (its edges and knee).

A *pick* names one row of it: ``knee``, ``best_<objective>`` (the edges of the front,
:func:`suspopt.choosing.kepsilon.pareto_picks`, or the ones the file stored), ``chosen`` (the k-ε
optimum of a kesort file) or a design's id (:mod:`suspopt.design_ids`: its row in the front
it came from, ``NAME:ROW`` in a kesort file of several fronts), which names the same design
in every file that holds it. :func:`read_picks` resolves picks into
:class:`Picked` designs; :meth:`Picked.params` gives them to :func:`suspopt.simulate` in one
batch, and :func:`design_config` writes one of them into its config as a standalone YAML.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..config import Config, ConfigError
from ..config.loader import edit_config, load_config_text, set_path
from ..config.road import FileRoad, resolve_road_file
from ..errors import require, type_name
from ..files import listed
from ..params import ParamView

if TYPE_CHECKING:
    from .selection import ParetoSet

__all__ = [
    "Picked",
    "DesignTable",
    "read_table",
    "read_picks",
    "read_front",
    "design_config",
    "split_picks",
    "stored_scenario_values",
]


@dataclass
class DesignTable:
    """The designs of a result file: ``X (N, n)`` physical values, ``F (N, m)``, their names
    and units; ``picks`` by name (row indices); ``configs`` the YAML text of each row's
    config and ``config_of (N,)`` which one; ``table`` the group (``pareto``, ``kesort``,
    ``designs``); ``ids`` each row's design id (:func:`suspopt.design_ids.table_ids`)."""

    path: Path
    table: str
    X: np.ndarray
    var_names: list[str]
    var_units: list[str]
    F: np.ndarray
    obj_names: list[str]
    obj_units: list[str]
    picks: dict[str, int]
    configs: list[str]
    config_of: np.ndarray
    ids: list[str]

    def resolve(self, pick: str, option: str = "--pick") -> int:
        """The row of ``pick`` (a name or a design id); ConfigError, naming the command-line
        ``option`` it came from, listing the choices."""
        from ..design_ids import describe_ids, find_id

        if pick in self.picks:
            return self.picks[pick]
        row = find_id(self.ids, pick)
        if row is None and pick.strip().isdigit():
            raise ConfigError(
                f"{option} {pick}: {self.path}: /{self.table} has "
                + (
                    f"rows 0 to {len(self.X) - 1}"
                    if self.ids == [str(k) for k in range(len(self.X))]
                    else f"no design {pick} (its designs: {describe_ids(self.ids)})"
                )
            )
        if row is None:
            raise ConfigError(
                f"{option} {pick}: {self.path} has no such pick; it has "
                f"{', '.join([*self.picks, 'a design id'])} (its designs: "
                f"{describe_ids(self.ids)})"
            )
        return row


@dataclass
class Picked:
    """Designs picked from one table, all of one config: ``names`` (the picks as given),
    ``rows`` in the table, ``ids`` their design ids (:mod:`suspopt.design_ids`), ``X (P,
    n)`` physical values of ``var_names`` at ``paths``, ``F (P, m)`` their stored
    objectives, and ``config`` (resolving relative paths from the file's folder)."""

    source: Path
    table: str
    names: list[str]
    rows: np.ndarray
    X: np.ndarray
    var_names: list[str]
    var_units: list[str]
    paths: list[str]
    F: np.ndarray
    obj_names: list[str]
    obj_units: list[str]
    config: Config
    ids: list[str]

    def params(self) -> dict[str, np.ndarray]:
        """``simulate``'s params: dotted path -> (P,) values."""
        return {path: self.X[:, j] for j, path in enumerate(self.paths)}

    def labels(self) -> list[str]:
        """Each design as a figure names it: the pick and its id (``knee (design 13)``), the
        id alone where the pick was the id."""
        from ..design_ids import find_id

        return [
            f"design {i}" if find_id([i], name) == 0 else f"{name} (design {i})"
            for name, i in zip(self.names, self.ids)
        ]


def split_picks(given: list[str]) -> list[str]:
    """``--pick`` values as given (repeatable, each may list several separated by commas)."""
    picks = [p.strip() for item in given for p in item.split(",") if p.strip()]
    if not picks:
        raise ConfigError("--pick: name a design: knee, best_<objective>, chosen or a design id")
    return picks


def read_table(path: str | Path) -> DesignTable:
    """The design table of an optimise, kesort or analyse file (module docstring);
    ConfigError naming the file and the dataset for anything else."""
    from ..design_ids import table_ids
    from ..h5read import H5Reader
    from .kepsilon import pareto_picks

    path = Path(path)
    with H5Reader(path) as h5:
        groups = set(h5.file.keys())
        if "kesort" in groups:
            table = "kesort"
        elif "pareto" in groups:
            table = "pareto"
        elif "designs" in groups and "F" in h5.file["designs"]:
            table = "designs"
        else:
            raise ConfigError(
                f"{path}: holds no designs to pick (/pareto, /kesort or /designs){h5._holds()}:"
                f" give a file of suspopt optimise, kesort or analyse roads, masses,"
                f" controllers, tolerances, builds or transmissibility (of a Pareto file)"
            )
        X = h5.array(f"{table}/X", ndim=2)
        F = h5.array(f"{table}/F", ndim=2)
        if len(X) != len(F) or len(X) == 0:
            raise ConfigError(f"{path}: /{table}: X and F have {len(X)} and {len(F)} rows")
        var_names = h5.labels(f"{table}/X", "names", X.shape[1])
        var_units = h5.labels(f"{table}/X", "units", X.shape[1])
        obj_names = h5.labels(f"{table}/F", "names", F.shape[1])
        obj_units = h5.labels(f"{table}/F", "units", F.shape[1])
        h5.objectives(f"{table}/F", F, obj_names)
        picks: dict[str, int] = {}
        stored = True  # (the file says which design each pick is; else they are computed)
        if table == "kesort":
            sets = h5.group("kesort/sets")
            configs = [
                h5.text(v, "/kesort/sets/config")
                for v in np.atleast_1d(h5.dataset("kesort/sets/config")[()])
            ]
            config_of = h5.array("kesort/source", ndim=1, integer=True)
            del sets
            picks["chosen"] = _index(h5, "kesort/chosen", len(X))
            picks.update(_stored_picks(h5, "kesort/picks", len(X)))
        else:
            configs = [h5.text_attr("config")]
            config_of = np.zeros(len(X), dtype=np.int64)
            if table == "designs":  # (analyse transmissibility: the picks of each row)
                entries = _row_picks(h5, len(X))
                stored = entries is not None
                for row, entry in enumerate(entries or []):
                    for name in entry.split(","):
                        picks.setdefault(name.strip(), row)
            elif "pareto/picks" in h5.file:  # (an analysis: of the front, or --pick)
                picks.update(_stored_picks(h5, "pareto/picks", len(X)))
            else:  # (an optimise file)
                stored = False
        if ((config_of < 0) | (config_of >= len(configs))).any():
            raise ConfigError(f"{path}: /kesort/source: indices beyond /kesort/sets")
        ids = table_ids(h5, table, len(X))
    if not stored and np.isfinite(F).all():
        picks = pareto_picks(F, obj_names)
    return DesignTable(
        path, table, X, var_names, var_units, F, obj_names, obj_units, picks, configs, config_of,
        ids,
    )  # fmt: skip


def _row_picks(h5, rows: int) -> list[str] | None:
    """The attribute ``picks`` of ``/designs``: the picks of each of its ``rows`` rows,
    comma-separated (None where it is missing)."""
    if not h5.has_attr("picks", "designs"):
        return None
    return h5.labels("designs", "picks", rows, kind="Group", of="designs")


def _index(h5, name: str, rows: int) -> int:
    value = h5.array(name, ndim=0, integer=True)
    if not 0 <= int(value) < rows:
        raise ConfigError(f"{h5.where}: /{name}: {int(value)} is not a row of the table")
    return int(value)


def _stored_picks(h5, group: str, rows: int) -> dict[str, int]:
    return {name: _index(h5, f"{group}/{name}", rows) for name in h5.group(group)}


def read_picks(path: str | Path, picks: str | Sequence[str]) -> Picked:
    """The designs ``picks`` of the file ``path`` (module docstring), with their config.
    ``picks`` as ``--pick`` takes them: names or row numbers, a list or one string, each
    item possibly several separated by commas; none is a ConfigError."""
    picks = split_picks([str(p) for p in listed(picks)])
    table = read_table(path)
    rows = np.array([table.resolve(p) for p in picks])
    which = sorted({int(table.config_of[r]) for r in rows})
    if len(which) > 1:
        raise ConfigError(
            f"--pick: {', '.join(picks)} come from sets of {table.path} with "
            f"different configs; pick designs of one set at a time"
        )
    cfg = load_config_text(
        table.configs[which[0]], table.path.with_name(table.path.name + ":config")
    )
    path_of = {v.label: v.path for v in cfg.design_variables}
    missing = [n for n in table.var_names if n not in path_of]
    X = table.X[rows]
    keep = [j for j, n in enumerate(table.var_names) if n in path_of]
    if (
        missing
        and not np.isnan(X[:, [j for j, n in enumerate(table.var_names) if n in missing]]).all()
    ):
        raise ConfigError(
            f"{table.path}: /{table.table}/X holds {', '.join(missing)}, which "
            f"the stored config's design_variables do not have"
        )
    X = X[:, keep]
    if not np.isfinite(X).all():
        raise ConfigError(
            f"{table.path}: /{table.table}/X: the picked designs have no value for some variable"
        )
    names = [table.var_names[j] for j in keep]
    try:  # a stored value its field cannot take
        ParamView(cfg, {path_of[n]: X[:, j] for j, n in enumerate(names)})
    except ConfigError as exc:
        raise ConfigError(f"{table.path}: /{table.table}/X: {exc}") from None
    return Picked(
        source=table.path,
        table=table.table,
        names=list(picks),
        rows=rows,
        X=X,
        var_names=names,
        var_units=[table.var_units[j] for j in keep],
        paths=[path_of[n] for n in names],
        F=table.F[rows],
        obj_names=table.obj_names,
        obj_units=table.obj_units,
        config=cfg,
        ids=[table.ids[r] for r in rows],
    )


def design_config(picked: Picked, i: int = 0) -> tuple[Config, str]:
    """Design ``i`` of ``picked`` written into its config: the values in place, a road file
    made absolute (the config leaves the file's folder), and a comment block saying where
    it came from. Returns the config and its YAML text."""
    from .._version import __version__

    require(picked, Picked, "picked", "from read_picks(path, picks)")
    if isinstance(i, bool) or not isinstance(i, (int, np.integer)):
        raise TypeError(f"i must be a design's row number in picked; got {type_name(i)}")
    if not -len(picked.X) <= i < len(picked.X):
        raise IndexError(
            f"design {i!r}: picked holds {len(picked.X)} design(s), 0..{len(picked.X) - 1}"
        )
    cfg = picked.config
    values = {path: float(picked.X[i, j]) for j, path in enumerate(picked.paths)}

    def put(data: dict) -> None:
        for path, value in values.items():
            set_path(data, path, value)
        if isinstance(cfg.road, FileRoad) and isinstance(data.get("road"), dict):
            data["road"]["path"] = str(resolve_road_file(cfg.road, cfg.base_dir).resolve())

    edited = edit_config(cfg.text, put, cfg.source, "the picked design's values")
    objectives = ", ".join(
        f"{n} = {v:.6g} {u}".rstrip()
        for n, v, u in zip(picked.obj_names, picked.F[i], picked.obj_units)
    )
    variables = ", ".join(
        f"{n} = {v:.6g} {u}".rstrip()
        for n, v, u in zip(picked.var_names, picked.X[i], picked.var_units)
    )
    header = "\n".join(
        [
            f"# Design {picked.names[i]!r} (row {int(picked.rows[i])} of /{picked.table}, design "
            f"id {picked.ids[i]}) of {picked.source}",
            f"# written by suspopt {__version__}: the stored config with the design's values in "
            f"place.",
            f"# stored objectives: {objectives}",
            f"# design variables: {variables}",
        ]
    )
    text = header + "\n" + edited.text
    return load_config_text(text, cfg.source), text


def read_front(path: str | Path, picks: Sequence[str] | None = None) -> ParetoSet:
    """The front a front analysis takes: with no ``picks``, the Pareto set of a ``suspopt
    optimise`` file (:func:`suspopt.choosing.selection.read_pareto`); with ``picks`` (``--pick`` as
    ``simulate`` takes them: ``knee``, ``best_<objective>``, ``chosen``, row numbers;
    comma-separated or repeated), those designs alone, from any file whose designs can be
    picked (:func:`read_picks`: optimise, kesort or analyse), each once, in the order first
    named. They keep their stored main objectives and, from an optimise file, their
    constraints; from any other file ``G`` is None and they are evaluated again."""
    from ..optimisation.problem import Problem
    from .selection import ParetoSet, read_pareto

    if not picks:
        try:
            return read_pareto(path)
        except ConfigError as exc:
            try:
                stores = _stores_constraints(Path(path))
            except ConfigError:
                stores = True  # (unreadable: the first error says it)
            if stores:
                raise
            raise ConfigError(
                f"{exc}; to analyse designs of it, give --pick (knee, best_<objective>, "
                f"chosen or design ids)"
            ) from None
    picked = read_picks(path, split_picks(list(picks)))
    first: dict[int, int] = {}  # source row -> row here
    keep: list[int] = []  # each row here: its first pick
    marks: dict[str, int] = {}
    for i, (name, row) in enumerate(zip(picked.names, picked.rows.tolist())):
        if row not in first:
            first[row] = len(keep)
            keep.append(i)
        if not name.isdigit() and name not in picked.ids:  # (an id names no pick)
            marks.setdefault(name, first[row])
    cfg = picked.config
    main = Problem.from_config(cfg).obj_names
    missing = [n for n in main if n not in picked.obj_names]
    if not main or missing:
        raise ConfigError(
            f"{picked.source}: /{picked.table}/F holds {', '.join(picked.obj_names)}; its "
            f"config's main objectives are {', '.join(main) or 'none'}"
        )
    columns = [picked.obj_names.index(n) for n in main]
    G, constraint_names = None, []
    if picked.table == "pareto" and _stores_constraints(picked.source):
        whole = read_pareto(picked.source)
        G = None if whole.G is None else whole.G[list(first)]
        constraint_names = whole.constraint_names
    return ParetoSet(
        picked.source,
        picked.X[keep],
        picked.var_names,
        picked.var_units,
        picked.F[keep][:, columns],
        main,
        G,
        constraint_names,
        cfg.text,
        picked=marks,
        source_rows=np.array(list(first), dtype=np.int64),
        ids=tuple(picked.ids[i] for i in keep),
    )


def _stores_constraints(path: Path) -> bool:
    """Whether the file ``path`` has ``/pareto/G`` (a ``suspopt optimise`` output)."""
    from ..h5read import H5Reader

    with H5Reader(path) as h5:
        return "pareto/G" in h5.file


def stored_scenario_values(
    picked: Picked, scenario: int, names: Sequence[str]
) -> tuple[np.ndarray, str]:
    """The stored values ``(P, m)`` of the objectives of ``picked`` (its columns
    ``obj_names``) under the scenario ``scenario`` (an index into the config's scenario
    ``names``), and a note ("" when there is nothing to say): ``/pareto/scenarios/F`` of
    the front each design came from at its row there. For a pick of a front, that is its own
    file; for a pick of a kesort file, the front of its set (``/kesort/sets/file``, as
    given to kesort or beside the kesort file) at its ``/kesort/row``, when that front still
    holds the config kesort evaluated it with (otherwise its values are not the ones it was
    sorted on). NaN where no value is stored (a front of no scenarios, a supplementary
    objective, a front moved away; the note says which)."""
    from ..h5read import H5Reader

    stored = np.full_like(picked.F, np.nan)
    origins = _origins(picked)
    if origins is None:
        return stored, ""
    notes = []
    for front, text, at, rows in origins:
        if front is None:
            notes.append(f"{text}: not found; its stored scenario values are not shown")
            continue
        with H5Reader(front) as h5:
            if h5._node("pareto/scenarios/F") is None:
                continue
            if text is not None and h5.text_attr("config") != text:
                notes.append(
                    f"{front} holds another config than the one {picked.source} sorted its "
                    f"designs with; their stored scenario values are not shown"
                )
                continue
            F = h5.array("pareto/F", ndim=2)
            front_names = h5.labels("pareto/F", "names", F.shape[1])
            FS = h5.array("pareto/scenarios/F", ndim=3, columns=F.shape[1])
        if FS.shape[1] != len(names) or len(FS) <= rows.max():
            raise ConfigError(
                f"{front}: /pareto/scenarios/F: shape {FS.shape} does not fit /pareto/F and "
                f"the config's {len(names)} scenarios"
            )
        for j, name in enumerate(picked.obj_names):
            if name in front_names:
                stored[at, j] = FS[rows, scenario, front_names.index(name)]
    return stored, "; ".join(notes)


def _origins(picked: Picked):
    """Where the designs of ``picked`` came from: ``(front, config text or None, indices in
    picked, rows in that front's /pareto)`` per front (``front`` None where a kesort
    file's front is not found; ``config text`` the kesort file's for the set, to check);
    None for a table that is neither /pareto nor /kesort."""
    from ..h5read import H5Reader

    everything = np.arange(len(picked.rows))
    if picked.table == "pareto":
        return [(picked.source, None, everything, picked.rows)]
    if picked.table != "kesort":
        return None
    with H5Reader(picked.source) as h5:
        count = len(h5.dataset("kesort/sets/file"))
        files = h5.texts("kesort/sets/file", count)
        configs = h5.texts("kesort/sets/config", count)
        source = h5.array("kesort/source", ndim=1, integer=True)[picked.rows]
        row = h5.array("kesort/row", ndim=1, integer=True)[picked.rows]
    out = []
    for k in np.unique(source):
        given = Path(files[k])
        beside = picked.source.parent / given
        front = given if given.is_file() else beside if beside.is_file() else None
        at = np.flatnonzero(source == k)
        out.append((front, configs[k] if front is not None else files[k], at, row[at]))
    return out
