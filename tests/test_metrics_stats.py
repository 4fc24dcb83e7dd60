"""Signal statistics and handling / road-holding metrics (thesis Eq 2.87-2.91)."""

from __future__ import annotations

import numpy as np
import pytest

from suspopt.metrics import stats
from suspopt.metrics.stats import (
    STATISTICS,
    dynamic_tyre_load_ratio,
    max_abs,
    maximum,
    mean,
    minimum,
    peak_dynamic_tyre_load_ratio,
    peak_to_peak,
    peak_tyre_force,
    pitch_variance,
    rms,
    std,
    suspension_travel_max,
    suspension_travel_max_abs,
    suspension_travel_variance,
    tyre_deflection_max,
    tyre_deflection_max_abs,
    tyre_deflection_variance,
    var,
)

SIGNALS = np.array([[1.0, 2.0, 3.0, 4.0], [-5.0, 2.0, 3.0, 0.0]])


def test_variance_is_the_population_variance_of_eq_2_87():
    """(1/n) Σ (x - x̄)², not the n-1 sample estimate: [1, 2, 3, 4] -> 1.25."""
    np.testing.assert_allclose(var(SIGNALS), [1.25, 9.5])
    np.testing.assert_allclose(std(SIGNALS), np.sqrt([1.25, 9.5]))


def test_generic_statistics_by_hand():
    np.testing.assert_allclose(rms(SIGNALS), np.sqrt([7.5, 9.5]))
    np.testing.assert_array_equal(maximum(SIGNALS), [4.0, 3.0])
    np.testing.assert_array_equal(minimum(SIGNALS), [1.0, -5.0])
    np.testing.assert_array_equal(max_abs(SIGNALS), [4.0, 5.0])
    np.testing.assert_array_equal(mean(SIGNALS), [2.5, 0.0])
    np.testing.assert_array_equal(peak_to_peak(SIGNALS), [3.0, 8.0])
    assert var(SIGNALS[0]).shape == ()


def test_registry_names_every_statistic():
    assert set(STATISTICS) == {"var", "std", "rms", "max", "min", "max_abs", "mean", "peak_to_peak"}
    assert STATISTICS["max"] is maximum and STATISTICS["min"] is minimum
    for name, function in STATISTICS.items():
        assert function(SIGNALS).shape == (2,), name
        assert function is getattr(stats, function.__name__)


def test_handling_metrics_keep_the_sign_of_max_and_offer_max_abs():
    """MST / MTD are MAX (Eq 2.88, 2.90), signed; max_abs is the two-sided reading."""
    travel = SIGNALS[1]
    assert suspension_travel_variance(travel) == pytest.approx(9.5)
    assert suspension_travel_max(travel) == 3.0
    assert suspension_travel_max_abs(travel) == 5.0
    assert tyre_deflection_variance(travel) == pytest.approx(9.5)
    assert tyre_deflection_max(travel) == 3.0
    assert tyre_deflection_max_abs(travel) == 5.0
    assert pitch_variance(SIGNALS[0]) == pytest.approx(1.25)


def test_dynamic_tyre_load_ratios_of_a_sinusoidal_load():
    """F = F_static + A sin: std ratio A/(√2 F_static), peak ratio A/F_static, per design."""
    t = np.arange(1000) / 1000.0
    static = np.array([3000.0, 4000.0])
    amplitude = np.array([600.0, 2000.0])
    dynamic = amplitude[:, None] * np.sin(2 * np.pi * 5 * t)
    total = static[:, None] + dynamic
    np.testing.assert_allclose(
        dynamic_tyre_load_ratio(total, static), amplitude / (np.sqrt(2) * static)
    )
    np.testing.assert_allclose(
        dynamic_tyre_load_ratio(dynamic, static), amplitude / (np.sqrt(2) * static)
    )
    np.testing.assert_allclose(peak_dynamic_tyre_load_ratio(dynamic, static), amplitude / static)
    np.testing.assert_allclose(
        peak_dynamic_tyre_load_ratio(total, static, includes_static=True), amplitude / static
    )
    np.testing.assert_allclose(peak_tyre_force(total), static + amplitude)
