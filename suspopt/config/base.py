"""Common base of every config section: unknown keys are rejected, numbers stay numbers."""

from __future__ import annotations

import difflib
from collections.abc import Iterable

from pydantic import BaseModel, ConfigDict

__all__ = ["Section", "check_known"]


class Section(BaseModel):
    """Base class of all config sections.

    Unknown keys are errors (a misspelt key must never be silently ignored) and fields are
    validated on assignment so that a programmatic edit is checked like a YAML value. Types
    are strict: a number field takes a number (an integer field a whole number written
    without a point), never a boolean or a string, and a text field takes text.
    """

    model_config = ConfigDict(extra="forbid", validate_assignment=True, frozen=False,
                              strict=True)


def check_known(what: str, name: str, known: Iterable[str]) -> str:
    """Return ``name`` if it is in ``known``, else raise ValueError with the closest matches."""
    known = list(known)
    if name not in known:
        close = difflib.get_close_matches(name, known, n=3)
        raise ValueError(f"unknown {what} {name!r}" + (
            f"; did you mean {', '.join(close)}?" if close else f"; known: {', '.join(known)}"))
    return name
