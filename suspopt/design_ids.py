"""One identity per design: the id every table, pick, report label and result file names a
design by.

**The choice.** A design's id is its row in the ``suspopt optimise`` front it came from
(``/pareto`` of that file), written as a decimal number: ``13``. It does not change when a
later step filters the designs (``kesort`` leaving out infeasible ones, ``--pick`` taking a
few), so ``--pick 13`` names the same design in the front, in a ``kesort`` file of it and in
an ``analyse`` file of it. Where ``kesort`` pools several fronts, the id says which front too:
``NAME:ROW``, ``NAME`` the front's set name (:func:`set_names`: its case label, made unique
with ``#k`` where several fronts share one label), ``ROW`` its row in that front
(``C1:13``, ``front#2:7``).

**Where it is stored.** A file written by ``kesort`` holds ``/kesort/id (N,)``, one string per
design (``units`` ``1``, dimension ``design``); an ``analyse`` file holds ``/pareto/id``; the
``/designs/id`` of ``simulate --pick`` and of ``analyse transmissibility`` name the designs
simulated. A file without stored ids (written before they were stored, or an optimise
file, whose rows are the ids) gives each design its row number in the file's table, as
before (:func:`table_ids`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = [
    "set_names",
    "pooled_ids",
    "selection_ids",
    "front_ids",
    "table_ids",
    "find_id",
    "id_marks",
    "describe_ids",
    "picked_note",
    "ID_SEPARATOR",
]

#: Between a pooled front's set name and its row: ``C1:13``.
ID_SEPARATOR = ":"


def set_names(labels: Sequence[str]) -> list[str]:
    """The name of each pooled front in an id: its case ``labels[i]``, or ``label#k`` (``k``
    from 1 in their order) where several fronts carry the same label."""
    count = {label: list(labels).count(label) for label in labels}
    seen: dict[str, int] = {}
    names = []
    for label in labels:
        seen[label] = seen.get(label, 0) + 1
        names.append(label if count[label] == 1 else f"{label}#{seen[label]}")
    return names


def pooled_ids(labels: Sequence[str], source: np.ndarray, row: np.ndarray) -> np.ndarray:
    """The ids ``(N,)`` of pooled designs: ``row[i]`` (the design's row in its front) when
    one front is pooled, else ``NAME:ROW`` with ``NAME`` the set name (:func:`set_names`)
    of front ``source[i]`` (an index into ``labels``, one label per front)."""
    rows = [str(int(r)) for r in np.asarray(row)]
    if len(labels) == 1:
        return np.array(rows, dtype=object)
    names = set_names(labels)
    return np.array(
        [f"{names[int(s)]}{ID_SEPARATOR}{r}" for s, r in zip(np.asarray(source), rows)],
        dtype=object,
    )


def table_ids(h5, table: str, rows: int) -> list[str]:
    """The ids of the ``rows`` designs of the group ``table`` of an open file
    (:class:`suspopt.h5read.H5Reader`): ``/<table>/id`` where the file stores it (a
    ConfigError naming the dataset if it does not hold one unique id per design), else each
    design's row number in the table (files without stored ids)."""
    from .errors import ConfigError

    name = f"{table}/id"
    if h5._node(name) is None:
        return [str(k) for k in range(rows)]
    ids = h5.texts(name, rows)
    if len(set(ids)) != rows or not all(ids):
        raise ConfigError(
            f"{h5.where}: /{name}: {len(set(ids))} distinct ids for {rows} designs: one "
            f"non-empty id per design"
        )
    return ids


def find_id(ids: Sequence[str], pick: str) -> int | None:
    """The index of the design whose id is ``pick`` (None if no design has it). A number
    matches the id it spells (``013`` is ``13``)."""
    text = pick.strip()
    if text.isdigit():
        text = str(int(text))
    try:
        return list(ids).index(text)
    except ValueError:
        return None


def selection_ids(selection) -> np.ndarray:
    """The ids ``(N,)`` of the designs of a :class:`suspopt.choosing.selection.Selection`
    (:func:`pooled_ids` of its fronts' labels, sources and rows): ``/kesort/id``."""
    return pooled_ids([s.label for s in selection.sets], selection.source, selection.row)


def front_ids(pareto) -> list[str]:
    """The ids of the designs of a :class:`suspopt.choosing.selection.ParetoSet`: those it was read
    with (``ids``), else the rows of the file they were picked from (``source_rows``), else
    its own row numbers (a whole front)."""
    if pareto.ids is not None:
        return list(pareto.ids)
    rows = pareto.source_rows if pareto.source_rows is not None else range(len(pareto.X))
    return [str(int(r)) for r in rows]


def picked_note(pareto) -> list[str]:
    """The note of a report on the designs of a :class:`suspopt.choosing.selection.ParetoSet` picked
    from a file (``--pick``): each by its id and the names it was picked by; none for a
    whole front."""
    if pareto.source_rows is None:
        return []
    named = pareto.marks_by_row()
    each = [
        f"design {i}" + (f" ({', '.join(named[k])})" if k in named else "")
        for k, i in enumerate(front_ids(pareto))
    ]
    return [f"{len(pareto.X)} design(s) of {pareto.path.name} (--pick): " + "; ".join(each)]


def describe_ids(ids: Sequence[str], most: int = 8) -> str:
    """The ids of a table in a few words: ``0 to 39`` for rows in order, else the first
    ``most`` of them and their count."""
    ids = list(ids)
    if ids == [str(k) for k in range(len(ids))]:
        return f"0 to {len(ids) - 1}" if ids else "none"
    shown = ", ".join(ids[:most])
    return shown if len(ids) <= most else f"{shown}, ... ({len(ids)} designs)"


def id_marks(pareto, marks) -> dict[str, int]:
    """``marks`` (a pick's name -> its row in the :class:`suspopt.choosing.selection.ParetoSet`
    ``pareto``) with each name followed by the design's id, as a figure labels them:
    ``knee (design 13)``."""
    ids = front_ids(pareto)
    return {f"{name} (design {ids[k]})": k for name, k in marks.items()}
