"""ISO 2631-1 weightings and ride-comfort metrics against the analogue definition, ISO's tables
and closed forms (thesis Eq 2.78-2.85)."""

from __future__ import annotations

from decimal import Decimal

import numpy as np
import pytest
from scipy import signal

from suspopt.metrics import iso2631
from suspopt.metrics.iso2631 import (
    WEIGHTINGS,
    comfort_reaction,
    crest_factor,
    mtvv,
    ratio_tests,
    running_rms,
    vdv,
    weight,
    weighted_rms,
    weighting_response,
)

FS = 1000.0
THIRD_OCTAVES = 10.0 ** (np.arange(-3, 20) / 10.0)  # exact 1/3-octave centres 0.5 ... 80 Hz


def _smooth_step(x: np.ndarray) -> np.ndarray:
    """C-infinity step from 0 (x <= 0) to 1 (x >= 1): its spectrum has no low-frequency tail."""
    x = np.clip(x, 0.0, 1.0)
    rise = np.exp(-1.0 / np.where(x > 0, x, 1.0)) * (x > 0)
    fall = np.exp(-1.0 / np.where(x < 1, 1.0 - x, 1.0)) * (x < 1)
    return rise / (rise + fall)


def _amplitude(t: np.ndarray, y: np.ndarray, f: float) -> float:
    basis = np.stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)], axis=1)
    coefficients, *_ = np.linalg.lstsq(basis, y, rcond=None)
    return float(np.hypot(*coefficients))


@pytest.mark.parametrize("name", list(WEIGHTINGS))
def test_effective_magnitude_within_half_percent_of_analogue(name):
    """Long sines (smooth 10 s onset, 20 s to settle, 10 s measured) at every 1/3-octave centre
    0.5-80 Hz, weighted at fs = 1 kHz in one batch: amplitude ratio within 0.5 % of |H|."""
    ramp, settle, measured = 10.0, 20.0, 10.0
    t = np.arange(int((ramp + settle + measured) * FS)) / FS
    sines = _smooth_step(t / ramp) * np.sin(2 * np.pi * THIRD_OCTAVES[:, None] * t)
    weighted = weight(sines, FS, name)
    window = t >= ramp + settle
    gains = np.array(
        [
            _amplitude(t[window], row[window], f)
            for row, f in zip(weighted, THIRD_OCTAVES, strict=True)
        ]
    )
    analogue = np.abs(weighting_response(THIRD_OCTAVES, name))
    np.testing.assert_allclose(gains, analogue, rtol=0.005)


# ISO 2631-1:1997 Table 3 (identical in ISO 8041), weighting factors x 1000 at the nominal
# one-third-octave frequencies, as printed (3 significant figures).
NOMINAL = [
    0.1,
    0.125,
    0.16,
    0.2,
    0.25,
    0.315,
    0.4,
    0.5,
    0.63,
    0.8,
    1.0,
    1.25,
    1.6,
    2.0,
    2.5,
    3.15,
    4.0,
    5.0,
    6.3,
    8.0,
    10.0,
    12.5,
    16.0,
    20.0,
    25.0,
    31.5,
    40.0,
    50.0,
    63.0,
    80.0,
]
ISO_TABLE_3 = {
    "Wk": (
        NOMINAL,
        [
            "31.2",
            "48.6",
            "79.0",
            "121",
            "182",
            "263",
            "352",
            "418",
            "459",
            "477",
            "482",
            "484",
            "494",
            "531",
            "631",
            "804",
            "967",
            "1039",
            "1054",
            "1036",
            "988",
            "902",
            "768",
            "636",
            "513",
            "405",
            "314",
            "246",
            "186",
            "132",
        ],
    ),
    "Wd": (
        NOMINAL,
        [
            "62.4",
            "97.3",
            "158",
            "243",
            "365",
            "530",
            "713",
            "853",
            "944",
            "992",
            "1011",
            "1008",
            "968",
            "890",
            "776",
            "642",
            "512",
            "409",
            "323",
            "253",
            "202",
            "161",
            "125",
            "100",
            "80.0",
            "63.2",
            "49.4",
            "38.8",
            "29.5",
            "21.1",
        ],
    ),
    "Wf": (
        [0.1, 0.125, 0.16, 0.2, 0.25, 0.315, 0.4, 0.5, 0.63, 0.8, 1.0, 1.25, 1.6, 2.0],
        [
            "695",
            "895",
            "1006",
            "992",
            "854",
            "619",
            "384",
            "224",
            "116",
            "53.0",
            "23.5",
            "9.98",
            "3.77",
            "1.55",
        ],
    ),
}


@pytest.mark.parametrize("name", list(ISO_TABLE_3))
def test_weighting_response_matches_iso_table_3(name):
    """Within half a unit of the printed last digit plus 0.2 %: the table is rounded to three
    figures and was computed from the rounded Annex A parameters (largest gap seen: 0.11 %)."""
    frequencies, printed = ISO_TABLE_3[name]
    table = np.array([float(v) for v in printed])
    half_unit = np.array([0.5 * 10.0 ** Decimal(v).as_tuple().exponent for v in printed])
    computed = 1000.0 * np.abs(weighting_response(np.array(frequencies), name))
    assert np.all(np.abs(computed - table) <= half_unit + 0.002 * table), (computed, table)


def _analogue_system(params: iso2631.WeightingParameters) -> signal.lti:
    """The Annex A product as one rational transfer function in s (polynomial coefficients)."""

    def quadratic(f: float, q: float) -> np.ndarray:
        w = 2 * np.pi * f
        return np.array([1 / w**2, 1 / (q * w), 1.0]) if np.isfinite(f) else np.array([1.0])

    q_band = 1 / np.sqrt(2)
    w1, w2 = 2 * np.pi * params.f1, 2 * np.pi * params.f2
    num = np.polymul([1.0, 0.0, 0.0], [w2**2])
    den = np.polymul([1.0, w1 / q_band, w1**2], [1.0, w2 / q_band, w2**2])
    if np.isfinite(params.f3):
        num = np.polymul(num, [1 / (2 * np.pi * params.f3), 1.0])
    den = np.polymul(den, quadratic(params.f4, params.q4))
    if np.isfinite(params.f5):
        num = np.polymul(num, quadratic(params.f5, params.q5) * (params.f5 / params.f6) ** 2)
        den = np.polymul(den, quadratic(params.f6, params.q6))
    return signal.lti(num, den)


@pytest.mark.parametrize("name", list(WEIGHTINGS))
def test_weighted_shocks_match_causal_analogue_filter(name):
    """Time domain: the weighted record equals the analogue filter integrated by lsim (phase and
    causality included) and a shock at the very end does not wrap onto the record's start."""
    t = np.arange(int(20 * FS)) / FS

    def half_sine(t0: float, d: float) -> np.ndarray:
        return np.where((t >= t0) & (t <= t0 + d), np.sin(np.pi * (t - t0) / d), 0.0)

    shocks = 3.0 * half_sine(1.0, 0.25) - 2.0 * half_sine(19.7, 0.3)
    _, expected, _ = signal.lsim(_analogue_system(WEIGHTINGS[name]), shocks, t)
    got = weight(shocks, FS, name)
    np.testing.assert_allclose(got, expected, atol=2e-3 * np.max(np.abs(expected)))


def test_weight_batches_rows_like_single_calls():
    rng = np.random.default_rng(1)
    a = rng.standard_normal((3, 4000))
    batched = weight(a, 200.0, "Wk")
    np.testing.assert_allclose(
        batched, np.stack([weight(row, 200.0, "Wk") for row in a]), atol=1e-12
    )


@pytest.mark.parametrize("unweighted", [None, "none", "None"])
def test_unweighted_leaves_signal_unchanged(unweighted):
    a = np.sin(np.linspace(0, 30, 1000))
    np.testing.assert_array_equal(weight(a, 100.0, unweighted), a)
    np.testing.assert_array_equal(weighting_response([1.0, 10.0], unweighted), [1.0, 1.0])


def test_weighting_names_are_case_insensitive_and_typos_are_explained():
    np.testing.assert_array_equal(weighting_response(4.0, "wk"), weighting_response(4.0, "Wk"))
    with pytest.raises(ValueError, match="Did you mean Wk"):
        weighting_response(4.0, "Wkk")


def test_sampling_rate_below_100_hz_is_rejected():
    with pytest.raises(ValueError, match="100 Hz"):
        weighted_rms(np.zeros(100), 99.0, "Wk")


def test_sine_closed_forms():
    """Unweighted sine of amplitude A over whole periods: rms A/√2, CF √2, VDV A(3T/8)^¼,
    running rms A/√2 once the window is full and the ramp of Eq 2.80 before, MTVV A/√2."""
    amplitude, f0, duration, tau = np.array([1.0, 2.5]), 5.0, 4.0, 1.0
    t = np.arange(int(duration * FS)) / FS
    a = amplitude[:, None] * np.sin(2 * np.pi * f0 * t)
    np.testing.assert_allclose(weighted_rms(a, FS, None), amplitude / np.sqrt(2), rtol=1e-12)
    np.testing.assert_allclose(crest_factor(a, FS, None), np.sqrt(2), rtol=1e-12)
    np.testing.assert_allclose(vdv(a, FS, None), amplitude * (3 * duration / 8) ** 0.25, rtol=1e-12)
    running = running_rms(a, FS, None, tau)
    full = t >= tau - 0.5 / FS
    np.testing.assert_allclose(
        running[:, full],
        np.broadcast_to(amplitude[:, None] / np.sqrt(2), running[:, full].shape),
        rtol=1e-9,
    )
    w, elapsed = 2 * np.pi * f0, t[~full] + 1 / FS
    ramp = np.sqrt((elapsed / 2 - np.sin(2 * w * elapsed) / (4 * w)) / tau)
    np.testing.assert_allclose(
        running[:, ~full], amplitude[:, None] * ramp, atol=2e-3 * amplitude.max()
    )
    np.testing.assert_allclose(mtvv(a, FS, None, tau), amplitude / np.sqrt(2), rtol=1e-9)
    ratios = ratio_tests(a, FS, None, tau)
    np.testing.assert_allclose(ratios["mtvv_ratio"], 1.0, rtol=1e-9)
    np.testing.assert_allclose(ratios["vdv_ratio"], (3 / 8) ** 0.25 * np.sqrt(2), rtol=1e-9)
    assert ratios["basic_method_sufficient"].all()


def test_half_sine_shock_closed_forms():
    """Half-sine shock of amplitude A and duration d in a record of T seconds: rms A√(d/2T),
    VDV A(3d/8)^¼, MTVV A√(d/2τ), CF √(2T/d); the ratio tests flag it (Eq 2.84-2.85)."""
    amplitude, d, duration, tau = 3.0, 0.2, 10.0, 1.0
    t = np.arange(int(duration * FS)) / FS
    inside = (t >= 1.0) & (t <= 1.0 + d + 1e-9)
    a = np.where(inside, amplitude * np.sin(np.pi * (t - 1.0) / d), 0.0)
    np.testing.assert_allclose(
        weighted_rms(a, FS, None), amplitude * np.sqrt(d / (2 * duration)), rtol=1e-9
    )
    np.testing.assert_allclose(vdv(a, FS, None), amplitude * (3 * d / 8) ** 0.25, rtol=1e-9)
    np.testing.assert_allclose(
        mtvv(a, FS, None, tau), amplitude * np.sqrt(d / (2 * tau)), rtol=1e-9
    )
    np.testing.assert_allclose(crest_factor(a, FS, None), np.sqrt(2 * duration / d), rtol=1e-9)
    ratios = ratio_tests(a, FS, None, tau)
    np.testing.assert_allclose(ratios["mtvv_ratio"], np.sqrt(duration / tau), rtol=1e-9)
    np.testing.assert_allclose(
        ratios["vdv_ratio"], (3 / 8) ** 0.25 * np.sqrt(2) * (duration / d) ** 0.25, rtol=1e-9
    )
    assert not ratios["basic_method_sufficient"]
    assert ratios["mtvv_limit"] == 1.5 and ratios["vdv_limit"] == 1.75


def test_weighted_rms_of_two_sines_adds_weighted_powers():
    """RC (Eq 2.78) of a two-tone record: √(Σ (A_i |W(f_i)|)² / 2) once the onset has died out."""
    t = np.arange(int(60 * FS)) / FS
    tones = (1.0, 4.0), (0.5, 20.0)
    a = sum(amp * np.sin(2 * np.pi * f * t) for amp, f in tones)
    expected = np.sqrt(sum((amp * abs(weighting_response(f, "Wk"))) ** 2 / 2 for amp, f in tones))
    assert weighted_rms(a, FS, "Wk") == pytest.approx(expected, rel=0.005)


@pytest.mark.parametrize(
    "value, label",
    [
        (0.0, "not uncomfortable"),
        (0.3, "not uncomfortable"),
        (0.315, "a little uncomfortable"),
        (0.55, "a little uncomfortable / fairly uncomfortable"),
        (0.63, "fairly uncomfortable"),
        (0.9, "fairly uncomfortable / uncomfortable"),
        (1.1, "uncomfortable"),
        (1.5, "uncomfortable / very uncomfortable"),
        (1.8, "very uncomfortable"),
        (2.2, "very uncomfortable / extremely uncomfortable"),
        (2.5, "extremely uncomfortable"),
        (9.0, "extremely uncomfortable"),
    ],
)
def test_comfort_reaction_follows_iso_bands(value, label):
    assert comfort_reaction(value) == label


def test_comfort_reaction_of_an_array_keeps_its_shape_and_rejects_nonsense():
    labels = comfort_reaction(np.array([[0.1, 0.55], [1.0, 3.0]]))
    assert labels.shape == (2, 2)
    assert labels[0, 1] == "a little uncomfortable / fairly uncomfortable"
    assert labels[1, 0] == "uncomfortable"
    with pytest.raises(ValueError):
        comfort_reaction([0.2, np.nan])
    with pytest.raises(ValueError):
        comfort_reaction(-0.1)


def test_matches_independent_implementation_phonometry():
    """Cross-check against phonometry's ISO 8041-1 weightings when that package is installed."""
    phonometry = pytest.importorskip("phonometry")
    f = np.geomspace(0.1, 400.0, 200)
    for name in WEIGHTINGS:
        np.testing.assert_allclose(
            np.abs(weighting_response(f, name)), phonometry.weighting_factors(name, f), rtol=1e-9
        )
