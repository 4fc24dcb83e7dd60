"""What the library tells while it works (:mod:`suspopt._notices`), shown on stderr.

- A compile of the compiled engine's numba code that lasts more than :data:`DELAY` seconds
  (the first compiled run on a machine compiles the kernel once, a minute or more) gets a
  live indicator on a terminal (a spinner and the time so far; a line of the optimiser's
  progress bar while that bar is on screen), or one line where stderr is not a terminal (a
  CI log), and when it ends a line saying what it cost and where it is kept. A cache's load
  (well under a second) shows nothing.
- ``simulation.engine: auto`` falling back to numpy is one ``note:`` line.

``-q`` silences both, as it does the progress bar.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from .console import err, out

__all__ = ["Notices", "notices", "duration"]

#: A compile shown once it has lasted this long [s].
DELAY = 1.0
#: How often the indicator's time is redrawn [s].
TICK = 0.5


def duration(seconds: float) -> str:
    """``41 s``, ``2 min 18 s``."""
    whole = int(round(seconds))
    if whole < 60:
        return f"{seconds:.1f} s" if seconds < 10 else f"{whole} s"
    return f"{whole // 60} min {whole % 60} s"


class Notices:
    """The command line's listener of :mod:`suspopt._notices` (module docstring)."""

    def __init__(self) -> None:
        self.progress: Any = None  # the optimiser's rich Progress while it is on screen
        self._stop: threading.Event | None = None
        self._thread: threading.Thread | None = None
        self._shown = False

    @contextmanager
    def beside(self, progress: Any) -> Iterator[None]:
        """While the block runs, a compile's indicator is a line of ``progress`` (a rich
        Progress on screen) instead of a spinner of its own."""
        self.progress = progress if progress.live.is_started else None
        try:
            yield
        finally:
            self.progress = None

    def __call__(self, kind: str, **data: Any) -> None:
        if out.quiet:
            return
        if kind == "engine-fallback":
            err.print(f"note: {data['message']}", soft_wrap=True)
        elif kind == "compile-start":
            self._start(str(data["what"]))
        elif kind == "compile-end":
            self._end(str(data["what"]), float(data["seconds"]), data.get("cache"))

    def _text(self, what: str, seconds: float) -> str:
        whole = int(seconds)
        return f"compiling {what}, once for this machine {whole // 60}:{whole % 60:02d}"

    def _start(self, what: str) -> None:
        self._stop, self._shown = threading.Event(), False
        self._thread = threading.Thread(
            target=self._indicate, args=(what, time.perf_counter(), self._stop), daemon=True
        )
        self._thread.start()

    def _indicate(self, what: str, start: float, stop: threading.Event) -> None:
        if stop.wait(DELAY):
            return
        self._shown = True
        text = self._text(what, time.perf_counter() - start)
        if not err.is_terminal:
            err.print(f"compiling {what}, once for this machine (later runs load it) ...")
            return
        progress, status, task = self.progress, None, None
        if progress is not None:
            task = progress.add_task(text, total=None)
        else:
            status = err.console.status(text)
            status.start()
        try:
            while not stop.wait(TICK):
                text = self._text(what, time.perf_counter() - start)
                if task is not None:
                    progress.update(task, description=text)
                elif status is not None:
                    status.update(text)
        finally:
            if task is not None:
                progress.remove_task(task)
            if status is not None:
                status.stop()

    def _end(self, what: str, seconds: float, cache: Any) -> None:
        if self._stop is None or self._thread is None:
            return
        self._stop.set()
        self._thread.join()
        self._stop = self._thread = None
        if self._shown:
            where = f"; kept in {cache}" if cache is not None else ""
            err.print(f"compiled {what} in {duration(seconds)}{where}", soft_wrap=True)


#: The one listener of the process.
notices = Notices()
