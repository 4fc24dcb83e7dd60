"""Damper dissipated power (thesis Eq 2.92) and switching metrics (Sec 2.4.6)."""

from __future__ import annotations

import numpy as np

from suspopt.metrics import (
    damper_switches,
    mean_dissipated_power,
    mean_dissipated_power_from_damping,
    share_at_max_damping,
)

T = np.linspace(0.0, 2.0, 2001)  # whole periods of 2 Hz
VELOCITY = np.array([0.1, 0.4])[:, None] * np.sin(2 * np.pi * 2.0 * T)  # (2, T) m/s


def test_passive_damper_dissipates_c_v_squared_over_two():
    """ṠT = V sin ωt over whole periods: DE = c V²/2 (W)."""
    c = np.array([1500.0, 3000.0])
    expected = c * np.array([0.1, 0.4]) ** 2 / 2
    np.testing.assert_allclose(
        mean_dissipated_power(c[:, None] * VELOCITY, VELOCITY, T), expected, rtol=1e-9
    )
    np.testing.assert_allclose(
        mean_dissipated_power_from_damping(c, VELOCITY, T), expected, rtol=1e-9
    )
    assert mean_dissipated_power_from_damping(1500.0, VELOCITY[0], T) == expected[0]


def test_two_state_damper_power_and_share_at_max():
    """C = C_max while ṠT > 0, C_min otherwise: DE = (C_max + C_min) V²/4, half the time stiff."""
    c_min, c_max = 400.0, np.array([1200.0, 2000.0])
    damping = np.where(VELOCITY > 0, c_max[:, None], c_min)
    expected = (c_max + c_min) * np.array([0.1, 0.4]) ** 2 / 4
    np.testing.assert_allclose(
        mean_dissipated_power_from_damping(damping, VELOCITY, T), expected, rtol=1e-6
    )
    np.testing.assert_allclose(share_at_max_damping(damping, c_max), 0.5, atol=5e-3)


def test_switches_count_state_changes_of_a_hand_made_sequence():
    states = np.array(
        [
            [400, 400, 1200, 1200, 400, 1200, 1200, 1200, 400],
            [400, 400, 400, 400, 400, 400, 400, 400, 400],
        ],
        dtype=float,
    )
    np.testing.assert_array_equal(damper_switches(states), [4, 0])
    np.testing.assert_allclose(share_at_max_damping(states, 1200.0), [5 / 9, 0.0])
    assert damper_switches(states[0]) == 4


def test_switch_tolerance_ignores_noise_below_it():
    noisy = np.array([1000.0, 1000.0 + 1e-9, 1000.0, 3000.0, 3000.0 - 1e-9, 1000.0])
    assert damper_switches(noisy) == 5
    assert damper_switches(noisy, tol=1e-6) == 2
    assert share_at_max_damping(noisy, 3000.0, tol=1e-6) == 2 / 6
