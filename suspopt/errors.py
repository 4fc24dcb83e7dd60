"""The error every part of suspopt raises for bad input (a light module: the command line
catches it before anything heavy is imported)."""

import difflib
from collections.abc import Iterable

__all__ = ["ConfigError", "check_known"]


class ConfigError(ValueError):
    """Bad input: the message is one line naming the file, line and key path (or the file and
    the dataset)."""


def check_known(what: str, name: str, known: Iterable[str]) -> str:
    """Return ``name`` if it is in ``known``, else raise ValueError with the closest matches."""
    known = list(known)
    if name not in known:
        close = difflib.get_close_matches(name, known, n=3)
        raise ValueError(
            f"unknown {what} {name!r}"
            + (f"; did you mean {', '.join(close)}?" if close else f"; known: {', '.join(known)}")
        )
    return name
