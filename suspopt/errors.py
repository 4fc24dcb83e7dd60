"""The error every part of suspopt raises for bad input (a light module: the command line
catches it before anything heavy is imported)."""

import difflib
from collections.abc import Iterable

__all__ = ["ConfigError", "check_known", "require", "type_name"]


class ConfigError(ValueError):
    """Bad input: the message is one line naming the file, line and key path (or the file and
    the dataset)."""


def type_name(value: object) -> str:
    """The type of ``value`` for a message, and the value itself when it is short."""
    shown = repr(value)
    return type(value).__name__ + (f" {shown}" if len(shown) <= 60 else "")


def require(value, kind: type, argument: str, how: str):
    """``value`` when it is a ``kind``, else a TypeError naming ``argument`` and ``how`` to make
    one: the library's entry points call it first, so that another object given (a path where
    the loaded file belongs) is not an AttributeError from deep inside."""
    if not isinstance(value, kind):
        raise TypeError(f"{argument} must be a {kind.__name__} ({how}); got {type_name(value)}")
    return value


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
