"""Where the command prints: the consoles :data:`out` and :data:`err` (plain lines without
rich, rich made on first use) and the tables that fold to the terminal (:func:`new_table`)."""

from __future__ import annotations

import contextlib
import functools
import os
import sys
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rich.console import Console
    from rich.table import Table

__all__ = ["LazyConsole", "out", "err", "new_table"]

#: The control characters a printed line drops (all of C0 but tab and newline, and DEL): text
#: from files and arguments must not move the cursor or colour the terminal.
_CONTROL = dict.fromkeys([*range(9), *range(11, 32), 127])


class LazyConsole:
    """Where the commands print: plain text lines are written as they are (their control
    characters dropped), anything else (tables, progress bars) through a rich ``Console``
    made on first use - rich takes about 17 ms to import, which a command that prints only
    lines (``validate``) does not pay. Text from files and arguments is never read as rich
    markup, emoji codes (":x:" in a file name) or highlighted. ``quiet`` silences both."""

    def __init__(self, stderr: bool = False):
        self._stderr, self._quiet = stderr, False
        self._console: Console | None = None

    @property
    def console(self) -> Console:
        if self._console is None:
            from rich.console import Console

            class _Console(Console):
                def on_broken_pipe(console) -> None:  # rich's default: SystemExit(1)
                    self._reader_gone()

            self._console = _Console(
                stderr=self._stderr,
                markup=False,
                emoji=False,
                highlight=False,
                soft_wrap=True,
                quiet=self._quiet,
            )
        return self._console

    @property
    def quiet(self) -> bool:
        return self._quiet

    @quiet.setter
    def quiet(self, value: bool) -> None:
        self._quiet = value
        if self._console is not None:
            self._console.quiet = value

    def print(self, *objects: Any, **kwargs: Any) -> None:
        """Print ``objects``: text alone as one line (soft-wrapped, as rich would with
        ``soft_wrap``), anything else through rich."""
        if all(isinstance(o, str) for o in objects) and set(kwargs) <= {"soft_wrap"}:
            if not self._quiet:
                try:
                    self._stream().write(" ".join(objects).translate(_CONTROL) + "\n")
                except BrokenPipeError:
                    self._reader_gone()
            return
        self.console.print(*objects, **kwargs)

    def _stream(self):
        return sys.stderr if self._stderr else sys.stdout

    def _reader_gone(self) -> None:
        """The reader of the stream went away (``suspopt simulate ... | head``): the command
        goes on, its outputs are written and its exit code is its own; what it would still
        print goes to the null device."""
        self.quiet = True
        with contextlib.suppress(OSError, ValueError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), self._stream().fileno())

    def __getattr__(self, name: str) -> Any:  # width, is_terminal, ...
        return getattr(self.console, name)


out = LazyConsole()
err = LazyConsole(stderr=True)


def new_table(title: str | None = None) -> Table:
    """A rich table whose cells fold onto further lines when the terminal is narrow (a CI
    log's 80 columns) instead of being cut to "…"; its rows as given are kept in ``cells``
    for :func:`show_table`."""
    return _folding_table()(title=title)


@functools.cache
def _folding_table() -> type:
    """The class of :func:`new_table` (made when first needed: it needs rich)."""
    from rich.table import Table

    class FoldingTable(Table):
        def __init__(self, *args, **kwargs) -> None:
            super().__init__(*args, **kwargs)
            self.cells: list[tuple[str, ...]] = []

        def add_column(self, *args, **kwargs) -> None:
            kwargs.setdefault("overflow", "fold")
            super().add_column(*args, **kwargs)

        def add_row(self, *cells, **kwargs) -> None:
            self.cells.append(tuple(str(c) for c in cells))
            super().add_row(*cells, **kwargs)

    return FoldingTable
