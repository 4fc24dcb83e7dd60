"""How the analyses' reports show their numbers: a change that cannot be computed, a stored
design that failed.

A change (:func:`suspopt.analyse.relative_change`) is NaN where it cannot be computed: the
value it is measured from is 0, or a failed design's, or the change is beyond the
floating-point range (a damaged file's 1e-308). A table shows it as :data:`NOT_COMPUTED`
(``n/a``) and the report adds :data:`NOT_COMPUTED_NOTE`, never ``-inf %`` or ``nan %``. A
stored design that failed (the file holds the optimiser's penalty values for it, 1e10 or
more, or its re-simulation failed) shows ``failed`` for its stored values, and its changes
are not computed (:func:`stored_reference`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..optimisation.problem import PENALTY

__all__ = [
    "NOT_COMPUTED",
    "NOT_COMPUTED_NOTE",
    "percent",
    "change_span",
    "stored_reference",
    "stored_failed",
    "stored_cells",
    "failed_stored_note",
]


#: What a table shows for a change that cannot be computed
#: (:func:`suspopt.analyse.relative_change`).
NOT_COMPUTED = "n/a"
#: The note of a report that shows :data:`NOT_COMPUTED`.
NOT_COMPUTED_NOTE = (
    f"{NOT_COMPUTED}: a change that cannot be computed (the value it is measured from is 0 or "
    "a failed design's, or the change is beyond the floating-point range)"
)


def percent(value, digits: str = ".1f", suffix: str = " %") -> str:
    """The change ``value`` [%] as a table shows it: signed, to ``digits`` (``+12.3 %``),
    with three significant digits from 10^6 % on (``+1.5e+307 %``, not 300 digits), and
    :data:`NOT_COMPUTED` (no ``suffix``) where it is not a finite number."""
    value = float(value)
    if not math.isfinite(value):
        return NOT_COMPUTED
    if abs(value) >= 1e6:
        return f"{value:+.3g}{suffix}"
    return f"{value:+{digits}}{suffix}"


def change_span(name: str, changes) -> str:
    """``name -12.1 to +3.0 % (median -4.2 %)``: the range and median of ``changes`` [%]
    that could be computed, and how many could not (:data:`NOT_COMPUTED`)."""
    changes = np.asarray(changes, dtype=float).ravel()
    finite = changes[np.isfinite(changes)]
    missing = changes.size - finite.size
    if not finite.size:
        return f"{name} {NOT_COMPUTED}"
    with np.errstate(over="ignore"):  # (the mean of two middle values of 1e308: inf, n/a)
        median = np.median(finite)
    text = (
        f"{name} {percent(finite.min(), suffix='')} to {percent(finite.max())} "
        f"(median {percent(median)})"
    )
    return text + (f", {NOT_COMPUTED} for {missing}" if missing else "")


def stored_reference(F, stored) -> np.ndarray:
    """(N, m + s) what the changes of an analysis of a front are measured from: the file's
    main objectives ``F (N, m)``, then the supplementary ones of ``stored`` (the front's
    designs re-simulated under the stored config: :class:`~suspopt.choosing.selection.DesignSet`);
    NaN in the row of a design that failed (the file holds the optimiser's penalty values
    for it, or its re-simulation failed), whose change cannot be computed."""
    reference = np.hstack([F, stored.F[:, F.shape[1] :]])
    reference[stored_failed(F, stored)] = np.nan
    return reference


def stored_failed(F, stored) -> np.ndarray:
    """(N,) which designs of a stored front failed (:func:`stored_reference`)."""
    return np.asarray(stored.failed, dtype=bool) | (np.asarray(F) >= PENALTY).any(axis=1)


def stored_cells(values, failed: bool) -> list[str]:
    """The cells of a stored design's objectives ``values``: "failed" for each where the
    design failed (the file holds the optimiser's penalty values for it)."""
    return ["failed" if failed else f"{f:.4g}" for f in values]


def failed_stored_note(failed: np.ndarray, ids: Sequence[str] | None = None) -> str:
    """The note of a report of a front some of whose stored designs ``failed`` (N,), named
    by their ``ids`` (:mod:`suspopt.design_ids`; default their row numbers)."""
    rows = np.flatnonzero(failed)
    name = (lambda k: str(int(k))) if ids is None else (lambda k: ids[int(k)])
    shown = ", ".join(name(k) for k in rows[:10]) + (", ..." if len(rows) > 10 else "")
    return (
        f"{len(rows)} of {failed.size} stored designs failed (design {shown}: the file holds "
        f"the optimiser's penalty values, or their re-simulation failed); their changes "
        f"cannot be computed"
    )
