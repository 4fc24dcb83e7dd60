"""k-optimality and k-ε optimality (Sec 6.1.1, Eq 6.10-6.12), and the Pareto-theory picks
(Fig. 8.21): choosing one design from a Pareto set. Every objective is minimised.

**Levels (Eq 6.10).** For solution ``i`` of a set of ``N`` solutions with ``m`` objectives,

    k_i = min over j != i of  sum_l Γ(Δ_l(i, j))  - 1,      Δ_l(i, j) = f_l(i) - f_l(j).

k-optimality (Das) takes the crisp merit ``Γ(Δ) = 1`` if ``Δ <= 0``, else 0 (Eq 6.11): the sum
counts the objectives in which ``i`` is not worse than ``j``, and the level is that count for
the least favourable ``j``, minus 1. So ``k = m - 1`` for a solution better than every other in
every objective (the utopia point), ``k >= 0`` for a Pareto-optimal solution and ``k = -1``
where some solution is better in every objective. k-ε optimality (Gobbi et al.) softens the
merit with an indifference threshold ``ε_l`` per objective (Eq 6.12 as mended, slip:
docs/thesis-slips.md#eq-612): ``Γ = 1`` if ``Δ <= 0``, ``1 - Δ/ε`` if ``0 < Δ < ε``,
``0`` if ``Δ >= ε``. The
level becomes continuous in ``[-1, m - 1]``; it is never below the k-optimality level and
tends to it as ``ε -> 0`` (``ε_l = 0`` *is* Eq 6.11 for that objective).

**Choice.** The thesis takes the solution of the highest level and tunes ε until only one
solution holds it (Sec 6.2.2, 7.2.2). :func:`kesort` reports every solution within ``tie_tol``
of the top level as ``ties`` and chooses the first of them.

**Level convention.** Eq 6.10 subtracts 1, so the top level is ``m - 1``. The thesis's text
and figures read the levels one higher: with six objectives its optima are "above level five
but below six" (Sec 7.3) and "of level five, i.e. it dominates five out of six objectives"
(Sec 6.3), which only fits ``min sum Γ`` without the ``- 1``. suspopt keeps Eq 6.10; add 1 to
compare with the thesis's figures.

**Normalisation and ε.** Each objective is normalised over the set, by its maximum
(``NF = F / max F``, Eq 7.12; needs a positive maximum) or min-max
(``NF = (F - min F) / (max F - min F)``). The threshold is either absolute (``eps``, in the
objectives' own units, one value or one per objective) or ``ε_l = P · max NF_l`` (Eq 6.19,
7.13). Γ depends on ``Δ_l / ε_l`` only, so an absolute ε gives the same levels whatever the
normalisation; with ``P`` the normalisation sets the scale: by the maximum (the thesis's
choice) ε is ``P`` times each objective's largest value, min-max makes it ``P`` times its
range over the set (for an objective whose values sit in a narrow band far from 0). Either way
the levels are invariant to a change of an objective's unit. ``P="auto"`` takes the smallest
``P`` of a grid over ``P_range`` that yields a single best solution: the thesis chose ``P`` by
hand for this (0.55-0.65 in Ch. 6, 0.10-0.20 in Ch. 7).

**Cost.** The pairwise comparison is ``N² m`` work, done in row blocks of about
``chunk_bytes`` of memory, so 10,000 solutions × 10 objectives take about a second in less
than 64 MB (``benchmarks/bench_kesort.py``). ``P="auto"`` sorts the whole set at the first P
of its grid; at each next P it only asks whether one solution leads, from upper bounds of
every level (the minimum over a few hundred columns) and the exact levels of the solutions
whose bounds reach the top, then sorts the P it settles on whole: the same P and levels as
a whole sort at every P, with a few N pairs per P instead of N² where no P breaks a tie.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np

__all__ = [
    "kesort",
    "KEpsilonSort",
    "k_eps_levels",
    "normalise_objectives",
    "pareto_picks",
    "check_options",
    "NORMALISATIONS",
]

#: Normalisations of the objectives before ε = P · max NF (Eq 7.12 and min-max).
NORMALISATIONS = ("max", "minmax")
#: Most values of P that ``P="auto"`` may try (``P_range`` and ``P_step`` give the grid; each
#: value is one sort of the set): a hundred times the default grid's 100.
MAX_P_GRID = 10_000

_CHUNK_BYTES = 64 * 2**20


@dataclass(frozen=True)
class KEpsilonSort:
    """Result of :func:`kesort` for ``N`` solutions and ``m`` objectives.

    ``k (N,)``: the k-optimality levels (Eq 6.10 with Eq 6.11), integers from -1 to m - 1,
    computed when first read (one more pass over the pairs); ``unique``: whether one solution
    alone holds the highest k-ε level.

    Attributes
    ----------
    k_eps : ndarray
        k-ε levels ``(N,)`` [-] (Eq 6.10 with Eq 6.12).
    chosen : int
        Index of the solution of the highest k-ε level (the first of ``ties``).
    ties : ndarray
        Indices of every solution within ``tie_tol`` of that level.
    epsilon : ndarray
        The thresholds ``(m,)`` in the objectives' units.
    P : float or None
        The factor [-] of Eq 6.19/7.13 (None for an absolute ``eps``).
    P_auto : bool
        Whether ``P`` was searched.
    normalisation : str
        ``max`` or ``minmax``.
    NF : ndarray
        The normalised objectives ``(N, m)`` [-].
    names : tuple of str
        The objectives' names.
    """

    k_eps: np.ndarray
    chosen: int
    ties: np.ndarray
    epsilon: np.ndarray
    P: float | None
    P_auto: bool
    normalisation: str
    NF: np.ndarray
    names: tuple[str, ...]

    @cached_property
    def k(self) -> np.ndarray:
        # the normalisation keeps each objective's order, so the crisp levels are F's own
        return k_eps_levels(self.NF, 0.0)

    @property
    def unique(self) -> bool:
        """True when one solution alone holds the highest level."""
        return len(self.ties) == 1


def _objectives(F) -> np.ndarray:
    F = np.array(F, dtype=float)
    if F.ndim != 2 or F.shape[0] == 0 or F.shape[1] == 0:
        raise ValueError(
            f"F must be (N solutions, m objectives) with N, m >= 1; got shape {F.shape}"
        )
    bad = np.argwhere(~np.isfinite(F))
    if len(bad):
        i, j = bad[0]
        raise ValueError(
            f"F[{i}, {j}] is {F[i, j]}: objectives must be finite (drop failed designs first)"
        )
    return F


def _names(names: Sequence[str] | None, m: int) -> tuple[str, ...]:
    if names is None:
        return tuple(f"f{j + 1}" for j in range(m))
    from ..files import listed

    names = listed(names)  # ("RC": one name, not two)
    if len(names) != m:
        raise ValueError(f"{len(names)} names for {m} objectives")
    return tuple(names)


def normalise_objectives(
    F, how: str = "max", names: Sequence[str] | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(NF, offset, scale)`` with ``NF = (F - offset) / scale`` column by column.

    ``max``: offset 0, scale ``max F`` (Eq 7.12); a column whose maximum is not positive is an
    error (dividing by it would reverse or break the order). ``minmax``: offset ``min F``, scale
    ``max F - min F`` (1 for a constant column, which becomes 0). A column whose normalised
    values leave the floating-point range (``F`` spanning more than about 1e308 times its
    scale, as only a damaged file holds) is an error naming the objective.
    """
    F = _objectives(F)
    names = _names(names, F.shape[1])
    with np.errstate(over="ignore", invalid="ignore"):
        if how == "max":
            scale = F.max(axis=0)
            for j in np.flatnonzero(scale <= 0):
                raise ValueError(
                    f"objective {names[j]} has maximum {scale[j]:g} <= 0 over the "
                    f"set: normalising by the maximum (Eq 7.12) needs a positive "
                    f"one; use min-max normalisation"
                )
            offset = np.zeros_like(scale)
        elif how == "minmax":
            offset = F.min(axis=0)
            spread = F.max(axis=0) - offset
            scale = np.where(spread > 0, spread, 1.0)
        else:
            raise ValueError(
                f"unknown normalisation {how!r}; use one of {', '.join(NORMALISATIONS)}"
            )
        NF = (F - offset) / scale
    _in_range(
        lambda j: (
            f"objective {names[j]} spans {F[:, j].min():g} to {F[:, j].max():g}: "
            f"normalised ({how}) it leaves the floating-point range"
        ),
        NF,
        scale,
    )
    return NF, offset, scale


def _in_range(say, *columns: np.ndarray) -> None:
    """ValueError ``say(j)`` for the first objective ``j`` (the last axis of each array) with
    a value that is not finite in any of ``columns``."""
    finite = np.logical_and.reduce(
        [np.isfinite(a).reshape(-1, a.shape[-1]).all(axis=0) for a in columns]
    )
    for j in np.flatnonzero(~finite):
        raise ValueError(say(j))


def k_eps_levels(F, eps, chunk_bytes: int = _CHUNK_BYTES) -> np.ndarray:
    """k-ε levels (Eq 6.10, Γ of Eq 6.12 as mended, slip: docs/thesis-slips.md#eq-612) of the
    rows of ``F (N, m)``.

    ``eps``: one threshold or one per objective, in the units of ``F``; ``eps_l = 0`` gives the
    crisp merit of Eq 6.11 for that objective, so ``eps = 0`` returns the k-optimality levels.
    A single solution (no other to compare with) gets the top level ``m - 1``. The comparison
    runs in blocks of rows of about ``chunk_bytes`` bytes; no Python loop over solutions.
    """
    F = _objectives(F)
    N, m = F.shape
    eps = _per_objective(eps, m)
    if (eps < 0).any() or not np.isfinite(eps).all():
        raise ValueError(f"eps must be finite and >= 0; got {eps.tolist()}")
    if N == 1:
        return np.full(1, m - 1.0)
    return _Merits(F, eps).levels(np.arange(N), chunk_bytes)


class _Merits:
    """The pairwise sums ``Σ_l Γ(Δ_l(i, j))`` of Eq 6.10 for the rows ``F (N, m)`` and the
    thresholds ``eps (m,)``, for any rows against any columns: each pair's sum is computed
    by the same operations whatever the block it is in, so that levels computed for some
    rows alone, or bounded by some columns, are the bits of the whole comparison."""

    def __init__(self, F: np.ndarray, eps: np.ndarray):
        self.F, self.eps, self.N = F, eps, F.shape[0]
        self.soft = eps > 0
        # Γ = clip(1 - Δ/ε, 0, 1) = clip((1 + f_j/ε) - f_i/ε, 0, 1): one subtraction per
        # pair. That form rounds Γ by about |f/ε| 2^-53 (the 1 vanishes beside an f/ε of
        # 2^53, making a tie Γ = 0): a column where |f/ε| exceeds 2^16 (Γ within 2^-37; an ε
        # far below the objective's values) takes 1 - Δ/ε itself, where Δ of two values
        # closer than ε is exact and an overflow to ±inf is the right limit (Γ = 0 or 1)
        self.scaled = F.copy()
        with np.errstate(over="ignore"):
            self.scaled[:, self.soft] /= eps[self.soft]
        self.direct = self.soft & ~(np.abs(self.scaled) <= 2.0**16).all(axis=0)
        self.shifted = self.scaled + 1.0

    def sums(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """``(len(rows), len(cols))``: the sum of merits of each row against each column
        (``cols`` ascending), a row against itself ``inf`` (not compared with itself)."""
        F, eps = self.F, self.eps
        S, T = np.zeros((rows.size, cols.size)), np.empty((rows.size, cols.size))
        for j in range(F.shape[1]):
            if self.direct[j]:
                with np.errstate(over="ignore"):
                    np.subtract(F[rows, j, None], F[None, cols, j], out=T)
                    np.divide(T, eps[j], out=T)
                np.subtract(1.0, T, out=T)
                np.clip(T, 0.0, 1.0, out=T)
            elif self.soft[j]:
                np.subtract(self.shifted[None, cols, j], self.scaled[rows, j, None], out=T)
                np.clip(T, 0.0, 1.0, out=T)
            else:
                np.less_equal(F[rows, j, None], F[None, cols, j], out=T)
            S += T
        at = np.minimum(np.searchsorted(cols, rows), cols.size - 1)  # (cols is sorted)
        itself = np.flatnonzero(cols[at] == rows)
        S[itself, at[itself]] = np.inf
        return S

    def levels(self, rows: np.ndarray, chunk_bytes: int, cols: np.ndarray | None = None):
        """The levels of ``rows`` against every solution (or, against ``cols`` alone, an
        upper bound of them: the minimum over fewer pairs), in blocks of about
        ``chunk_bytes``."""
        cols = np.arange(self.N) if cols is None else cols
        width = int(max(1, min(rows.size, chunk_bytes // (24 * max(cols.size, 1)))))
        out = np.empty(rows.size)
        for start in range(0, rows.size, width):
            out[start : start + width] = self.sums(rows[start : start + width], cols).min(1) - 1.0
        return out

    def unique_top(self, tie_tol: float, probe: np.ndarray, chunk_bytes: int):
        """Whether one solution alone holds the top level (within ``tie_tol``), and the
        rows whose levels came within it, without the levels of every solution: bounds
        against the ``probe`` rows, then the exact levels of the solutions in the order of
        their bounds until no bound reaches the top found less ``tie_tol``, or none can
        rise above it and two hold it. The answer is the whole comparison's (a solution
        not compared exactly has a level at most its bound); ``near`` may then hold only
        some of the tied rows."""
        bound = self.levels(np.arange(self.N), chunk_bytes, probe)
        order = np.argsort(-bound, kind="stable")
        most = int(max(1, chunk_bytes // (24 * self.N)))
        done, exact, top, batch = 0, np.empty(0), -np.inf, 16
        while done < self.N and bound[order[done]] >= top - tie_tol:
            if bound[order[done]] <= top and np.sum(exact >= top - tie_tol) > 1:
                break  # (none left can rise above the top, and two hold it already)
            rows = order[done : done + min(batch, most)]
            exact = np.concatenate([exact, self.levels(rows, chunk_bytes)])
            top, done, batch = max(top, float(exact.max())), done + rows.size, 2 * batch
        near = order[:done][exact >= top - tie_tol]
        return near.size == 1, near


def _ties(levels: np.ndarray, tie_tol: float) -> np.ndarray:
    return np.flatnonzero(levels >= levels.max() - tie_tol)


def check_options(
    eps=None,
    P: float | str | None = None,
    normalise: str = "max",
    P_range: tuple[float, float] = (0.01, 1.0),
    P_step: float = 0.01,
    tie_tol: float = 1e-9,
) -> None:
    """Raise ValueError for options :func:`kesort` cannot use (before any work is done)."""
    if not 0 <= _number(tie_tol) < math.inf:  # (NaN left no tie: an IndexError)
        raise ValueError(f"tie_tol must be finite and >= 0; got {tie_tol!r}")
    if eps is not None and P is not None:
        raise ValueError("give either eps (absolute thresholds) or P (eps = P max NF), not both")
    if eps is not None:
        values = np.asarray(eps, dtype=float)
        if values.ndim > 1 or (values < 0).any() or not np.isfinite(values).all():
            raise ValueError(
                f"eps must be one value or one per objective, finite and >= 0; "
                f"got {values.tolist()}"
            )
    elif P is not None and P != "auto":
        if not 0 < _number(P) < np.inf:
            raise ValueError(f"P must be finite and > 0, or 'auto'; got {P!r}")
    else:
        try:
            lo, hi = (float(p) for p in P_range)
            P_step = float(P_step)
        except (TypeError, ValueError):
            raise ValueError(
                f"P_range must be two numbers (low, high) and P_step one; got {P_range!r}, "
                f"{P_step!r}"
            ) from None
        if not (0 < lo <= hi < np.inf and 0 < P_step < np.inf):
            raise ValueError(
                f"P_range must satisfy 0 < low <= high and P_step > 0, all finite; got "
                f"{tuple(P_range)}, {P_step}"
            )
        points = (hi - lo) / P_step + 1
        if not points <= MAX_P_GRID:
            raise ValueError(
                f"P_range {tuple(P_range)} with P_step {P_step} is a grid of {points:.3g} "
                f"values of P; at most {MAX_P_GRID} (each is one sort)"
            )
    if normalise not in NORMALISATIONS:
        raise ValueError(
            f"unknown normalisation {normalise!r}; use one of {', '.join(NORMALISATIONS)}"
        )


def _number(value) -> float:
    """``value`` as a float, NaN when it is not a number (refused by the range checks)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def kesort(
    F,
    eps=None,
    *,
    P: float | str | None = None,
    normalise: str = "max",
    names: Sequence[str] | None = None,
    P_range: tuple[float, float] = (0.01, 1.0),
    P_step: float = 0.01,
    tie_tol: float = 1e-9,
    chunk_bytes: int = _CHUNK_BYTES,
) -> KEpsilonSort:
    """Sort the solutions ``F (N, m)`` (minimised) by k-ε optimality and choose one.

    Give either ``eps`` (absolute thresholds in the units of ``F``: one value or ``(m,)``) or
    ``P``: a number for ``ε_l = P · max NF_l`` (Eq 6.19, 7.13), or ``"auto"`` (the default when
    neither is given) for the smallest ``P`` on the grid ``P_range[0], P_range[0] + P_step,
    ... <= P_range[1]`` that leaves one solution alone at the top level; if none does, the
    largest ``P`` is kept and ``unique`` is False. ``normalise``: ``max`` (Eq 7.12) or
    ``minmax`` (see the module docstring). Returns a :class:`KEpsilonSort`.

    Parameters
    ----------
    F : array_like
        Objective values ``(N, m)`` of the solutions, each in its own unit (minimised).
    eps : float or array_like, optional
        Absolute thresholds ``ε`` in the units of ``F``, one value or ``(m,)``.
    P : float or "auto", optional
        Threshold as a share [-] of each objective's largest normalised value.
    normalise : {"max", "minmax"}
        Normalisation of ``F`` before the thresholds.
    names : sequence of str, optional
        The objectives' names (default ``f1``, ``f2``, ...).
    P_range : (float, float)
        The range [-] searched for ``P = "auto"``.
    P_step : float
        Step [-] of that search.
    tie_tol : float
        Relative tolerance [-] below which two k-ε levels count as a tie.
    chunk_bytes : int
        Memory [bytes] one block of the pairwise comparison may take (larger sets are
        compared in blocks).

    Returns
    -------
    KEpsilonSort
        The k-ε level of each solution and the chosen one.
    """
    check_options(eps, P, normalise, P_range, P_step, tie_tol)
    F = _objectives(F)
    names = _names(names, F.shape[1])
    NF, _, scale = normalise_objectives(F, normalise, names)
    if eps is not None:
        eps_nf = _eps_normalised(eps, scale, names, normalise)
        levels, P_value, auto = k_eps_levels(NF, eps_nf, chunk_bytes), None, False
    elif P is None or P == "auto":
        P_value, eps_nf, levels = _auto_P(NF, P_range, P_step, tie_tol, chunk_bytes)
        auto = True
    else:
        P_value = float(P)
        eps_nf = P_value * NF.max(axis=0)
        levels, auto = k_eps_levels(NF, eps_nf, chunk_bytes), False
    ties = _ties(levels, tie_tol)
    return KEpsilonSort(
        k_eps=levels,
        chosen=int(ties[0]),
        ties=ties,
        epsilon=_eps_in_units(eps_nf, scale, names),
        P=P_value,
        P_auto=auto,
        normalisation=normalise,
        NF=NF,
        names=names,
    )


def _per_objective(eps, m: int, names: tuple[str, ...] = ()) -> np.ndarray:
    """``eps`` as ``(m,)`` thresholds, one per objective; ValueError unless it is one value
    or ``m`` of them (a numpy broadcasting message before)."""
    values = np.asarray(eps, dtype=float)
    if values.size not in (1, m) or values.ndim > 1:
        listed = f" ({', '.join(names)})" if names else ""
        raise ValueError(
            f"eps gives {values.size} values for {m} objectives{listed}; give one value, "
            "or one per objective"
        )
    return np.broadcast_to(values.reshape(-1), (m,))


def _eps_normalised(eps, scale: np.ndarray, names: tuple[str, ...], how: str) -> np.ndarray:
    """The absolute thresholds ``eps`` in the units of the normalised objectives (``eps /
    scale``); ValueError naming the objective where that leaves the floating-point range."""
    given = _per_objective(eps, scale.size, names)
    with np.errstate(over="ignore"):
        eps_nf = given / scale
    _in_range(
        lambda j: (
            f"eps {given[j]:g} of objective {names[j]} is beyond the floating-point "
            f"range in units of its scale {scale[j]:g} ({how} normalisation)"
        ),
        eps_nf,
    )
    return eps_nf


def _eps_in_units(eps_nf, scale: np.ndarray, names: tuple[str, ...]) -> np.ndarray:
    """The thresholds ``eps_nf`` of the normalised objectives in the objectives' own units;
    ValueError naming the objective where that leaves the floating-point range (a ``P`` of
    10^291 on an objective of 10^17)."""
    eps_nf = np.broadcast_to(eps_nf, scale.shape)
    with np.errstate(over="ignore"):
        epsilon = eps_nf * scale
    _in_range(
        lambda j: (
            f"objective {names[j]}: a threshold of {eps_nf[j]:g} times its scale "
            f"{scale[j]:g} is beyond the floating-point range"
        ),
        epsilon,
    )
    return epsilon


def _auto_P(NF: np.ndarray, P_range, P_step: float, tie_tol: float, chunk_bytes: int):
    """The smallest P of the grid with a single best solution: (P, ε in NF units, levels).
    The first P sorts the whole set; the next ones ask :meth:`_Merits.unique_top` alone
    (a few N pairs instead of N²; a tie no P breaks, such as a design pooled twice,
    made every value of the grid a whole sort), and the P found is sorted whole."""
    lo, hi = (float(p) for p in P_range)
    steps = np.arange(int(np.floor((hi - lo) / P_step + 1e-9)) + 1)
    # 12 significant digits: 0.15, not 0.15000000000000002 (and 1e-320 stays 1e-320)
    grid = [float(f"{value:.12g}") for value in lo + P_step * steps]
    peak = NF.max(axis=0)
    P_value = grid[0]
    levels = k_eps_levels(NF, P_value * peak, chunk_bytes)
    near = _ties(levels, tie_tol)
    if len(near) == 1 or len(NF) == 1 or len(grid) == 1:
        return P_value, P_value * peak, levels
    spread = np.linspace(
        0, len(NF) - 1, min(len(NF), max(16, min(256, int(2 * len(NF) ** 0.5))))
    ).astype(int)
    for P_value in grid[1:]:
        probe = np.unique(np.concatenate([near[:32], NF.argmin(axis=0), spread]))
        merits = _Merits(NF, _per_objective(P_value * peak, NF.shape[1]))
        unique, near = merits.unique_top(tie_tol, probe, chunk_bytes)
        if unique:
            break
    return float(P_value), P_value * peak, k_eps_levels(NF, P_value * peak, chunk_bytes)


def pareto_picks(F, names: Sequence[str] | None = None) -> dict[str, int]:
    """The Pareto-theory picks of Fig. 8.21: indices into ``F (N, m)`` (minimised).

    ``best_<name>`` for each objective (names default ``f1``, ``f2``, ...): the edge of the
    front where that objective is lowest, i.e. the optimum of the single-objective problem
    (ties broken by the lowest sum of the other objectives after min-max normalisation, so
    the edge is itself non-dominated). ``knee``: the best compromise, Fig. 8.21's "Mid"
    solution, taken as the solution nearest (Euclidean) to the utopia point once each
    objective is scaled from the ideal point (the lowest values) to the nadir point estimated
    from the edges (the payoff table: the worst value of each objective among the
    ``best_<name>`` solutions), ``argmin_i ||(F_i - ideal) / (nadir - ideal)||``.

    Why this knee: Sec 8.4 picks "the mid solution of the Pareto front [that] corresponds to
    the best compromise of the two objectives" without a formula. The distance to the utopia
    point (compromise programming) reads the same for any ``m``, unlike the farthest point from
    the line joining the two edges, which exists for two objectives only; the scaling makes it
    independent of the objectives' units, and taking the nadir from the edges keeps dominated
    designs far off the front (a pooled or re-simulated set) from moving it. It is always
    non-dominated (a solution that dominates another is nearer the utopia point), and on a
    convex two-objective front it lands in the middle, where Fig. 8.21 puts "Mid".

    Parameters
    ----------
    F : array_like
        Objective values ``(N, m)`` (minimised), each in its own unit.
    names : sequence of str, optional
        The objectives' names (default ``f1``, ``f2``, ...).

    Returns
    -------
    dict of str to int
        Row of ``F`` for ``best_<name>`` of each objective and for ``knee``.
    """
    F = _objectives(F)
    names = _names(names, F.shape[1])
    NF, _, _ = normalise_objectives(F, "minmax", names)
    total = NF.sum(axis=1)
    picks = {
        f"best_{name}": int(np.lexsort((total - NF[:, j], F[:, j]))[0])
        for j, name in enumerate(names)
    }
    ideal = F.min(axis=0)
    span = F[list(picks.values())].max(axis=0) - ideal
    with np.errstate(over="ignore"):  # a design beyond the range's reach is infinitely far
        scaled = (F - ideal) / np.where(span > 0, span, 1.0)
        picks["knee"] = int(np.argmin(np.einsum("ij,ij->i", scaled, scaled)))
    return picks
