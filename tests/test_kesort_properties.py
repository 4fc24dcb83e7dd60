"""Property tests of the k-ε sort over any finite objectives (hypothesis).

Objective values anywhere in the floating-point range (subnormals and ±1.8e308 included), any
threshold: the levels stay in ``[-1, m - 1]``, never below the crisp k-optimality levels
(Eq 6.10-6.12), and no floating-point overflow, invalid operation or division by zero
happens on the way (numpy would print each as a warning line on the command line). Where
the normalisation cannot represent a set, the sort refuses it with a ValueError naming the
objective. The examples are derandomised: the same on every run.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from suspopt.choosing.kepsilon import k_eps_levels, kesort, pareto_picks

FINITE = st.floats(allow_nan=False, allow_infinity=False)
#: values from a damaged file, and everyday ones, mixed
VALUES = FINITE | st.floats(-10.0, 10.0)
SETS = st.tuples(st.integers(1, 12), st.integers(1, 6)).flatmap(
    lambda shape: arrays(np.float64, shape, elements=VALUES)
)
THRESHOLDS = st.just(0.0) | st.floats(0.0, 10.0) | FINITE.map(abs)
RAISE = {"over": "raise", "invalid": "raise", "divide": "raise"}
EXAMPLES = settings(max_examples=300, deadline=None, derandomize=True, database=None)


@EXAMPLES
@given(F=SETS, eps=THRESHOLDS)
def test_levels_lie_between_minus_one_and_m_minus_one_above_the_crisp_ones(F, eps):
    m = F.shape[1]
    with np.errstate(**RAISE):
        levels = k_eps_levels(F, eps)
        crisp = k_eps_levels(F, 0.0)
    assert np.isfinite(levels).all()
    assert (levels >= -1.0).all() and (levels <= m - 1).all()
    assert (levels >= crisp - 1e-9).all()  # (kesort's tie tolerance)


@EXAMPLES
@given(
    F=SETS,
    how=st.sampled_from(["max", "minmax"]),
    P=st.none() | st.floats(1e-320, 1e308),
)
def test_the_sort_chooses_a_design_or_names_the_objective_it_cannot_normalise(F, how, P):
    with np.errstate(**RAISE):
        try:
            result = kesort(F, P=P, normalise=how)
        except ValueError as exc:
            assert str(exc).startswith("objective f"), exc
            return
    assert np.isfinite(result.k_eps).all() and np.isfinite(result.NF).all()
    assert 0 <= result.chosen < len(F) and result.chosen in result.ties


@EXAMPLES
@given(F=SETS)
def test_the_picks_are_rows_of_the_set_or_the_objective_is_named(F):
    with np.errstate(**RAISE):
        try:
            picks = pareto_picks(F)
        except ValueError as exc:
            assert str(exc).startswith("objective f"), exc
            return
    assert set(picks) == {f"best_f{j + 1}" for j in range(F.shape[1])} | {"knee"}
    assert all(0 <= row < len(F) for row in picks.values())
    for j in range(F.shape[1]):  # each edge is a best value of its objective
        assert F[picks[f"best_f{j + 1}"], j] == F[:, j].min()


#: sets of 17-80 designs (more than the bounds' probe spans) with coarse values: ties
#: and designs repeated, so that P = "auto" often runs through its grid
TIED = st.tuples(st.integers(17, 80), st.integers(1, 4)).flatmap(
    lambda shape: arrays(np.float64, shape, elements=st.sampled_from([0.5, 1.0, 1.5, 2.0, 4.0]))
)


@settings(max_examples=150, deadline=None, derandomize=True, database=None)
@given(F=TIED, how=st.sampled_from(["max", "minmax"]), tie_tol=st.sampled_from([0.0, 1e-9, 0.05]))
def test_auto_P_is_the_first_P_whose_whole_sort_has_one_leader(F, how, tie_tol):
    """The bounds and partial sorts of ``P = "auto"`` give what sorting the whole set at
    every P of the grid gives: the same P, the same levels, bit for bit."""
    try:
        result = kesort(F, P="auto", normalise=how, tie_tol=tie_tol, P_step=0.05)
    except ValueError as exc:  # (a constant objective under min-max)
        assert str(exc).startswith("objective f"), exc
        return
    for k in range(20):
        P = float(f"{0.01 + k * 0.05:.12g}")
        levels = kesort(F, P=P, normalise=how, tie_tol=tie_tol).k_eps
        if (levels >= levels.max() - tie_tol).sum() == 1:
            break
    assert result.P == P
    np.testing.assert_array_equal(result.k_eps, levels)


@settings(max_examples=300, deadline=None, derandomize=True, database=None)
@given(
    F=TIED,
    eps=st.sampled_from([0.0, 0.3, 1.0, 3.0]),
    tie_tol=st.sampled_from([0.0, 1e-9, 0.05, 0.3]),
    probe=st.lists(st.integers(0, 79), min_size=1, max_size=6),
    batch=st.sampled_from([1, 10**9]),
)
def test_the_leader_found_from_bounds_is_the_whole_sorts(F, eps, tie_tol, probe, batch):
    """``_Merits.unique_top`` with bounds from a handful of columns (loose ones: most
    solutions must then be compared exactly): whether one solution leads, and which, as
    the whole sort says."""
    ke = importlib.import_module("suspopt.choosing.kepsilon")
    merits = ke._Merits(F, np.full(F.shape[1], eps))
    probe = np.unique([p % len(F) for p in probe])
    unique, near = merits.unique_top(tie_tol, probe, chunk_bytes=batch * 24 * len(F))
    levels = k_eps_levels(F, eps)
    leaders = np.flatnonzero(levels >= levels.max() - tie_tol)
    assert unique == (leaders.size == 1)
    assert set(near) <= set(leaders) and (not unique or near[0] == leaders[0])


@pytest.mark.parametrize("eps", [1.2e-257, 1e-320, 5e-324])
def test_a_threshold_below_every_difference_is_the_crisp_merit(eps):
    """Ties included (Δ = 0 is Γ = 1): the shortcut 1 + f/ε lost its 1 beside an f/ε of
    2^53 and more, making two equal designs each worse than the other."""
    F = np.array([[1.0, 2.0], [1.0 + 2**-52, 1.5], [3.0, 1.0], [3.0, 1.0]])
    np.testing.assert_array_equal(k_eps_levels(F, eps), k_eps_levels(F, 0.0))
    np.testing.assert_array_equal(k_eps_levels([[1.0], [1.0]], eps), [0.0, 0.0])


def test_a_threshold_too_large_for_the_objectives_units_is_named():
    with pytest.raises(ValueError, match="objective f1: a threshold of 3e[+]291 times"):
        kesort([[5.7e16], [6e16]], P=3e291)
