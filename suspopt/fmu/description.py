"""What the FMU's code is generated from: the :class:`Description` of one design, filled by
:func:`suspopt.fmu.model.describe` and :func:`suspopt.fmu.outputs.add_outputs`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["Description", "RECORDS"]

#: Record kinds of the controller's signals (:meth:`SemiActiveController.published`).
RECORDS = ("damper_state", "control_condition", "control_threshold")


@dataclass
class Description:
    """The C-ready description of one design (module docstring). ``info`` holds what the
    model description and the outputs need and the probes do not compare (names, units)."""

    structure: dict[str, Any] = field(default_factory=dict)
    entries: dict[str, np.ndarray] = field(default_factory=dict)
    info: dict[str, Any] = field(default_factory=dict)

    def put(self, name: str, values) -> None:
        self.entries[name] = np.atleast_1d(np.asarray(values, dtype=float)).ravel().copy()

    def same_structure(self, other: Description) -> bool:
        """Whether ``other`` has this structure and entries of the same sizes."""
        if self.structure.keys() != other.structure.keys():
            return False
        for key, value in self.structure.items():
            if not _equal(value, other.structure[key]):
                return False
        return {k: v.size for k, v in self.entries.items()} == {
            k: v.size for k, v in other.entries.items()
        }


def _equal(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(np.asarray(a), np.asarray(b))
    return a == b
