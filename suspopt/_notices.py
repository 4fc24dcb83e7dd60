"""What the library has to tell whoever runs it while it works, without printing it.

The library prints nothing. Some things it does still deserve a word to the user: the compiled
engine's kernel being compiled for this machine (a pause of a minute or more the first time),
or ``simulation.engine: auto`` falling back to numpy because numba cannot be imported. The
library hands such notices to the listeners registered here; the command line registers one
that shows them on stderr (a live indicator while a compile runs). With no listener (the
library used from Python), a fallback is a ``UserWarning`` and a compile is logged on the
``suspopt`` logger at INFO level.

This module imports nothing, so that the command line can register its listener at start-up
for free.

Notices (``kind``, then the keyword data):

- ``"compile-start"``: a compile of suspopt's numba code began (``what``: what is compiled);
- ``"compile-end"``: it ended (``what``, ``seconds``: its wall time, ``cache``: the folder
  that keeps it, or None where it cannot be kept);
- ``"engine-fallback"``: ``engine: auto`` runs on numpy (``message``: which engine and why),
  said once per process.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["Listener", "listen", "unlisten", "tell"]

#: A listener: called with the notice's kind and its data.
Listener = Callable[..., None]

_listeners: list[Listener] = []


def listen(listener: Listener) -> None:
    """Register ``listener`` (``listener(kind, **data)``), once."""
    if listener not in _listeners:
        _listeners.append(listener)


def unlisten(listener: Listener) -> None:
    """Remove ``listener`` (nothing when it is not registered)."""
    if listener in _listeners:
        _listeners.remove(listener)


def tell(kind: str, **data: Any) -> bool:
    """Hand the notice to every listener; whether there was one (else the caller says it
    its own way: a warning, a log line)."""
    for listener in list(_listeners):
        listener(kind, **data)
    return bool(_listeners)
