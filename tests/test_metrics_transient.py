"""Transient metrics (thesis Sec 2.4.1) against exact second- and first-order responses."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from suspopt.metrics import transient_metrics

FS = 1000.0
STEP_AT = 2.0
T = np.arange(int(30.0 * FS)) / FS

# (natural frequency ω_n in rad/s, damping ratio ζ) of the batch of designs
DESIGNS = np.array(
    [
        [2 * np.pi * 1.0, 0.1],
        [2 * np.pi * 1.5, 0.25],
        [2 * np.pi * 0.8, 0.5],
        [2 * np.pi * 2.0, 0.7],
    ]
)


def _step_response(tau: np.ndarray, wn: float, zeta: float) -> np.ndarray:
    """Unit step response of ω_n²/(s² + 2ζω_n s + ω_n²), ``tau`` the time since the step."""
    wd = wn * np.sqrt(1 - zeta**2)
    tau = np.maximum(tau, 0.0)
    return 1 - np.exp(-zeta * wn * tau) * (np.cos(wd * tau) + zeta * wn / wd * np.sin(wd * tau))


def _exact_step_metrics(wn: float, zeta: float, band: float) -> dict[str, float]:
    """Closed forms t_p = π/ω_d and overshoot exp(-πζ/√(1-ζ²)); the 10-90 % rise and the band
    settling time solved exactly (error extrema are e^{-ζω_n kπ/ω_d} at t_k = kπ/ω_d)."""
    wd = wn * np.sqrt(1 - zeta**2)
    t_peak = np.pi / wd
    y = lambda tau: _step_response(np.asarray(tau), wn, zeta)  # noqa: E731
    rise = brentq(lambda s: y(s) - 0.9, 0, t_peak) - brentq(lambda s: y(s) - 0.1, 0, t_peak)
    k = int(np.floor(np.log(1 / band) * wd / (zeta * wn * np.pi)))  # last extremum outside
    if np.exp(-zeta * wn * k * np.pi / wd) <= band:
        k -= 1
    t_k, t_next = k * np.pi / wd, (k + 1) * np.pi / wd
    sign = 1.0 if k % 2 else -1.0  # odd k: overshoot above 1, even k: undershoot
    settling = brentq(lambda s: (y(s) - 1) - sign * band, t_k, t_next)
    return {
        "peak_time": t_peak,
        "overshoot": 100 * np.exp(-np.pi * zeta / np.sqrt(1 - zeta**2)),
        "rise_time": rise,
        "settling_time": settling,
    }


@pytest.fixture(scope="module")
def step_batch():
    y = np.stack([_step_response(T - STEP_AT, wn, zeta) for wn, zeta in DESIGNS])
    return y, transient_metrics(T, y, band=0.02, start=STEP_AT)


def test_second_order_step_matches_closed_forms(step_batch):
    _, got = step_batch
    for i, (wn, zeta) in enumerate(DESIGNS):
        exact = _exact_step_metrics(wn, zeta, 0.02)
        assert got["peak_time"][i] == pytest.approx(STEP_AT + exact["peak_time"], abs=1 / FS)
        assert got["peak_time_from_start"][i] == pytest.approx(exact["peak_time"], abs=1 / FS)
        assert got["overshoot"][i] == pytest.approx(exact["overshoot"], abs=0.01)
        assert got["peak"][i] == pytest.approx(1 + exact["overshoot"] / 100, abs=1e-4)
        assert got["rise_time"][i] == pytest.approx(exact["rise_time"], abs=2e-4)
        # interpolated crossing of the band edge: a fraction of a sample
        assert got["settling_time_from_start"][i] == pytest.approx(exact["settling_time"], abs=1e-3)
        assert got["settling_time"][i] == pytest.approx(STEP_AT + exact["settling_time"], abs=1e-3)
    np.testing.assert_allclose(got["steady_state"], 1.0, atol=1e-6)
    np.testing.assert_array_equal(got["initial_value"], 0.0)
    assert not got["returns_to_initial"].any()


def test_batch_equals_single_calls(step_batch):
    y, batched = step_batch
    for i, row in enumerate(y):
        single = transient_metrics(T, row, band=0.02, start=STEP_AT)
        for key, value in single.items():
            np.testing.assert_array_equal(batched[key][i], value, err_msg=key)
            assert np.ndim(value) == 0


def test_negative_going_response_mirrors_positive(step_batch):
    y, positive = step_batch
    negative = transient_metrics(T, -y, band=0.02, start=STEP_AT)
    np.testing.assert_allclose(negative["peak"], -positive["peak"])
    for key in ("overshoot", "rise_time", "peak_time", "settling_time"):
        np.testing.assert_allclose(negative[key], positive[key], err_msg=key)


def test_offset_initial_value_uses_signed_excursion():
    """A response from 0.3 down to -0.7 (change -1): metrics equal those of the unit step."""
    wn, zeta = DESIGNS[1]
    y = 0.3 - _step_response(T - STEP_AT, wn, zeta)
    got = transient_metrics(T, y, start=STEP_AT)
    exact = _exact_step_metrics(wn, zeta, 0.02)
    assert got["initial_value"] == pytest.approx(0.3)
    assert got["steady_state"] == pytest.approx(-0.7, abs=1e-6)
    assert got["peak"] == pytest.approx(-0.7 - exact["overshoot"] / 100, abs=1e-4)
    assert got["overshoot"] == pytest.approx(exact["overshoot"], abs=0.01)
    assert got["rise_time"] == pytest.approx(exact["rise_time"], abs=2e-4)


def test_first_order_response_closed_forms():
    """1 - e^{-t/T}: no overshoot, rise T ln 9, 2 % settling T ln 50."""
    time_constant = np.array([0.2, 0.5])
    y = 1 - np.exp(-np.maximum(T - STEP_AT, 0)[None, :] / time_constant[:, None])
    got = transient_metrics(T, y, start=STEP_AT)
    np.testing.assert_allclose(got["overshoot"], 0.0, atol=1e-9)
    np.testing.assert_allclose(got["rise_time"], time_constant * np.log(9), atol=1e-5)
    np.testing.assert_allclose(
        got["settling_time_from_start"], time_constant * np.log(50), atol=1e-5
    )


def test_response_returning_to_zero_settles_relative_to_its_peak():
    """Impulse-like response e^{-σt} sin(ω_d t) (steady state 0, like an acceleration): the peak
    at tan(ω_d t) = ω_d/σ, the band is 2 % of the peak, overshoot is undefined."""
    wn, zeta = 2 * np.pi * 1.2, 0.2
    sigma, wd = zeta * wn, wn * np.sqrt(1 - zeta**2)
    tau = np.maximum(T - STEP_AT, 0)
    y = np.exp(-sigma * tau) * np.sin(wd * tau)
    got = transient_metrics(T, y, start=STEP_AT)

    t_peak = np.arctan(wd / sigma) / wd
    peak = np.exp(-sigma * t_peak) * np.sin(wd * t_peak)
    level = 0.02 * peak
    extrema = t_peak + np.arange(40) * np.pi / wd  # |y| there is e^{-σt} ω_d/ω_n
    k = np.flatnonzero(np.exp(-sigma * extrema) * wd / wn > level)[-1]
    response = lambda s: np.exp(-sigma * s) * np.sin(wd * s)  # noqa: E731
    settling = brentq(lambda s: abs(response(s)) - level, extrema[k], (k + 1) * np.pi / wd)

    assert got["returns_to_initial"]
    assert np.isnan(got["overshoot"])
    assert got["peak"] == pytest.approx(peak, rel=1e-5)
    assert got["peak_time_from_start"] == pytest.approx(t_peak, abs=1 / FS)
    assert got["settling_time_from_start"] == pytest.approx(settling, abs=1e-3)


def test_unsettled_response_has_nan_settling_time_and_start_defaults_to_first_sample():
    y = np.sin(2 * np.pi * T)
    got = transient_metrics(T, y)
    assert np.isnan(got["settling_time"])
    assert got["peak_time_from_start"] == got["peak_time"] == pytest.approx(0.25, abs=1 / FS)


def test_band_and_final_window_are_honoured():
    wn, zeta = DESIGNS[1]
    y = _step_response(T - STEP_AT, wn, zeta)
    wide = transient_metrics(T, y, band=0.05, start=STEP_AT)
    assert wide["settling_time_from_start"] == pytest.approx(
        _exact_step_metrics(wn, zeta, 0.05)["settling_time"], abs=1e-3
    )
    ramp = np.linspace(0.0, 1.0, T.size)
    assert transient_metrics(T, ramp, final_fraction=0.5)["steady_state"] == pytest.approx(
        0.75, abs=1e-3
    )
