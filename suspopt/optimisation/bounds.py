"""Designs against the bounds of their search.

An optimum whose design variable lies at the variable's bound was stopped by the bound, not
by the objectives: the best design may lie beyond it, and the bound is the engineer's to
question (a wider range, or a limit the design must keep). This is our addition; the thesis
reports the optimum's values without saying which lie at a bound.

A value is *at* a bound when it lies within :data:`AT_BOUND` of the variable's search range
of it: the range of the value, or of its ``log10`` for a variable with ``scale: log`` (the
space the optimiser searches, :class:`~suspopt.optimisation.Problem`). An optimiser rarely lands
on a bound exactly (a GA's offspring approach it), so 1 % of the range counts as at it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..config.optimise import DesignVariable

if TYPE_CHECKING:
    from ..choosing.picks import DesignTable

__all__ = ["AT_BOUND", "at_bounds", "bounds_note", "table_bounds"]

#: The share of a design variable's search range within which a value is at the bound.
AT_BOUND = 0.01


def at_bounds(
    variables: Sequence[DesignVariable], X: np.ndarray, share: float = AT_BOUND
) -> np.ndarray:
    """(N, n) int8 of the designs ``X (N, n)`` (physical values of ``variables``, in their
    order): -1 where a value lies within ``share`` of its search range of the lower bound
    (or below it), +1 of the upper bound (or above it), 0 between. NaN values are 0."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    if X.shape[1:] != (len(variables),):
        raise ValueError(f"X: {X.shape[1:] or 'no'} columns for {len(variables)} design variables")
    log = np.array([v.scale == "log" for v in variables], dtype=bool)
    lower = np.array([v.lower for v in variables], dtype=float)
    upper = np.array([v.upper for v in variables], dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        values = np.where(log, np.log10(np.where(log, X, 1.0)), X)
        lower = np.where(log, np.log10(np.where(log, lower, 1.0)), lower)
        upper = np.where(log, np.log10(np.where(log, upper, 1.0)), upper)
        position = (values - lower) / (upper - lower)
    out = np.zeros(X.shape, dtype=np.int8)
    out[position <= share] = -1
    out[position >= 1.0 - share] = 1
    return out


def bounds_note(
    names: Sequence[str],
    variables: Sequence[DesignVariable],
    X: np.ndarray,
    share: float = AT_BOUND,
) -> str | None:
    """One line naming the design variables ``names`` that lie at a bound in the designs
    ``X (N, n)`` (:func:`at_bounds`), with how many designs where there are several; None
    when none does."""
    where = at_bounds(variables, X, share)
    N = len(where)
    found = []
    for j, name in enumerate(names):
        for side, label in ((-1, "lower"), (1, "upper")):
            count = int((where[:, j] == side).sum())
            if count:
                found.append(f"{name} {label}" + (f" in {count} of {N} designs" if N > 1 else ""))
    if not found:
        return None
    beyond = "the optimum may lie beyond" if N == 1 else "the front may reach further"
    return (
        f"at a bound (within {100 * share:g} % of its range): {', '.join(found)}; {beyond}:"
        f" widen the bounds in design_variables if the design allows"
    )


def table_bounds(table: DesignTable) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(lower (n,), upper (n,), at (N, n))`` of the design table of a result file
    (:func:`suspopt.choosing.picks.read_table`): each variable's search range from the configs the
    file stored (the widest over the sets of a kesort file; NaN for a variable none of them
    has), and :func:`at_bounds` of each design against its own config's variables (0 where
    its config lacks the variable). ConfigError when a stored config does not load."""
    from ..config.loader import load_config_text

    n = len(table.var_names)
    lower, upper = np.full(n, np.nan), np.full(n, np.nan)
    at = np.zeros(table.X.shape, dtype=np.int8)
    for c, text in enumerate(table.configs):
        cfg = load_config_text(text, table.path.with_name(f"{table.path.name}:config"))
        mine = {v.label: v for v in cfg.design_variables}
        columns = np.array([j for j, name in enumerate(table.var_names) if name in mine], int)
        if not columns.size:
            continue
        variables = [mine[table.var_names[j]] for j in columns]
        lower[columns] = np.fmin(lower[columns], [v.lower for v in variables])
        upper[columns] = np.fmax(upper[columns], [v.upper for v in variables])
        rows = np.flatnonzero(table.config_of == c)
        at[np.ix_(rows, columns)] = at_bounds(variables, table.X[np.ix_(rows, columns)])
    return lower, upper, at
