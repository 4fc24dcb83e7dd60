"""Long tables summarised on the terminal (:func:`suspopt.cli.base.show_table` without
``--full``): a table of more than :data:`LONG_TABLE` rows shows its first
:data:`SUMMARY_ROWS`, a table split into parts to fit the terminal's width shows the parts
that fit in :data:`SUMMARY_LINES` lines, and one line counts the rest (and of its notes,
the first and the last :data:`SUMMARY_NOTES`, :func:`notes_that_fit`)::

    ... 385 more rows and 17 more parts (68 columns): --full for all; the whole table is
    in built.h5

The whole table is always in the command's output file; without one the line says that
``-o FILE`` keeps it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

#: A table of :func:`suspopt.cli.base.new_table` (a rich ``Table`` with its ``cells``).
Table = Any

#: A table of more rows than this is cut to its first :data:`SUMMARY_ROWS`.
LONG_TABLE = 25
#: The rows a cut table shows.
SUMMARY_ROWS = 10
#: The most lines the parts of a summarised table take (one part at least).
SUMMARY_LINES = 40
#: The most notes below a table (its first ones and its last are kept).
SUMMARY_NOTES = 6
#: The lines a part takes besides its rows: title, borders and header.
_FRAME_LINES = 5


def top_rows(table: Table) -> Table:
    """``table``, or when it has more than :data:`LONG_TABLE` rows a copy of its first
    :data:`SUMMARY_ROWS` (with its columns, title and section ends)."""
    from .console import new_table

    if len(table.cells) <= LONG_TABLE:
        return table
    top = new_table(table.title)
    for column in table.columns:
        top.add_column(column.header, justify=column.justify)
    for row, kept in zip(table.cells[:SUMMARY_ROWS], table.rows):
        top.add_row(*row, end_section=kept.end_section)
    return top


def parts_that_fit(parts: list[Table]) -> list[Table]:
    """The first of ``parts`` whose lines (rows and frames) take at most
    :data:`SUMMARY_LINES`, the first always."""
    kept: list[Table] = []
    used = 0
    for part in parts:
        lines = len(part.cells) + _FRAME_LINES
        if kept and used + lines > SUMMARY_LINES:
            break
        kept.append(part)
        used += lines
    return kept


def rest_line(
    table: Table, shown: Table, left_out: list[Table], where: Path | None, keys: int
) -> str | None:
    """The line counting what the summary of ``table`` (its rows ``shown``, its parts
    ``left_out``, each of which repeats the ``keys`` first columns) does not print, or None
    when it prints everything."""
    said = []
    rows = len(table.cells) - len(shown.cells)
    if rows:
        said.append(f"{rows} more rows")
    if left_out:
        columns = sum(len(p.columns) - keys for p in left_out)
        many = "s" if len(left_out) > 1 else ""
        said.append(f"{len(left_out)} more part{many} ({columns} columns)")
    if not said:
        return None
    kept = f"the whole table is in {where}" if where is not None else "-o FILE keeps it"
    return f"... {' and '.join(said)}: --full for all; {kept}"


def notes_that_fit(notes: list[str]) -> list[str]:
    """``notes``, or of more than :data:`SUMMARY_NOTES` their first and last ones and a line
    counting those left out (the last note is a table's conclusion: "largest change of
    each objective")."""
    if len(notes) <= SUMMARY_NOTES:
        return notes
    left = len(notes) - SUMMARY_NOTES + 1
    return [*notes[: SUMMARY_NOTES - 2], notes[-1], f"... {left} more notes: --full for all"]
