"""The ``suspopt`` command: a thin layer that reads arguments, calls the library and renders.

Exit codes: 0 success; 2 bad input (config, file, arguments) with one line naming the YAML key
and line (or the file and dataset); 3 a run whose every optimum design failed to simulate;
130 interrupted, 143 terminated (SIGTERM; suspopt._entry); 1 an unexpected failure (a bug).

Layout: :mod:`~suspopt.cli.base` holds the app, its global options, the consoles and the
shared helpers; each command lives in its own module (``configs``: validate, schema, init,
export; ``simulation``; ``analysis``; ``optimisation``; ``selection``: kesort), which registers
it on the app when imported here.
"""

from __future__ import annotations

from . import analysis, configs, optimisation, report, selection, simulation  # noqa: F401  (register)
from .base import EXIT_ALL_FAILED, app, err, out, plain_helps

plain_helps(app)

__all__ = ["app", "out", "err", "EXIT_ALL_FAILED"]
