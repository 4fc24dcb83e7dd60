"""Non-linear spring usage ratio (thesis Eq 5.3)."""

from __future__ import annotations

import numpy as np
import pytest

from suspopt.metrics import nonlinear_spring_usage


def test_usage_by_hand_and_from_the_printed_form():
    """At the largest |x| = 0.05 m with k_l = 5e4 N/m, k_nl = 1e7 N/m³: 2.5e4/7.5e4 = 1/3."""
    travel = np.array([0.0, 0.01, -0.05, 0.02])
    assert nonlinear_spring_usage(travel, 5e4, 1e7) == pytest.approx(1 / 3, rel=1e-12)
    x = travel[travel != 0]
    printed = np.max(1e7 * x**3 / (5e4 * x + 1e7 * x**3))
    np.testing.assert_allclose(nonlinear_spring_usage(travel, 5e4, 1e7), printed, rtol=1e-12)


def test_batched_stiffnesses_broadcast_against_travel():
    travel = np.array([[0.0, 0.02, -0.04], [0.01, 0.0, 0.03]])
    k_l, k_nl = np.array([5e4, 1e5]), np.array([1e7, 5e6])
    expected = [1e7 * 0.04**2 / (5e4 + 1e7 * 0.04**2), 5e6 * 0.03**2 / (1e5 + 5e6 * 0.03**2)]
    np.testing.assert_allclose(nonlinear_spring_usage(travel, k_l, k_nl), expected)


def test_zero_over_zero_is_zero():
    assert nonlinear_spring_usage(np.zeros(5), 5e4, 1e7) == 0.0
    assert nonlinear_spring_usage(np.array([0.0, 0.1]), 0.0, 0.0) == 0.0
    assert nonlinear_spring_usage(np.array([0.0, 0.1]), 0.0, 1e7) == 1.0


def test_the_ratio_at_the_largest_travel_is_the_largest_ratio():
    """The ratio taken once at each record's largest x² against the ratio of every sample:
    equal to rounding, NaN where the travel has a NaN or an infinity, 0 where k_nl = 0; a
    softening spring (k_nl < 0) is the per-sample formula itself."""
    rng = np.random.default_rng(7)
    travel = rng.standard_normal((40, 500)) * 10.0 ** rng.uniform(-4, 0, (40, 1))
    travel[3, 17], travel[4, 0], travel[5, -1] = np.nan, np.inf, -np.inf
    k_l = rng.uniform(1e4, 2e5, 40)
    k_nl = rng.uniform(0.0, 3e7, 40)
    k_nl[6] = 0.0

    def every_sample(x, kl, knl):
        cubic = knl[:, None] * np.square(x)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.max(np.where(cubic != 0.0, cubic / (kl[:, None] + cubic), 0.0), axis=-1)

    with np.errstate(invalid="ignore"):
        got, want = nonlinear_spring_usage(travel, k_l, k_nl), every_sample(travel, k_l, k_nl)
    assert np.array_equal(np.isnan(got), np.isnan(want)) and np.isnan(got[[3, 4, 5]]).all()
    np.testing.assert_allclose(got, want, rtol=4e-16, atol=0)
    assert got[6] == 0.0
    soft = -np.abs(k_nl) * 1e-3
    with np.errstate(invalid="ignore"):
        assert np.array_equal(
            nonlinear_spring_usage(travel, k_l, soft),
            every_sample(travel, k_l, soft),
            equal_nan=True,
        )
