"""Common base of every config section: unknown keys are rejected, numbers stay numbers."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict

__all__ = ["Section"]


class Section(BaseModel):
    """Base class of all config sections.

    Unknown keys are errors (a misspelt key must never be silently ignored) and fields are
    validated on assignment so that a programmatic edit is checked like a YAML value.
    """

    model_config = ConfigDict(extra="forbid", validate_assignment=True, frozen=False)
