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
