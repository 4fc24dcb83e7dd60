"""Welch PSD, H1 transfer function, coherence and transmissibility (thesis Eq 2.86)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal
from scipy.integrate import trapezoid

from suspopt.metrics import coherence, psd, transfer_function, transmissibility

FS = 200.0
RNG = np.random.default_rng(7)
NOISE = RNG.standard_normal((2, 2**16))  # two designs' worth of white input
LOW_PASS = signal.butter(2, 10.0, fs=FS)  # a known linear "seat" between input and output


def test_white_noise_psd_level_and_variance():
    """One-sided density of unit white noise: 2σ²/fs in (unit)²/Hz; ∫ PSD df = variance."""
    sigma = np.array([1.0, 3.0])
    f, p = psd(sigma[:, None] * NOISE, FS)
    assert p.shape == (2, f.size)
    inner = (f > 5) & (f < 90)
    np.testing.assert_allclose(p[:, inner].mean(axis=1), 2 * sigma**2 / FS, rtol=0.03)
    np.testing.assert_allclose(trapezoid(p, f, axis=1), sigma**2, rtol=0.03)


def test_sine_power_is_amplitude_squared_over_two():
    t = np.arange(2**15) / FS
    f, p = psd(2.0 * np.sin(2 * np.pi * 12.5 * t), FS, nperseg=4096)
    assert trapezoid(p, f) == pytest.approx(2.0**2 / 2, rel=0.01)
    assert f[np.argmax(p)] == pytest.approx(12.5, abs=FS / 4096)


def test_h1_recovers_a_known_filter_despite_output_noise():
    """One input (T,) against P outputs (P, T): gains 1 and 3 times a Butterworth low-pass."""
    x = NOISE[0]
    gains = np.array([1.0, 3.0])
    y = gains[:, None] * signal.lfilter(*LOW_PASS, x) + 0.1 * NOISE[1]
    f, h = transfer_function(x, y, FS, nperseg=1024)
    _, expected = signal.freqz(*LOW_PASS, worN=f, fs=FS)
    band = f < 20
    error = np.abs(h[:, band] - gains[:, None] * expected[band])
    assert np.all(error <= 0.03 * gains[:, None]), error.max(axis=1)
    _, tr = transmissibility(x, y, FS, nperseg=1024)
    np.testing.assert_allclose(tr, np.abs(h))
    np.testing.assert_allclose(
        tr[:, band], gains[:, None] * np.abs(expected[band]), rtol=0.05, atol=0.02
    )


def test_coherence_separates_related_from_unrelated_signals():
    x = NOISE[0]
    _, related = coherence(x, signal.lfilter(*LOW_PASS, x), FS, nperseg=1024)
    f, unrelated = coherence(x, NOISE[1], FS, nperseg=1024)
    assert related[(f > 0) & (f < 20)].min() > 0.99
    assert unrelated.mean() < 0.05


def test_default_segment_scales_with_the_record():
    f_short, _ = psd(NOISE[0, :4000], FS)
    f_long, _ = psd(NOISE[0], FS)
    assert f_short[1] == pytest.approx(FS / 500)  # T/8 = 500 samples
    assert f_long[1] == pytest.approx(FS / 2**13)


def test_record_psd_resolves_one_over_its_segment_or_the_record():
    """Segments of PSD_SEGMENT seconds (spacing 1/8 Hz), or the whole of a shorter record
    (a 3 s record: 1/3 Hz, where psd's default eighth gives 2.67 Hz)."""
    from suspopt.metrics.spectral import PSD_SEGMENT, record_psd

    fs = 1000.0
    for duration, spacing in ((3.0, 1 / 3.0), (20.0, 1 / PSD_SEGMENT)):
        x = np.random.default_rng(0).standard_normal(int(duration * fs))
        f, p = record_psd(x, fs)
        assert np.diff(f) == pytest.approx(spacing, rel=1e-3)
        np.testing.assert_array_equal(p, psd(x, fs, min(x.size, round(PSD_SEGMENT * fs)))[1])
    assert np.diff(psd(np.zeros(3000), fs)[0])[0] == pytest.approx(8 / 3.0)
